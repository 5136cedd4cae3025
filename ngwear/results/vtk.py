"""VTU/PVD output of a result's frames for ParaView (NGSolve's VTKOutput).

Each frame is one VTU named by its step, ``fields_step050.vtu`` (:func:`frame_name`, as the pictures of the
same step: ``fig2_step050.png``), and ``fields.pvd`` lists them with their times.  The series is written
into a scratch folder and moved in when complete: an interrupted write never leaves a half series, and a
rerun into the same folder leaves no frame of an earlier run behind.
"""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import ngsolve as ngs


def frame_name(step: int) -> str:
    """``step050``: how the files of a frame (its VTU, its picture) name its step."""
    return f"step{step:03d}"


def write_series(result, directory: Path) -> Path:
    """Write one VTU (displacement, wear) per frame, named by its step, and ``fields.pvd`` with their times."""
    directory = Path(directory)
    disc = result.discretization
    mesh = disc.mesh
    u = ngs.GridFunction(disc.fes)
    wear = ngs.GridFunction(ngs.H1(mesh, order=result.scene.mesh.order, definedon="body"))
    with tempfile.TemporaryDirectory(dir=directory, prefix=".fields-") as scratch:
        body, entries = _body(mesh), []
        for step in result.stored_steps:
            u.vec.FV().NumPy()[:] = result.displacement(step)
            disc.set_nodal(wear, result.wear[step])
            name = f"fields_{frame_name(step)}"
            ngs.VTKOutput(mesh, coefs=[u, wear], names=["displacement", "wear"], filename=str(Path(scratch) / name),
                          subdivision=result.scene.mesh.order - 1).Do(drawelems=body)
            entries.append(f'<DataSet timestep="{float(result.times[step])!r}" file="{name}.vtu"/>')
        (Path(scratch) / "fields.pvd").write_text(
            '<?xml version="1.0"?>\n<VTKFile type="Collection" version="1.0" byte_order="LittleEndian">\n'
            "<Collection>\n" + "\n".join(entries) + "\n</Collection>\n</VTKFile>\n")
        for old in directory.glob("fields*.vtu"):
            old.unlink()
        for new in sorted(Path(scratch).iterdir(), key=lambda f: f.suffix == ".pvd"):   # the index last
            shutil.move(str(new), directory / new.name)
    return directory / "fields.pvd"


def _body(mesh: ngs.Mesh) -> ngs.BitArray:
    """The elements of region ``body``: VTKOutput's ``drawelems`` marks elements (a region's Mask() marks regions)."""
    elements = mesh.ngmesh.Elements3D() if mesh.dim == 3 else mesh.ngmesh.Elements2D()
    names = mesh.GetMaterials()
    return ngs.BitArray([names[index - 1] == "body" for index in elements.NumPy()["index"]])
