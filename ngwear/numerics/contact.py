"""What the contact points read at each step: the foundation's motion, the coefficients and the laws there.

    v*_i = s_v v*(x_i),   n*_i,   α_i = α(κ_i, μ_i, ‖v*_i‖),   w' = α g(p),   μ_i n*_i,
    f_i = m_i (p_i (ν + μ_i n*_i) + λ_i ν)   (the contact forces),

at a step's speed factor s_v (:class:`Instant`, made by the time loop through
:attr:`Contact.motion`), with the coefficients μ_i, κ_i and the compliance's L_i at the contact points
(:class:`~ngwear.model.coefficients.Coefficients`), the compliance p and the wear law (:mod:`ngwear.model.wear_laws`).
Every key it reads invalidates nothing (:class:`~ngwear.model.keys.Level` ``NOTHING``): a :class:`Contact` is made
anew for each scene of a :class:`~ngwear.numerics.discrete.Discretization`, on the kept contact points and ν.

A contact does not change during a run: the coefficients a step is solved with are passed to it (a run's state holds
them).  A coefficient of state (one that names the temperature T, the pressure p or the sliding speed v,
:mod:`ngwear.model.coefficients`) is evaluated from the last step's state, explicitly, before each step
(:mod:`ngwear.runs.heating`), from the initial state (T₀, p = 0, ‖v*(x_i)‖ at the first step's s_v) before the first;
the others are fields of x, evaluated once (:attr:`Contact.coefficients`).

The foundation's motion at the contact points (:class:`Motion`), and the factors that drive each step of a run:

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

from ..model.coefficients import Coefficients, stateful
from ..model.compliance import compliance_from
from ..model.keys import SceneError
from ..model.programme import Schedule
from ..model.rules import BIG
from ..model.wear_laws import wear_law

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


def _nodes(table) -> tuple[np.ndarray, np.ndarray] | None:
    """The times and values of a piecewise-linear table [[t, s], …] (None: empty, the factor 1)."""
    return tuple(np.array(column, dtype=float) for column in zip(*table)) if table else None


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
        The programme's stops (None: the tables drive the run, ``tables`` their nodes: s_v's, then s_F's).
    """

    def __init__(self, scene, points: np.ndarray, nu):
        foundation = scene.foundation
        self.points, self.nu = np.asarray(points, dtype=float), np.asarray(nu, dtype=float)
        dim = self.points.shape[1]
        self.omega = foundation.angular_velocity if foundation.angular_velocity is not None else (
            0.0 if dim == 2 else (0.0, 0.0, 0.0))
        self.center = np.zeros(dim) if foundation.center is None else np.asarray(foundation.center, dtype=float)
        self.schedule = None if scene.programme is None else Schedule.of(scene.programme)
        self.tables = tuple(_nodes(table) for table in (foundation.speed_table, scene.loads.time_table))
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
        """The instant t: the tables' factors there, or (a programme) those of ``place`` = (stop, step).

        Step m + 1 of the last stop is the programme's last dwell: no sliding, no load.
        """
        if self.schedule is None:
            speed, load = (1.0 if nodes is None else float(np.interp(t, *nodes)) for nodes in self.tables)
            return Instant(t, speed, load)
        stop, step = place
        phase = step / self.schedule.steps
        speed, load = (0.0 if step > self.schedule.steps else float(ends[stop, 0] + (ends[stop, 1] - ends[stop, 0]) *
                                                                      phase)
                       for ends in (self.schedule.speed, self.schedule.load))
        return Instant(t, speed, load, (int(stop), int(step)))

    def first(self) -> Instant:
        """The instant of a run's step 0: t = 0, at the first stop's start in a programme."""
        return self.at(0.0, None if self.schedule is None else (0, 0))

    @property
    def largest_speed(self) -> float:
        """Max |s_v| over the run (the tables and a programme's ramps are piecewise linear: their nodes)."""
        if self.schedule is not None:
            return float(np.abs(self.schedule.speed).max())
        return 1.0 if self.tables[0] is None else float(np.abs(self.tables[0][1]).max())

    @property
    def largest_load(self) -> float:
        """Max |s_F| over the run."""
        if self.schedule is not None:
            return float(np.abs(self.schedule.load).max())
        return 1.0 if self.tables[1] is None else float(np.abs(self.tables[1][1]).max())

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


