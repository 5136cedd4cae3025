"""Every picture a run gets: what ``ngwear run`` writes beside its results.

The paper's four frames (Figs. 1–4) of the body, its layer and the foundation; the wear and the
pressure along Γ_C (2D) or maps of the contact face (3D); the normal force, torque, worn volume and
plate displacement over time; for a turning counterface p·r against the radius; for a part of several regions
(a backing) ``regions.png``, the last frame coloured by region; for contact coefficients given as fields
``coefficients.png``, their maps (μ, κ, L); with ``heat`` ``temperatures.png`` and the surface temperature's map;
for a programme ``life.png``, the remaining thickness's map, its tapers against the stops and the wear per block.
"""
from __future__ import annotations

from pathlib import Path

from . import part_plots, plots, render


def write_pictures(result, out_dir) -> list[Path]:
    """Write the pictures that fit the result's scene into ``out_dir``; their paths."""
    out = Path(out_dir)
    paths = render.paper_figures(result, out)
    if result.scene.dim == 2:
        paths += [plots.wear_profiles(result, out / "wear.png"), plots.pressure_history(result, out / "pressure.png")]
    else:
        heated = ("surface_temperature",) if result.scene.heat.model != "none" else ()
        moved = ("remaining_thickness",) if result.scene.wear.geometry == "surface" else ()
        paths.append(part_plots.contact_maps(result, out / "contact_maps.png",
                                             fields=("pressure", "wear", *moved, *heated)))
    paths.append(part_plots.history(result, out / "history.png"))
    if len(result.discretization.mesh.GetMaterials()) > 1:
        paths.append(render.save_frame(result, -1, out / "regions.png", field="region"))
    if part_plots.varying(result):
        paths.append(part_plots.coefficient_maps(result, out / "coefficients.png"))
    if result.scene.heat.model != "none":
        paths.append(part_plots.temperatures(result, out / "temperatures.png"))
    if result.motion.rotating:
        paths.append(part_plots.pressure_radius(result, out / "pressure_radius.png"))
    if result.scene.programme is not None and result.steps >= result.scene.programme.steps_per_stop:  # a stop done
        paths.append(part_plots.life(result, out / "life.png"))
    return paths
