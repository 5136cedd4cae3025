"""The stops of a programme's run, one row each: what ``stops.csv`` and ``Result.stops`` hold.

A simulated stop's rows are its start and its m steps (:meth:`~ngwear.model.programme.Schedule.rows`); its numbers
are integrals over them by the trapezoidal rule on the stop's grid:

* ``energy``  ∫ P dt, P = Σ m_i μ_i p_i ‖v*_i‖ (:attr:`Result.friction_power <ngwear.results.result.Result>`: μ_i and
  m_i of the step, a coefficient of state and a geometry update change them);
* ``torque``, ``friction_force``, ``apparent_friction``  their means over the stop's sliding, ∫ X |s_v| dt / ∫ |s_v| dt
  (s_v the speed factor): the torque is the stop's energy over its sliding angle, ∫ T ω dt / ∫ ω dt on a turning
  counterface, the friction force its energy over its sliding distance on a translating one, and the instant at rest
  (s_v = 0) weighs nothing; ``apparent_friction`` is ‖F_t‖ / normal force per step
  (:mod:`ngwear.results.derived`);
* ``worn_volume``  Σ m_i Δw_i, Δw the stop's increment of the total wear (end minus start), m_i the weights at its
  end, and ``worn_mass`` ρ times it (with ``material.density``);
* ``max_total_wear``, ``min_remaining_thickness``  at its end, and the taper of the remaining thickness there
  (:func:`tapers`): ``taper_radial`` and ``taper_circumferential`` on a turning counterface, ``taper_along`` on a
  translating one, and ``taper_slope`` of any part;
* with a temperature (``heat.model = "conduction"``): ``temperature_start``, ``temperature_peak``,
  ``temperature_end`` of the body's highest temperature (``max_temperature``) at the stop's first row, the maximum
  over its rows and at its last row, and ``foundation_temperature_start``, ``…_peak``, ``…_end`` of the
  counterface's: the wear-versus-temperature table of a wear test.

A jumped stop (``programme.jump``) repeats the last simulated stop before it: its energy and means, its increment
(the jump adds N Δw), so the k-th jumped stop after simulated stop s ends with the wear w_s + k Δw_s, and its
temperatures (the jump's premise: its stops are the simulated one's; the heat of jumped stops is not simulated, the
crossing over them only cools).
"""
from __future__ import annotations

import numpy as np

from ..model.programme import Schedule
from .metrics import disc_taper, plane_slope, taper_along

TAPERS = ("taper_radial", "taper_circumferential", "taper_along", "taper_slope")
"""The tapers of :func:`tapers` (the first two on a turning counterface, the third on a translating one)."""
COLUMNS = ("stop", "block", "start", "energy", "torque", "friction_force", "apparent_friction", "worn_volume",
           "worn_mass", "max_total_wear", "min_remaining_thickness", *TAPERS, *(
               f"{field}_{when}" for field in ("temperature", "foundation_temperature")
               for when in ("start", "peak", "end")), "simulated")
"""The columns of ``stops.csv`` (``worn_mass`` only with ``material.density``, the temperatures only with heat)."""

TEMPERATURES = {"temperature": "max_temperature", "foundation_temperature": "foundation_temperature"}
"""The stop table's temperature columns' prefix and the step field each reads (with ``heat.model = "conduction"``)."""
QUANTITIES = {"start": "time", "energy": "energy", "torque": "torque", "friction_force": "force",
              "worn_volume": "volume", "worn_mass": "mass", "max_total_wear": "length",
              "min_remaining_thickness": "length", "taper_radial": "length", "taper_circumferential": "length",
              "taper_along": "length", **{c: "temperature" for c in COLUMNS if "temperature" in c}}
"""The quantity of each column with a unit (``stops.csv``'s headers, :func:`ngwear.results.history_csv.headed`)."""


def _trapezoid(values: np.ndarray, times: np.ndarray) -> float:
    """∫ v dt by the trapezoidal rule over the stop's rows."""
    return float(np.trapezoid(values, times))


