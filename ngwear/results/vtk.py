"""VTU/PVD output of a result's frames for ParaView (NGSolve's VTKOutput).

Each frame is one VTU named by its step, ``fields_step050.vtu`` (:func:`frame_name`, as the pictures of the
same step: ``fig2_step050.png``), and ``fields.pvd`` lists them with their times.  The series is written
into a scratch folder and moved in when complete: an interrupted write never leaves a half series, and a
rerun into the same folder leaves no frame of an earlier run behind.

Every element is written, a backing's too, with the cell field ``region``: k for the k-th region of the mesh
(``mesh.GetMaterials()``; the built-in kinds: 0 ``body``, 1 ``backing``), so that ParaView's Threshold picks a
region.  NGSolve writes the cells of each element together, as many for each (P2: its subdivision); a mesh of
several element types gets ``region`` as a point field instead (constant on each cell: the output repeats the
vertices of each element).
"""
from __future__ import annotations

import os
import re
import tempfile
from pathlib import Path

import ngsolve as ngs
import numpy as np


def frame_name(step: int) -> str:
    """``step050``: how the files of a frame (its VTU, its picture) name its step."""
    return f"step{step:03d}"


def write_series(result, directory: Path) -> Path:
    """Write one VTU (displacement, wear, region; temperature with heat) per frame, and ``fields.pvd`` with their times."""
    directory = Path(directory)
    disc = result.discretization
    mesh = disc.mesh
    u = ngs.GridFunction(disc.fes)
    wear = ngs.GridFunction(ngs.H1(mesh, order=result.scene.mesh.order))     # the contact points' space: 0 off Γ_C
    regions = element_regions(mesh)
    uniform = len({el.type for el in mesh.Elements(ngs.VOL)}) == 1
    coefs, names = [u, wear], ["displacement", "wear"]
    temperature = temperature_field(result)
    if temperature is not None:
        coefs.append(temperature)
        names.append("temperature")
    if not uniform:
        coefs.append(mesh.MaterialCF({name: k for k, name in enumerate(mesh.GetMaterials())}))
        names.append("region")
    with tempfile.TemporaryDirectory(dir=directory, prefix=".fields-") as scratch:
        entries = []
        for step in result.stored_steps:
            u.vec.FV().NumPy()[:] = result.displacement(step)
            disc.set_nodal(wear, result.wear[step])
            if temperature is not None:
                temperature.vec.FV().NumPy()[:] = result.temperatures[step]
            name = f"fields_{frame_name(step)}"
            ngs.VTKOutput(mesh, coefs=coefs, names=names, filename=str(Path(scratch) / name),
                          subdivision=result.scene.mesh.order - 1).Do()
            if uniform:
                add_cell_field(Path(scratch) / f"{name}.vtu", "region", regions)
            entries.append(f'<DataSet timestep="{float(result.times[step])!r}" file="{name}.vtu"/>')
        (Path(scratch) / "fields.pvd").write_text(
            '<?xml version="1.0"?>\n<VTKFile type="Collection" version="1.0" byte_order="LittleEndian">\n'
            "<Collection>\n" + "\n".join(entries) + "\n</Collection>\n</VTKFile>\n")
        for old in directory.glob("fields*.vtu"):
            old.unlink()
        for new in sorted(Path(scratch).iterdir(), key=lambda f: f.suffix == ".pvd"):   # the index last
            os.replace(new, directory / new.name)       # a link there is replaced, never written through
    return directory / "fields.pvd"


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
