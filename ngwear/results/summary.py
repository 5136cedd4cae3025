"""The summary of a run: ``summary.json`` and what ``ngwear run`` prints, in three parts.

The whole run (:func:`ngwear.results.whole_run.whole_run`: peaks and means of the torque, the friction force and
the pressure, the dissipated energy, the worn volume and mass, when wear reached g, with the largest wear and
penetration); the last step's values (:data:`LAST_STEP`); a part's life (the remaining thickness, geometry updates,
stops) and the temperatures of a heated run; the solver's counts, times, ``materials`` (each region's law,
constants, m_F, L_F: see :func:`ngwear.results.material_summary.region_materials`, an energy law's moduli estimated
over the frames) and ``provenance`` (:mod:`ngwear.results.provenance`).
"""
from __future__ import annotations

import numpy as np

from ..model.programme import Schedule
from .material_summary import region_materials
from .metrics import per_block, stops_to_limit, thickness_range
from .step_fields import DERIVED
from .stops import stop_table, tapers
from .units import units
from .whole_run import QUANTITIES as RUN
from .whole_run import whole_run

PART = tuple(f.name for f in DERIVED if not f.shape)
"""The derived per-step numbers of a part."""
LAST = tuple(name for name in PART if name not in RUN and name != "max_wear")
"""What the summary reports of the last step: the derived per-step numbers the whole run's part does not hold."""
LAST_STEP = (*LAST, "plate_displacement", "contact_fraction", "active_fraction")
"""The summary's keys of the last step (the plate's only with a plate)."""


def summary(result) -> dict:
    """Key numbers of ``result`` (a :class:`~ngwear.results.result.Result`), in the order ``ngwear run`` prints."""
    its = [r.iterations for r in result.newton if r.converged]
    out = {
        "status": result.status,
        "steps": result.steps,
        "contact_points": len(result.weights),
        **whole_run(result),
        **_extremes(result),
        "gap": result.scene.contact.gap,
        **_last_step(result),
        **({"rejected_steps": result.rejected} if result.scene.time.adaptive else {}),
        **life_metrics(result),
        **heat_extremes(result),
        "newton_iterations_total": int(sum(its)),
        "newton_iterations_max": int(max(its, default=0)),
        "wall_time_s": round(result.wall_time, 3),
        "solve_time_s": round(result.solve_time, 3),
        "materials": region_materials(result.scene, result.discretization,
                                      [result.fields[s] for s in result.stored_steps if s in result.fields]),
        "warnings": list(result.warnings),
        **({"provenance": result.provenance} if result.provenance else {}),
    }
    if result.scene.units:
        out["units"] = units(result.scene, [name for name, value in out.items() if isinstance(value, float)
                                            or name == "gap_reached_at"])
    return out


def _extremes(result) -> dict[str, float]:
    """The largest total wear and penetration u_ν − d₀ (how far Γ_C moved into the layer) of the run; no steps: {}."""
    if not len(result.times):
        return {}
    return {"max_wear": float(result.max_wear.max()), "max_penetration": float(result.penetration.max())}


def _last_step(result) -> dict[str, float]:
    """:data:`LAST_STEP` of the last step (a signed zero as 0); no steps: {} (nothing computed, nothing to report)."""
    if not len(result.times):
        return {}
    last = {name: float(getattr(result, name)[-1]) + 0.0 for name in LAST}
    if result.plate_displacement.shape[1]:
        last["plate_displacement"] = float(result.plate_displacement[-1, 0]) + 0.0
    last["contact_fraction"] = float((result.pressure[-1] > 0).mean())
    last["active_fraction"] = float((result.reaction[-1] > 0).mean())
    return last


def life_metrics(result) -> dict:
    """The summary's wear metrics: the remaining thickness at the last step (min, mean, max), the stops.

    A part's life (a programme, or ``wear.geometry = "surface"``) adds the remaining thickness's tapers
    (:func:`~ngwear.results.stops.tapers`); a programme the wear of each block (``blocks``: its stops, the worn
    volume per stop and per MJ dissipated, :func:`~ngwear.results.metrics.per_block`) and, with ``wear.limit``,
    ``stops_to_limit``: the stops left at the last simulated stop's wear (:func:`~ngwear.results.metrics.stops_to_limit`).
    """
    scene = result.scene
    remaining = result.remaining_thickness_of(result.total_wear_at(-1)) if len(result.times) else result.thickness
    low, mean, high = thickness_range(remaining, result.weights)
    out = {"remaining_thickness_min": low, "remaining_thickness_mean": mean, "remaining_thickness_max": high}
    if scene.programme is not None or scene.wear.geometry == "surface":
        out.update(tapers(result, remaining))
    out["geometry_updates"] = result.geometry_updates
    if scene.programme is None:
        return {**out, "stops_simulated": 0, "stops_jumped": len(result.jumped)}
    m = scene.programme.steps_per_stop
    ends = Schedule.of(scene.programme).ends(len(result.times))
    out.update(stops_simulated=len(ends), stops_jumped=len(result.jumped))
    if scene.wear.limit is not None and len(ends):
        total = result.total_wear
        left = stops_to_limit(remaining, scene.wear.limit, total[ends[-1]] - total[ends[-1] - m])
        out["stops_to_limit"] = left if np.isfinite(left) else None
    stops = stop_table(result, taper=False)                     # its tapers are the stops', not the summary's
    blocks = per_block(stops["block"].to_numpy(), stops["worn_volume"].to_numpy(), stops["energy"].to_numpy())
    peaks = block_peaks(result)
    out["blocks"] = [{"block": b, "stops": int(count), "volume_per_stop": float(volume),
                      "volume_per_megajoule": float(energy) if np.isfinite(energy) else None, **peaks.get(b, {})}
                     for b, (count, volume, energy) in enumerate(zip(blocks["stops"], blocks["volume_per_stop"],
                                                                     blocks["volume_per_megajoule"])) if count]
    return out


def block_peaks(result) -> dict[int, dict[str, float]]:
    """Per block of a heated programme: ``peak_face_temperature`` and ``peak_track_temperature``.

    The highest temperature of the contact points and of the counterface over the block's simulated stops' rows (a
    jumped stop repeats a simulated one's).
    """
    if "surface_temperature" not in result.rows or not len(result.times):
        return {}
    schedule, rows = Schedule.of(result.scene.programme), len(result.times)
    block = schedule.block[schedule.rows(result.jumped)[0][:rows]]
    face, track = result.surface_temperature.max(axis=1), result.foundation_temperature
    return {int(b): {"peak_face_temperature": float(face[block == b].max()),
                     "peak_track_temperature": float(track[block == b].max())} for b in np.unique(block)}


def heat_extremes(result) -> dict[str, float]:
    """The highest temperature of the body and of the counterface and when (``heat``; none else)."""
    if "max_temperature" not in result.rows or not len(result.times):
        return {}
    body, face = int(np.argmax(result.max_temperature)), int(np.argmax(result.foundation_temperature))
    return {"max_temperature": float(result.max_temperature[body]),
            "max_temperature_time": float(result.times[body]),
            "max_foundation_temperature": float(result.foundation_temperature[face]),
            "max_foundation_temperature_time": float(result.times[face])}
