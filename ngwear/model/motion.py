"""The foundation's motion at the contact points, and the factors that drive each step of a run.

    v*(x, t) = s_v (ω × (x − c) + v₀),      n*(x, t) = −v*_τ / ‖v*_τ‖,      ‖v*(x, t)‖ = |s_v| ‖ω × (x − c) + v₀‖,

with v₀ = ``foundation.velocity``, ω = ``foundation.angular_velocity`` (a number in 2D: ω × r = ω (−r_y, r_x)) and
c = ``foundation.center``; v*_τ = v* − (v*·ν) ν.  Points where v*_τ = 0 (on the axis, or a foundation at rest) get
n* = 0 and ‖v*‖ = 0: no friction, no wear.  The friction force on the foundation is μ p n* per unit area; its
moment about the axis, T = Σ m_i μ p_i ((x_i − c) × n*_i)·e, is negative when it opposes the rotation
(e = ω/‖ω‖; without rotation e = −ν, in 2D e = e_z).

A step's factors, :class:`Instant`: the speed factor s_v and the loads' factor s_F.  Without a programme they are
``foundation.speed_table`` and ``loads.time_table`` at the step's time t (piecewise linear; an empty table is 1);
with one (:mod:`ngwear.model.programme`) they are those of the step's place (stop i, step j) on the stop's grid,
s = s₀ + (s₁ − s₀) j/m, the same bits for every stop of a block whatever its time.  The time loop makes each step's
instant here (:meth:`Motion.at`), solves with it and records s_v and s_F (``speed_factor``, ``load_factor``), so that
every output reads the factors the step used.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .keys import piecewise_linear
from .programme import Schedule

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


@dataclass(frozen=True)
class Instant:
    """The end of a step: its time ``t``, the speed factor ``speed`` = s_v and the loads' factor ``load`` = s_F there.

    ``place``: a programme's (stop, step) on the stop's grid; None without a programme.
    """

    t: float
    speed: float
    load: float
    place: tuple[int, int] | None = None


class Motion:
    """The foundation's velocity field at fixed points x_i of Γ_C (reference configuration) and a run's factors.

    Attributes
    ----------
    rigid : ndarray
        v*(x_i) at s_v = 1, shape (n, d).
    direction, speed : ndarray
        n*_i at s_v > 0 (n, d) and ‖v*(x_i)‖ at s_v = 1 (n,), 0 where the foundation does not slide.
    schedule : Schedule or None
        The programme's stops (None: the tables drive the run).
    """

    def __init__(self, scene, points: np.ndarray, nu):
        foundation = scene.foundation
        self.points, self.nu = np.asarray(points, dtype=float), np.asarray(nu, dtype=float)
        dim = self.points.shape[1]
        self.omega = foundation.angular_velocity if foundation.angular_velocity is not None else (
            0.0 if dim == 2 else (0.0, 0.0, 0.0))
        self.center = np.zeros(dim) if foundation.center is None else np.asarray(foundation.center, dtype=float)
        self.schedule = None if scene.programme is None else Schedule.of(scene.programme)
        self.speed_table, self.load_table = foundation.speed_table, scene.loads.time_table
        self.arms = self.points - self.center
        rigid = cross(np.asarray(self.omega, dtype=float), self.arms) + np.asarray(foundation.velocity, dtype=float)
        tangential = rigid - (rigid @ self.nu)[:, None] * self.nu
        norm = np.linalg.norm(tangential, axis=1)
        sliding = norm > RELATIVE_ZERO * max(np.linalg.norm(rigid, axis=1).max(initial=0.0), 1e-300)
        self.rigid = rigid
        self.direction = np.where(sliding[:, None], -tangential / np.where(sliding, norm, 1.0)[:, None], 0.0)
        self.speed = np.where(sliding, np.linalg.norm(rigid, axis=1), 0.0)

    # ---- the factors of a step ---------------------------------------------------------------
    def at(self, t: float, place: tuple[int, int] | None = None) -> Instant:
        """The instant t: the tables' factors there, or (a programme) those of ``place`` = (stop, step)."""
        if self.schedule is None:
            return Instant(t, piecewise_linear(self.speed_table, t), piecewise_linear(self.load_table, t))
        stop, step = place
        phase = step / self.schedule.steps
        speed, load = (float(ends[stop, 0] + (ends[stop, 1] - ends[stop, 0]) * phase)
                       for ends in (self.schedule.speed, self.schedule.load))
        return Instant(t, speed, load, (int(stop), int(step)))

    @property
    def largest_speed(self) -> float:
        """Max |s_v| over the run (the tables and a programme's ramps are piecewise linear: their nodes)."""
        if self.schedule is not None:
            return float(np.abs(self.schedule.speed).max())
        return max((abs(f) for _, f in self.speed_table), default=1.0)

    @property
    def largest_load(self) -> float:
        """Max |s_F| over the run."""
        if self.schedule is not None:
            return float(np.abs(self.schedule.load).max())
        return max((abs(f) for _, f in self.load_table), default=1.0)

    # ---- the velocity at a speed factor ------------------------------------------------------
    def velocity(self, speed: float) -> np.ndarray:
        """v*(x_i) at the speed factor s_v, shape (n, d)."""
        return speed * self.rigid

    def n_star(self, speed: float) -> np.ndarray:
        """n*(x_i) at s_v, shape (n, d): the unit tangential direction opposite to the slip, 0 where none."""
        return np.sign(speed) * self.direction

    def speeds(self, speed) -> np.ndarray:
        """‖v*(x_i)‖ at s_v (a number, or one per step: shape (N, n)), 0 where the foundation does not slide."""
        return np.multiply.outer(np.abs(speed), self.speed)

    @property
    def sliding(self) -> bool:
        """Whether the foundation slides anywhere along Γ_C (at s_v ≠ 0)."""
        return bool(self.speed.any())

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
