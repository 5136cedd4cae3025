"""VTU/PVD output of a result's stored steps for ParaView (NGSolve's VTKOutput)."""
from __future__ import annotations

from pathlib import Path

import ngsolve as ngs


def write_series(result, directory: Path) -> Path:
    """Write ``fields_stepNNNNN.vtu`` for every stored step and ``fields.pvd`` linking them."""
    disc = result.discretization
    gf = disc.gridfunction(disc.recover(result.forces[0], result.times[0]) * 0)
    wear = ngs.GridFunction(disc.full_form.w.space)
    vtk = ngs.VTKOutput(disc.mesh, coefs=[gf, wear], names=["displacement", "wear"],
                        filename=str(Path(directory) / "fields"),
                        subdivision=result.scene.mesh.order - 1)
    for step in result.stored_steps:
        gf.vec.FV().NumPy()[:] = result.displacement(step)
        wear.vec.FV().NumPy()[:] = disc.points.Q @ result.wear[step]
        vtk.Do(time=float(result.times[step]), drawelems=disc.mesh.Materials("body"))
    return Path(directory) / "fields.pvd"
