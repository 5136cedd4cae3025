"""What an engineer reads off a part, per step, computed from a run's recorded rows: each quantity once.

With m_i the weights of the contact points (moved by the geometry updates: :func:`row_weights`), s_v the step's
recorded speed factor, μ_i the step's friction (:func:`friction`) and the foundation's motion at the points
(:class:`~ngwear.numerics.contact.Motion`: ‖v*_i‖ and n*_i at s_v = 1, the moment arms):

* ``normal_force``  Σ m_i (p_i + λ_i), the force the foundation carries;
* ``torque``  T = sign(s_v) Σ m_i μ_i p_i ((x_i − c) × n*_i)·e, the friction moment about the counterface's axis
  (negative: it opposes the rotation);
* ``tangential_force``  F_t = sign(s_v) Σ m_i μ_i p_i n*_i, the friction force on the foundation (against its slip),
  ``friction_force`` ‖F_t‖ and ``apparent_friction`` ‖F_t‖ / normal force (0 where that is 0): μ where every point
  slides one way and none is held at the bound, less on a turning counterface, where the points' friction forces
  point different ways;
* ``friction_power``  P = |s_v| Σ m_i μ_i p_i ‖v*_i‖ (|T ω| on a turning counterface, F_t·v on a translating one) and
  ``dissipated_energy`` ∫₀ᵗ P dt (trapezoidal over the steps);
* ``contact_area``  Σ m_i over the points with p_i + λ_i > 0, ``mean_pressure`` normal force / contact area;
* ``total_wear`` w + Σ W (the wear the geometry updates moved into the body), ``wear_volume`` Σ m_i (w + Σ W)_i,
  ``max_wear`` its largest value, ``remaining_thickness`` the worn region's thickness less it;
* ``penetration`` u_ν − d₀ (d₀ of the face as it is) and ``compression`` u_ν − d₀ − w.

:data:`QUANTITIES` maps each name to its function of the record; :class:`~ngwear.results.result.Result` has each as
a property of the same name.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import cumulative_trapezoid

from ..numerics.points import initial_distance


def weighted(values: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Σ_i values_ji m_i of each step j: one set of weights (n,) or (1, n), or a row per step (N, n)."""
    if weights.ndim == 1 or len(weights) == 1:
        return values @ weights.reshape(-1)
    return np.einsum("ji,ji->j", values, weights)


def row_weights(r) -> np.ndarray:
    """m_i of each step, (N, n), or of all (n,) while the geometry never moved: an update moves them."""
    if not len(r.removed_rows):
        return r.weights
    rows = np.searchsorted(r.removed_rows, np.arange(len(r.times)), side="left")   # updates before each
    return np.vstack([r.weights, r.moved_weights])[rows]


def friction(r) -> np.ndarray:
    """μ_i of each step, shape (N, n) or (1, n) (coefficients fixed for the run: ``friction_coefficient``)."""
    return r.rows["step_friction"] if "step_friction" in r.rows else r.friction_coefficient[None, :]


def normal_force(r) -> np.ndarray:
    """Σ m_i (p_i + λ_i) per step: the force the foundation carries."""
    return weighted(r.pressure + r.reaction, row_weights(r))


def torque(r) -> np.ndarray:
    """The friction moment about the counterface's axis per step (negative when it brakes a rotation)."""
    return np.sign(r.speed_factor) * weighted(r.pressure, friction(r) * r.motion.moment_arms() * row_weights(r))


def tangential_force(r) -> np.ndarray:
    """F_t = Σ m_i μ_i p_i n*_i per step, shape (N, d): the friction force on the foundation."""
    return np.sign(r.speed_factor)[:, None] * ((r.pressure * friction(r) * row_weights(r)) @ r.motion.direction)


def friction_force(r) -> np.ndarray:
    """‖F_t‖ per step."""
    return np.linalg.norm(tangential_force(r), axis=1)


def apparent_friction(r) -> np.ndarray:
    """‖F_t‖ / Σ m_i (p_i + λ_i) per step; 0 where the normal force is 0."""
    normal = normal_force(r)
    return np.divide(friction_force(r), normal, out=np.zeros_like(normal), where=normal > 0)


def friction_power(r) -> np.ndarray:
    """P = Σ m_i μ_i p_i ‖v*_i‖ per step (‖v*_i‖ of the step's speed factor)."""
    return np.abs(r.speed_factor) * weighted(r.pressure, friction(r) * r.motion.speed * row_weights(r))


def dissipated_energy(r) -> np.ndarray:
    """∫₀^{t_j} P dt per step, by the trapezoidal rule over the steps."""
    power = friction_power(r)
    return cumulative_trapezoid(power, r.times, initial=0.0) if len(power) else power


def contact_area(r) -> np.ndarray:
    """Σ m_i over the points in contact (p_i + λ_i > 0) per step."""
    return weighted(r.pressure + r.reaction > 0, row_weights(r))


def mean_pressure(r) -> np.ndarray:
    """Normal force / contact area per step (0 where nothing touches)."""
    area = contact_area(r)
    return np.divide(normal_force(r), area, out=np.zeros_like(area), where=area > 0)


def max_pressure(r) -> np.ndarray:
    """max_i p_i per step."""
    return r.pressure.max(axis=1, initial=0.0)


def total_wear(r) -> np.ndarray:
    """W plus, after geometry updates (``"surface"``), Σ W of the updates at or before each step."""
    if not len(r.removed_rows):
        return r.wear
    moved = np.zeros_like(r.wear)
    np.add.at(moved, r.removed_rows, r.removed)
    return r.wear + np.cumsum(moved, axis=0)


def max_wear(r) -> np.ndarray:
    """max_i of the total wear per step (w while the geometry never moved)."""
    return total_wear(r).max(axis=1, initial=0.0)


def wear_volume(r) -> np.ndarray:
    """Σ m_i (total wear)_i per step: the worn volume (an area in 2D)."""
    return weighted(total_wear(r), row_weights(r))


def remaining_thickness(r) -> np.ndarray:
    """The worn region's thickness along ν under each contact point, less the total wear, per step."""
    return r.thickness - total_wear(r)


def penetration(r) -> np.ndarray:
    """u_ν − d₀: how far Γ_C has moved into the layer (≤ g); d₀ of the face as it is (moved by the updates)."""
    reached = r.normal_displacement - r.d0[None, :]
    return reached - (total_wear(r) - r.wear) if len(r.removed_rows) else reached


def d0(r) -> np.ndarray:
    """The initial distance d₀ to the foundation at the contact points (as built)."""
    return initial_distance(r.contact_points, r.scene.contact.direction)


def geometry_updates(r) -> int:
    """The number of geometry updates (``wear.geometry = "surface"``)."""
    return len(r.removed_rows)


def compression(r) -> np.ndarray:
    """u_ν − d₀ − w: how far the remaining (unworn) layer is compressed (p acts where > 0)."""
    return penetration(r) - r.wear


QUANTITIES = {f.__name__: f for f in (row_weights, friction, normal_force, torque, tangential_force, friction_force,
                                     apparent_friction, friction_power, dissipated_energy, contact_area, mean_pressure,
                                     max_pressure, total_wear, max_wear, wear_volume, remaining_thickness, d0,
                                     geometry_updates, penetration, compression)}
"""The derived quantities by name (a :class:`~ngwear.results.result.Result` property each)."""
