"""Foundation kinematics at the contact points: translation and rotation of the counterface.

    v*(x, t) = s_v(t) (ω × (x − c) + v₀),      n*(x, t) = −v*_τ / ‖v*_τ‖,      α(x, t) = κ ‖v*(x, t)‖,

with v₀ = ``foundation.velocity``, ω = ``foundation.angular_velocity`` (a number in 2D: ω × r =
ω (−r_y, r_x)), c = ``foundation.center`` and s_v the ``speed_table``; v*_τ = v* − (v*·ν) ν.  Points
where v*_τ = 0 (on the axis, or a foundation at rest) get n* = 0 and α = 0: no friction, no wear.
The friction force on the foundation is μ p n* per unit area; its moment about the axis,
T = Σ m_i μ p_i ((x_i − c) × n*_i)·e, is negative when it opposes the rotation (e = ω/‖ω‖; without
rotation e = −ν, in 2D e = e_z).
"""
from __future__ import annotations

import numpy as np

from .keys import piecewise_linear

RELATIVE_ZERO = 1e-12
"""A tangential speed at most this fraction of the largest one counts as zero (points on the axis)."""


def cross(a, b: np.ndarray) -> np.ndarray:
    """Row-wise a × b; in 2D a is the scalar ω (out of plane) and the result lies in the plane."""
    b = np.atleast_2d(b)
    if b.shape[1] == 2:
        if np.ndim(a) == 0:
            return float(a) * np.column_stack([-b[:, 1], b[:, 0]])
        return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]          # (n, 2) × (n, 2): the z component
    return np.cross(np.broadcast_to(a, b.shape), b)


class Slip:
    """The foundation's velocity field at fixed points x_i of Γ_C (reference configuration)."""

    def __init__(self, foundation, points: np.ndarray, nu, factor=None):
        """``factor``: s_v(t) if not the ``speed_table``'s (a programme's :class:`~ngwear.model.programme.Drive`)."""
        self._factor = factor
        self.points, self.nu = np.asarray(points, dtype=float), np.asarray(nu, dtype=float)
        dim = self.points.shape[1]
        self.omega = foundation.angular_velocity if foundation.angular_velocity is not None else (
            0.0 if dim == 2 else (0.0, 0.0, 0.0))
        self.center = np.zeros(dim) if foundation.center is None else np.asarray(foundation.center, dtype=float)
        self.table = foundation.speed_table
        arms = self.points - self.center
        rigid = cross(np.asarray(self.omega, dtype=float), arms) + np.asarray(foundation.velocity, dtype=float)
        tangential = rigid - (rigid @ self.nu)[:, None] * self.nu
        norm = np.linalg.norm(tangential, axis=1)
        sliding = norm > RELATIVE_ZERO * max(np.linalg.norm(rigid, axis=1).max(initial=0.0), 1e-300)
        self.rigid = rigid                                             # v* at s_v = 1
        self.direction = np.where(sliding[:, None], -tangential / np.where(sliding, norm, 1.0)[:, None], 0.0)
        self.speed = np.where(sliding, np.linalg.norm(rigid, axis=1), 0.0)
        self.arms = arms

    def factor(self, t: float) -> float:
        """s_v(t)."""
        return piecewise_linear(self.table, t) if self._factor is None else self._factor(t)

    def velocity(self, t: float) -> np.ndarray:
        """v*(x_i, t), shape (n, d)."""
        return self.factor(t) * self.rigid

    def n_star(self, t: float) -> np.ndarray:
        """n*(x_i, t), shape (n, d): the unit tangential direction opposite to the slip, 0 where none."""
        return np.sign(self.factor(t)) * self.direction

    def speeds(self, t: float) -> np.ndarray:
        """‖v*(x_i, t)‖ at sliding points, 0 elsewhere (α = κ × this)."""
        return abs(self.factor(t)) * self.speed

    @property
    def rotating(self) -> bool:
        return bool(np.any(np.asarray(self.omega) != 0))

    @property
    def axis(self) -> np.ndarray | float:
        """e: ω/‖ω‖ (3D), sign ω (2D); without rotation −ν (3D), +1 (2D)."""
        if self.points.shape[1] == 2:
            return float(np.sign(self.omega)) if self.omega else 1.0
        omega = np.asarray(self.omega, dtype=float)
        return omega / np.linalg.norm(omega) if omega.any() else -self.nu

    def moment_arms(self) -> np.ndarray:
        """((x_i − c) × n*_i)·e while s_v > 0, shape (n,): torque per unit tangential force (times sign s_v)."""
        moment = cross(self.arms, self.direction)
        return moment * self.axis if moment.ndim == 1 else moment @ self.axis