def _sliding_mean(values: np.ndarray, speed: np.ndarray, times: np.ndarray) -> float:
    """∫ v |s_v| dt / ∫ |s_v| dt over the stop's rows (a stop that slides nothing: the plain mean)."""
    sliding = _trapezoid(np.abs(speed), times)
    if sliding > 0:
        return _trapezoid(values * np.abs(speed), times) / sliding
    span = times[-1] - times[0]
    return _trapezoid(values, times) / span if span > 0 else float(values[0])


def tapers(result, values: np.ndarray) -> dict[str, float]:
    """The taper of ``values`` over Γ_C (:mod:`ngwear.results.metrics`), of the remaining thickness in a life.

    On a turning counterface the radial (outer − inner) and circumferential (leading − trailing) taper of the fit
    v ≈ a + b r + c φ, on a translating one leading − trailing of v ≈ a + b ξ; of any part ``taper_slope``, the
    norm ‖g‖ of the best-fit plane v ≈ a + g·x (a length per length).
    """
    scene, points, weights = result.scene, result.contact_points, result.weights
    out, omega = {}, scene.foundation.angular_velocity
    if omega is not None and np.any(omega):
        center = scene.foundation.center or np.zeros(scene.dim)
        out["taper_radial"], out["taper_circumferential"] = disc_taper(points, values, weights, center, omega)
    elif scene.foundation.velocity is not None and np.any(scene.foundation.velocity):
        out["taper_along"] = taper_along(points, values, weights, scene.foundation.velocity)
    nu = np.linalg.svd(points - points.mean(axis=0), full_matrices=False)[2][-1]     # the face's mean normal
    out["taper_slope"] = float(np.linalg.norm(plane_slope(points, values, weights, nu)))
    return out


def stop_table(result, taper: bool = True):
    """A DataFrame, one row per stop completed (simulated or jumped) in the programme's order (see the module).

    ``taper=False`` leaves out the tapers (a fit over Γ_C per stop: most of the table's time).
    """
    import pandas as pd

    scene = result.scene
    schedule = Schedule.of(scene.programme)
    m, rows = schedule.steps, len(result.times)
    stop_of = schedule.rows(result.jumped)[0][:rows]
    power = result.friction_power                     # μ of each step (a coefficient of state: the one it used)
    torque, force, apparent = result.torque, result.friction_force, result.apparent_friction
    total, remaining, weights = result.total_wear, result.remaining_thickness, result.row_weights
    density = scene.value("material.density")
    heated = {name: getattr(result, field) for name, field in TEMPERATURES.items() if field in result.rows}
    records, jumped = {}, set(result.jumped.tolist())
    for end in schedule.ends(rows):
        span, stop = slice(end - m, end + 1), int(stop_of[end])
        times, speed = result.times[span], result.speed_factor[span]
        increment = total[end] - total[end - m]
        row = {"energy": _trapezoid(power[span], times), "torque": _sliding_mean(torque[span], speed, times),
               "friction_force": _sliding_mean(force[span], speed, times),
               "apparent_friction": _sliding_mean(apparent[span], speed, times),
               "worn_volume": float(increment @ (weights if weights.ndim == 1 else weights[end]))}
        heat = {f"{name}_{when}": float(value) for name, values in heated.items()
                for when, value in (("start", values[span][0]), ("peak", values[span].max()), ("end", values[end]))}
        k = stop
        while k == stop or k in jumped:                  # the simulated stop, then the stops jumped after it
            left = remaining[end] - (k - stop) * increment
            records[k] = {**row, "max_total_wear": float((total[end] + (k - stop) * increment).max()),
                          "min_remaining_thickness": float(left.min()), **(tapers(result, left) if taper else {}),
                          **heat, "simulated": k == stop}
            k += 1
    order = sorted(records)
    table = pd.DataFrame([records[i] for i in order], index=pd.Index(order, name="stop"))
    if not len(order):
        shown = tapers(result, result.thickness) if taper else {}
        table = pd.DataFrame(columns=[c for c in COLUMNS if c not in ("stop", "block", "start", "worn_mass") and
                                      (heated or "temperature" not in c) and (c not in TAPERS or c in shown)],
                             index=pd.Index([], name="stop", dtype=int))
    table.insert(0, "block", schedule.block[order])
    table.insert(1, "start", schedule.start[order])
    if density is not None:
        table.insert(table.columns.get_loc("worn_volume") + 1, "worn_mass", density * table["worn_volume"])
    return table

