"""VTU/PVD output of a result's frames for ParaView (NGSolve's VTKOutput).

Each frame is one VTU of the body named by its step, ``fields_step050.vtu`` (:func:`frame_name`, as the pictures of
the same step: ``fig2_step050.png``), with the point fields ``displacement``, ``wear``, ``stress`` (σ, 3 × 3) and
``von_mises`` (:mod:`ngwear.results.bulk_stress`), and one surface VTU of Γ_C, ``contact_step050.vtu``, with the
contact fields at the contact points (:mod:`ngwear.results.contact_file`).  ``fields.pvd`` lists both with their
times, the body as part 0 and the contact face as part 1 (ParaView opens it as one multiblock series).  The series is written
into a scratch folder and moved in when complete: an interrupted write never leaves a half series, and a
rerun into the same folder leaves no frame of an earlier run behind.

With ``wear.geometry = "surface"`` each frame shows the body as it was at its step: the mesh moved by the
geometry updates at or before the step (:meth:`Result.body_coordinates <ngwear.results.result.Result.body_coordinates>`),
its fields evaluated there, and the contact file's face with it.

Every element is written, a backing's too, with the cell field ``region``: k for the k-th region of the mesh
(``mesh.GetMaterials()``; the built-in kinds: 0 ``body``, 1 ``backing``), so that ParaView's Threshold picks a
region.  NGSolve writes the cells of each element together, as many for each (P2: its subdivision); a mesh of
several element types gets ``region`` as a point field instead (constant on each cell: the output repeats the
vertices of each element).
"""
from __future__ import annotations

import logging
import os
import re
import tempfile
from contextlib import contextmanager
from pathlib import Path

import ngsolve as ngs
import numpy as np

from ..numerics.topology import coordinates, place
from .bulk_stress import BulkStress, unknown_normal
from .contact_file import surface, write_contact

log = logging.getLogger(__name__)


def frame_name(step: int) -> str:
    """``step050``: how the files of a frame (its VTU, its picture) name its step."""
    return f"step{step:03d}"


def write_series(result, directory: Path) -> Path:
    """Write each frame's VTU (temperature too, with heat) and contact file, named by its step, and ``fields.pvd``."""
    directory = Path(directory)
    disc = result.discretization
    mesh = disc.mesh
    u = ngs.GridFunction(disc.fes)
    wear = ngs.GridFunction(ngs.H1(mesh, order=result.scene.mesh.order))     # the contact points' space: 0 off Γ_C
    regions = element_regions(mesh)
    uniform = len({el.type for el in mesh.Elements(ngs.VOL)}) == 1
    stress = BulkStress(result.scene, mesh, u)
    coefs, names = [u, wear, stress.tensor, stress.von_mises], ["displacement", "wear", "stress", "von_mises"]
    temperature = temperature_field(result)
    if temperature is not None:
        coefs.append(temperature)
        names.append("temperature")
    if not uniform:
        coefs.append(mesh.MaterialCF({name: k for k, name in enumerate(mesh.GetMaterials())}))
        names.append("region")
    unknown = unknown_normal(result.scene)
    if unknown:
        log.warning("%s: stress: σ₃₃ of region %s is written 0 (its 2D energy law does not define it)",
                    result.scene.name, ", ".join(unknown))
    face = surface(disc)
    final = coordinates(mesh) if result.geometry_updates else None
    with tempfile.TemporaryDirectory(dir=directory, prefix=".fields-") as scratch, _restored(mesh, final):
        entries = []
        for step in result.stored_steps:
            body = result.body_coordinates(step)
            if body is not None:                        # the worn body as it was at the step
                place(mesh, body)
            u.vec.FV().NumPy()[:] = result.displacement(step)
            disc.set_nodal(wear, result.wear[step])
            if temperature is not None:
                temperature.vec.FV().NumPy()[:] = result.temperatures[step]
            stress.update()
            name, contact, t = f"fields_{frame_name(step)}", f"contact_{frame_name(step)}", float(result.times[step])
            ngs.VTKOutput(mesh, coefs=coefs, names=names, filename=str(Path(scratch) / name),
                          subdivision=result.scene.mesh.order - 1).Do()
            if uniform:
                add_cell_field(Path(scratch) / f"{name}.vtu", "region", regions)
            write_contact(result, step, face if body is None else face.on(body), Path(scratch) / f"{contact}.vtu")
            entries += [f'<DataSet timestep="{t!r}" part="0" file="{name}.vtu"/>',
                        f'<DataSet timestep="{t!r}" part="1" file="{contact}.vtu"/>']
        (Path(scratch) / "fields.pvd").write_text(
            '<?xml version="1.0"?>\n<VTKFile type="Collection" version="1.0" byte_order="LittleEndian">\n'
            "<Collection>\n" + "\n".join(entries) + "\n</Collection>\n</VTKFile>\n")
        for old in [*directory.glob("fields*.vtu"), *directory.glob("contact_step*.vtu")]:
            old.unlink()
        for new in sorted(Path(scratch).iterdir(), key=lambda f: f.suffix == ".pvd"):   # the index last
            os.replace(new, directory / new.name)       # a link there is replaced, never written through
    return directory / "fields.pvd"


@contextmanager
def _restored(mesh: ngs.Mesh, coords: np.ndarray | None):
    """Put the mesh's vertices back at ``coords`` (its own: the frames move it to theirs) when done (None: unmoved)."""
    try:
        yield
    finally:
        if coords is not None:
            place(mesh, coords)


def temperature_field(result) -> ngs.GridFunction | None:
    """The frames' point field ``temperature`` (P1, as :class:`~ngwear.numerics.heat.Heat`): None without heat."""
    if result.scene.heat.model == "none" or not all(s in result.temperatures for s in result.stored_steps):
        return None
    return ngs.GridFunction(ngs.H1(result.discretization.mesh, order=1))


def element_regions(mesh: ngs.Mesh) -> np.ndarray:
    """The region number of each volume element, in NGSolve's order (its index among ``mesh.GetMaterials()``)."""
    elements = mesh.ngmesh.Elements3D() if mesh.dim == 3 else mesh.ngmesh.Elements2D()
    return elements.NumPy()["index"].astype(np.int32) - 1


def add_cell_field(path: Path, name: str, per_element: np.ndarray) -> None:
    """Add an integer cell field to a VTU of VTKOutput, each element's value on each of its cells.

    The field goes into the XML header as an ASCII array (before ``<Points>``); the appended binary data after
    the header, whose offsets count from its own start, stays as it is.
    """
    data = path.read_bytes()
    cells = int(re.search(rb'NumberOfCells="(\d+)"', data).group(1))
    if cells % len(per_element):
        raise ValueError(f"{path.name}: {cells} cells for {len(per_element)} elements (not as many for each)")
    values = np.repeat(per_element, cells // len(per_element))
    array = (f'<CellData Scalars="{name}">\n<DataArray type="Int32" Name="{name}" NumberOfComponents="1" '
             f'format="ascii">\n{" ".join(map(str, values))}\n</DataArray>\n</CellData>\n').encode()
    at = data.index(b"<Points>")
    path.write_bytes(data[:at] + array + data[at:])
