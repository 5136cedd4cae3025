"""What a whole run did, as ``summary.json`` and ``ngwear run`` report it before its last step.

Of the torque T, the friction force ‖F_t‖ and the pressure, the ``_peak`` (the value of the largest magnitude, its
sign kept; the pressure's: max p over the points and the steps) and the ``_mean`` over the run's time
(1/(t_N − t_0) ∫ f dt by the trapezoidal rule over the steps; the pressure's: of the mean contact pressure, normal
force / contact area); the ``dissipated_energy`` ∫ P dt, P = Σ m_i μ_i p_i ‖v*_i‖ (∫ |T ω| dt on a turning
counterface, ∫ F_t·v dt on a translating one); the worn volume and, where ``material.density`` ρ is given for the
regions that carry Γ_C (one value), its mass ρ V; ``gap_reached_at``, the first step time at which the layer's max w
reached g
to within :data:`WORN_THROUGH` (None: never; w approaches g only asymptotically, as the layer's pressure that drives
it vanishes there).  A signed zero is written as 0 (a stop at rest: T = 0, not −0).
"""
from __future__ import annotations

import numpy as np

QUANTITIES = {"end_time": "time", "torque_peak": "torque", "torque_mean": "torque", "friction_force_peak": "force",
              "friction_force_mean": "force", "pressure_peak": "pressure", "pressure_mean": "pressure",
              "dissipated_energy": "energy", "wear_volume": "volume", "wear_mass": "mass",
              "gap_reached_at": "time"}
"""The whole run's numbers (in the order of the summary) and their quantities (:mod:`ngwear.results.units`)."""
WORN_THROUGH = 1e-2
"""The layer counts as worn through where w ≥ (1 − this) g."""


def whole_run(result) -> dict:
    """The numbers of :data:`QUANTITIES` for ``result`` (``wear_mass`` only where ρ is given; no steps: {})."""
    times = result.times
    if not len(times):
        return {}
    out = {"end_time": float(times[-1])}
    for name in ("torque", "friction_force"):
        values = getattr(result, name)
        out[f"{name}_peak"], out[f"{name}_mean"] = peak(values), time_mean(times, values)
    out["pressure_peak"] = float(result.max_pressure.max())
    out["pressure_mean"] = time_mean(times, result.mean_pressure)
    out["dissipated_energy"] = float(result.dissipated_energy[-1])
    out["wear_volume"] = float(result.wear_volume[-1])
    density = layer_density(result)
    if density is not None:
        out["wear_mass"] = density * out["wear_volume"]
    reached = np.flatnonzero(result.wear.max(axis=1, initial=0.0) >= (1 - WORN_THROUGH) * result.scene.contact.gap)
    out["gap_reached_at"] = float(times[reached[0]]) if len(reached) else None
    return {name: value if value is None else value + 0.0 for name, value in out.items()}    # −0 → 0


def peak(values: np.ndarray) -> float:
    """The value of the largest magnitude (the first of equal ones), with its sign."""
    return float(values[np.argmax(np.abs(values))])


def time_mean(times: np.ndarray, values: np.ndarray) -> float:
    """1/(t_N − t_0) ∫ f dt by the trapezoidal rule; the value itself for a single step."""
    span = times[-1] - times[0]
    return float(np.trapezoid(values, times) / span) if span > 0 else float(values[-1])


def layer_density(result) -> float | None:
    """ρ of the regions carrying Γ_C (all regions without a mesh) when they give one value; else None."""
    scene, disc = result.scene, result.discretization
    regions = disc.body.contact_regions if disc is not None else scene.geometry.regions
    values = {table.density for table in scene.material.by_region(regions).values()}
    return float(values.pop()) if len(values) == 1 and None not in values else None
