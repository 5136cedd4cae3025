"""The wear metrics an engineer reads, as functions of arrays at the contact points and per stop.

* remaining thickness: its smallest, mean (over the area, weights m_i) and largest value;
* taper: the slope of the best-fit plane of a field over Γ_C (any part), and for a pad on a turning disc the
  radial taper (outer minus inner) and the circumferential one (leading minus trailing, the leading edge being
  where the counterface enters), both from the fit v ≈ a + b r + c φ over the face, φ the angle about the disc's
  axis in its direction of turning; on a translating counterface the leading edge is the upstream one;
* per block of a programme: the wear per stop and per MJ dissipated (P = Σ m_i μ_i p_i ‖v*_i‖, integrated);
* the stops left to ``wear.limit`` at the last block's rate;
* the radius √(A/π) of the area in contact (a worn flat's, against Argatov's law).
"""
from __future__ import annotations

import math

import numpy as np


def thickness_range(remaining: np.ndarray, weights: np.ndarray) -> tuple[float, float, float]:
    """(min, mean over the area, max) of the remaining thickness at the contact points."""
    return float(remaining.min()), float(weights @ remaining / weights.sum()), float(remaining.max())


def contact_radius(weights: np.ndarray, pressure: np.ndarray, reaction: np.ndarray) -> float:
    """√(A/π), A = Σ m_i over the points in contact (p_i + λ_i > 0): the radius of a round contact area."""
    return math.sqrt(weights[pressure + reaction > 0].sum() / math.pi)


def _fit(columns: list[np.ndarray], values: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """The weighted least-squares coefficients of values ≈ Σ_k β_k column_k (a constant column first)."""
    root = np.sqrt(weights)
    design = np.column_stack([np.ones(len(values)), *columns]) * root[:, None]
    return np.linalg.lstsq(design, values * root, rcond=None)[0]


def plane_slope(points: np.ndarray, values: np.ndarray, weights: np.ndarray, nu) -> np.ndarray:
    """The gradient g (d-vector ⟂ ν) of the best-fit plane v ≈ a + g·x over Γ_C (its norm: the taper per length)."""
    nu = np.asarray(nu, dtype=float)
    plane = np.linalg.svd(nu[None, :])[2][1:]                        # an orthonormal basis of the plane ⟂ ν
    local = (points - points.mean(axis=0)) @ plane.T
    return _fit(list(local.T), values, weights)[1:] @ plane


def disc_taper(points: np.ndarray, values: np.ndarray, weights: np.ndarray, center, omega) -> tuple[float, float]:
    """(Radial: outer minus inner, circumferential: leading minus trailing) of a field over a pad on a turning disc.

    From the fit v ≈ a + b r + c φ, r the distance from the axis (through ``center`` along ω; in 2D ω is a number
    and the axis ⟂ the plane), φ the angle about it measured in the direction the disc turns from the face's
    mean angle: radial = b (r_max − r_min), circumferential = c (φ_min − φ_max), the counterface entering at φ_min.
    """
    arms = np.asarray(points, dtype=float) - np.asarray(center, dtype=float)
    if arms.shape[1] == 2:
        sign = float(np.sign(omega))
        u, v = arms[:, 0], sign * arms[:, 1]                        # turned to the positive sense of rotation
    else:
        axis = np.asarray(omega, dtype=float) / np.linalg.norm(omega)
        arms = arms - np.outer(arms @ axis, axis)
        first = arms.mean(axis=0) / np.linalg.norm(arms.mean(axis=0))
        u, v = arms @ first, arms @ np.cross(axis, first)
    r = np.hypot(u, v)
    mean = math.atan2(weights @ v, weights @ u)
    phi = np.angle(np.exp(1j * (np.arctan2(v, u) - mean)))
    _, b, c = _fit([r, phi], values, weights)
    return float(b * np.ptp(r)), float(c * (phi.min() - phi.max()))


def taper_along(points: np.ndarray, values: np.ndarray, weights: np.ndarray, velocity) -> float:
    """Leading minus trailing of a field over Γ_C on a counterface translating with ``velocity``.

    From the fit v ≈ a + b ξ, ξ = x·v̂: b (ξ_min − ξ_max), the counterface entering at the smallest ξ.
    """
    xi = np.asarray(points, dtype=float) @ (np.asarray(velocity, dtype=float) / np.linalg.norm(velocity))
    _, b = _fit([xi], values, weights)
    return float(b * (xi.min() - xi.max()))


def dissipated(times: np.ndarray, power: np.ndarray) -> float:
    """∫ P dt by the trapezoidal rule over the steps, P = Σ m_i μ_i p_i ‖v*_i‖ at each (:func:`friction_power`)."""
    return float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(times)))


def friction_power(weights: np.ndarray, friction: np.ndarray, pressure: np.ndarray, speeds: np.ndarray) -> np.ndarray:
    """P = Σ_i m_i μ_i p_i ‖v*_i‖ of each row (a step) of ``pressure`` and ``speeds`` (steps × points)."""
    return (pressure * speeds) @ (weights * friction)


def per_block(blocks: np.ndarray, volume: np.ndarray, energy: np.ndarray) -> dict[str, np.ndarray]:
    """Of each block: its ``stops``, the worn ``volume_per_stop`` and ``volume_per_megajoule`` dissipated.

    ``volume`` and ``energy``: of each stop (simulated or jumped), in the order of the programme.
    """
    count = np.bincount(blocks)
    worn, spent = np.bincount(blocks, weights=volume), np.bincount(blocks, weights=energy)
    per_energy = np.divide(worn * 1e6, spent, out=np.full(len(count), np.nan), where=spent > 0)
    return {"stops": count, "volume_per_stop": worn / np.maximum(count, 1), "volume_per_megajoule": per_energy}


def stops_to_limit(remaining: np.ndarray, limit: float, per_stop: np.ndarray) -> float:
    """The stops until the remaining thickness reaches ``limit`` somewhere, at the wear ``per_stop`` of each point.

    0 where it has already; inf where nothing wears.
    """
    wearing = per_stop > 0
    if (remaining <= limit).any():
        return 0.0
    if not wearing.any():
        return math.inf
    return float(np.min((remaining[wearing] - limit) / per_stop[wearing]))
