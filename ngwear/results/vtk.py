"""VTU/PVD output of a result's frames for ParaView (NGSolve's VTKOutput).

The series is written into a scratch folder and moved in when complete: an interrupted write never
leaves a half series, and a rerun into the same folder leaves no frame of an earlier run behind.
"""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import ngsolve as ngs


def write_series(result, directory: Path) -> Path:
    """Write one VTU (displacement, wear) per frame and ``fields.pvd`` with their times."""
    directory = Path(directory)
    disc = result.discretization
    mesh = disc.mesh
    u = ngs.GridFunction(disc.fes)
    wear = ngs.GridFunction(ngs.H1(mesh, order=result.scene.mesh.order, definedon="body"))
    with tempfile.TemporaryDirectory(dir=directory, prefix=".fields-") as scratch:
        vtk = ngs.VTKOutput(mesh, coefs=[u, wear], names=["displacement", "wear"],
                            filename=str(Path(scratch) / "fields"), subdivision=result.scene.mesh.order - 1)
        body = _body(mesh)
        for step in result.stored_steps:
            u.vec.FV().NumPy()[:] = result.displacement(step)
            disc.set_nodal(wear, result.wear[step])
            vtk.Do(time=float(result.times[step]), drawelems=body)
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