class Contact:
    """The contact's data at the points: coefficients, compliance p, wear law, the motion; what a step reads of them.

    Parameters
    ----------
    scene : Scene
    points : ContactPoints
        x_i and m_i (:mod:`ngwear.numerics.points`).
    nu : ndarray
        The contact direction ν.

    Raises
    ------
    SceneError
        Friction or wear where the foundation does not slide, or a wear rate whose slope α g'(p(g)) L·T overflows.

    Attributes
    ----------
    coefficients : Coefficients
        μ_i, κ_i and L_i at the initial state (a run's state holds those of its steps, :class:`~ngwear.runs.step.State`).
    law : Compliance
        The compliance p with L = L_i.
    motion : Motion
        The foundation's velocity at the points and the run's factors s_v, s_F.
    wear_law : WearLaw
        w' = α g(p) (``contact.wear_law``).
    """

    def __init__(self, scene, points, nu: np.ndarray):
        self.scene, self.weights, self.nu, self.coords = scene, points.weights, nu, points.coords
        self.motion = Motion(scene, points.coords, nu)
        self.wear_law = wear_law(scene.contact)
        self.stateful = stateful(scene.contact)
        if "stiffness" in self.stateful:
            raise SceneError("contact.stiffness: a stiffness of the state (T, p, v) is not evaluated in the time loop "
                             "(friction and wear are): give a number or a field of x, y, z")
        state = self.initial_state()
        self.coefficients = Coefficients.of(scene.contact, points.coords, state, None if state is None else 0.0)
        self.law = compliance_from(scene.contact, self.coefficients.stiffness)
        self._check_motion()

    def initial_state(self) -> dict[str, np.ndarray] | None:
        """The state before the first step: T₀ (``heat.initial``), p = 0, ‖v*(x_i)‖ at the first step's s_v.

        None without a coefficient of the state.
        """
        if not self.stateful:
            return None
        n = len(self.weights)
        return {"T": np.full(n, self.scene.heat.start), "p": np.zeros(n), "v": self.motion.speeds(self.motion.first().speed)}

    def _check_motion(self) -> None:
        """Friction and wear need the foundation to slide; the fastest wear rate stays finite (the fields' values)."""
        sliding = self.motion.sliding
        for name, values in (("friction", self.coefficients.friction), ("wear", self.coefficients.wear)):
            if values.any() and not sliding:
                raise SceneError(f"foundation.velocity: must slide along Γ_C (a part tangential to contact.direction, "
                                 f"or foundation.angular_velocity about an axis along it) when contact.{name} > 0 "
                                 "somewhere")
        rate = self.largest_rate() * self.scene.time.T
        if not rate <= BIG:
            raise SceneError(f"contact.wear: the wear rate's slope α g'(p(g)) L·T = {rate:.3g} must be <= {BIG:g} at "
                             "every contact point (the wear of a run this fast overflows)")

    def alpha(self, coefficients: Coefficients, speed: float) -> np.ndarray:
        """α_i = α(κ_i, μ_i, ‖v*_i‖) at the speed factor s_v (0 where the foundation does not slide)."""
        return self.wear_law.alpha(coefficients.wear, coefficients.friction, self.motion.speeds(speed))

    def rate(self, coefficients: Coefficients, speed: float, pressure: np.ndarray) -> np.ndarray:
        """w'_i = α_i g(p_i) at s_v: the wear rate at the points."""
        return self.wear_law.rate(self.alpha(coefficients, speed), pressure)

    def friction_directions(self, coefficients: Coefficients, speed: float) -> np.ndarray:
        """μ_i n*_i at s_v, shape (n, d): the friction force per unit pressure at the contact points."""
        return coefficients.friction[:, None] * self.motion.n_star(speed)

    def forces(self, coefficients: Coefficients, pressure, reaction, speed: float) -> np.ndarray:
        """Point forces on the foundation side, f_i = m_i (p_i (ν + μ_i n*_i) + λ_i ν), shape (n, d)."""
        b = self.nu[None, :] + self.friction_directions(coefficients, speed)
        return self.weights[:, None] * (pressure[:, None] * b + reaction[:, None] * self.nu[None, :])

    def largest_rate(self) -> float:
        """Largest α_i g'(p(g)) L_p,i over the contact points and the run: the wear update's stiffness (its stability).

        α at the largest speed factor of the run (:attr:`Motion.largest_speed`; s_v is piecewise
        linear), the coefficients of the initial state.
        """
        law, c = self.wear_law, self.coefficients
        with np.errstate(over="ignore"):
            slopes = law.slope(law.alpha(c.wear, c.friction, self.motion.speed), self.law, self.scene.contact.gap)
            return float(np.max(slopes, initial=0.0)) * law.factor_power(self.motion.largest_speed)
