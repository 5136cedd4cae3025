"""VTU/PVD output of a result's stored steps for ParaView (NGSolve's VTKOutput)."""
from __future__ import annotations

from pathlib import Path

import ngsolve as ngs


def write_series(result, directory: Path) -> Path:
    """Write one VTU (displacement, wear) per stored step and ``fields.pvd`` with their times."""
    disc = result.discretization
    mesh = disc.mesh
    u = ngs.GridFunction(disc.fes)
    wear = ngs.GridFunction(ngs.H1(mesh, order=result.scene.mesh.order, definedon="body"))
    vtk = ngs.VTKOutput(mesh, coefs=[u, wear], names=["displacement", "wear"],
                        filename=str(Path(directory) / "fields"), subdivision=result.scene.mesh.order - 1)
    body = mesh.Materials("body").Mask()
    for step in result.stored_steps:
        u.vec.FV().NumPy()[:] = result.displacement(step)
        wear.vec.FV().NumPy()[:] = disc.points.Q @ result.wear[step]
        vtk.Do(time=float(result.times[step]), drawelems=body)
    return Path(directory) / "fields.pvd"
