"""What the contact points read at each step: the load factor, the foundation's slip and the contact laws there.

    s_F(t) (``loads.time_table``),   v*_i(t),   n*_i(t),   α_i(t) = κ_i ‖v*_i(t)‖,   μ_i n*_i(t),
    f_i = m_i (p_i (ν + μ_i n*_i) + λ_i ν)   (the contact forces),

(with a ``[programme]`` s_F and the speed factor s_v are its stops', :attr:`Contact.drive`)
with the coefficients μ_i, κ_i and the compliance's L_i at the contact points
(:class:`~ngwear.model.coefficients.Coefficients`) and the slip of :mod:`ngwear.model.kinematics`.  Every key it
reads invalidates nothing (:class:`~ngwear.model.keys.Level` ``NOTHING``): a :class:`Contact` is made anew for each
scene of a :class:`~ngwear.numerics.discrete.Discretization`, on the kept contact points and ν.

A coefficient is read per step through :meth:`Contact.coefficients_at`.  A coefficient of state (one that names the
temperature T, the pressure p or the sliding speed v, :mod:`ngwear.model.coefficients`) is evaluated from the last
step's state, explicitly: :meth:`Contact.update` before each step (:mod:`ngwear.runs.heating`), from the initial
state (T₀, p = 0, ‖v*(x_i, 0)‖) before the first; the others are fields of x, evaluated once.
"""
from __future__ import annotations

import numpy as np

from ..model.coefficients import Coefficients, stateful
from ..model.compliance import compliance_from
from ..model.keys import SceneError, piecewise_linear
from ..model.kinematics import Slip
from ..model.programme import Drive, Schedule
from ..model.rules import BIG

DRIFT = 0.1
"""Largest change of a μ of the state, relative to its largest value, within which the dense Newton matrices of the
reference μ are kept (:attr:`Contact.reference`)."""


class Contact:
    """The contact's data at the points: coefficients, compliance p, slip v*, and their values at each step t.

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
        Friction or wear where the foundation does not slide, or a wear rate κ‖v*‖·L·T that overflows.

    Attributes
    ----------
    coefficients : Coefficients
        μ_i, κ_i and L_i at the initial state (:meth:`coefficients_at` reads those of the current step).
    law : Compliance
        The compliance p with L = L_i.
    slip : Slip
        The foundation's velocity at the points.
    reference : ndarray or None
        With a μ of the state, the reference μ_ref whose dense Newton matrices are factorised and precondition the
        steps' (:class:`~ngwear.numerics.solver.Factors`): the μ of a step, kept while max |μ − μ_ref| ≤ ``DRIFT``
        max |μ_ref| (a checkpoint keeps it: a resumed run refines from the same factors); None for μ of x.
    """

    def __init__(self, scene, points, nu: np.ndarray):
        self.scene, self.weights, self.nu, self.coords = scene, points.weights, nu, points.coords
        self.drive = None if scene.programme is None else Drive(Schedule.of(scene.programme))
        self.slip = Slip(scene.foundation, points.coords, nu, None if self.drive is None else self.drive.speed)
        self.stateful = stateful(scene.contact)
        if "stiffness" in self.stateful:
            raise SceneError("contact.stiffness: a stiffness of the state (T, p, v) is not evaluated in the time loop "
                             "(friction and wear are): give a number or a field of x, y, z")
        state = self.initial_state()
        self.coefficients = Coefficients.of(scene.contact, points.coords, state, None if state is None else 0.0)
        self.reset()
        self.law = compliance_from(scene.contact, self.coefficients.stiffness)
        self._check_motion()

    def initial_state(self) -> dict[str, np.ndarray] | None:
        """The state before the first step: T₀ (``heat.initial``), p = 0, ‖v*(x_i, 0)‖; None without a coefficient of it."""
        if not self.stateful:
            return None
        n = len(self.weights)
        return {"T": np.full(n, self.scene.heat.start), "p": np.zeros(n), "v": self.slip.speeds(0.0)}

    def update(self, state: dict[str, np.ndarray], t: float) -> None:
        """The coefficients of the next step from the state {"T", "p", "v": (n,)} at t (the last step's): explicit.

        A value out of range is a SceneError naming the key, the point, the state there and t.
        """
        self.current = self.current.updated(self.scene.contact, self.coords, state, t)
        friction, reference = self.current.friction, self.reference
        if reference is not None and np.abs(friction - reference).max() > DRIFT * np.abs(reference).max(initial=0.0):
            self.reference = friction

    def reset(self) -> None:
        """Back to the coefficients of the initial state (a new run on this contact)."""
        self.current = self.coefficients
        self.reference = self.coefficients.friction if "friction" in self.stateful else None

    def _check_motion(self) -> None:
        """Friction and wear need the foundation to slide; the fastest wear rate stays finite (the fields' values)."""
        sliding = self.slip.speed.any()
        for name, values in (("friction", self.coefficients.friction), ("wear", self.coefficients.wear)):
            if values.any() and not sliding:
                raise SceneError(f"foundation.velocity: must slide along Γ_C (a part tangential to contact.direction, "
                                 f"or foundation.angular_velocity about an axis along it) when contact.{name} > 0 "
                                 "somewhere")
        rate = self.largest_rate() * self.scene.time.T
        if not rate <= BIG:
            raise SceneError(f"contact.wear: κ‖v*‖·L·T = {rate:.3g} must be <= {BIG:g} at every contact point (the "
                             "wear of a run this fast overflows)")

    def coefficients_at(self, t: float) -> Coefficients:
        """μ_i, κ_i, L_i for the step at t: the fields of x, and the coefficients of state of the last :meth:`update`."""
        return self.current

    def load_factor(self, t: float) -> float:
        """s_F(t), the factor of the loads (``loads.time_table``, or a programme's step: :attr:`drive`)."""
        return piecewise_linear(self.scene.loads.time_table, t) if self.drive is None else self.drive.load(t)

    def velocity(self, t: float) -> np.ndarray:
        """v*(x_i, t) at the contact points, shape (n, d)."""
        return self.slip.velocity(t)

    def n_star(self, t: float) -> np.ndarray:
        """n*_i(t) = −v*_τ/‖v*_τ‖ at the contact points, shape (n, d) (0 where the foundation does not slide)."""
        return self.slip.n_star(t)

    def alpha(self, t: float) -> np.ndarray:
        """α_i(t) = κ_i ‖v*(x_i, t)‖ (0 where the foundation does not slide)."""
        return self.coefficients_at(t).wear * self.slip.speeds(t)

    def friction_directions(self, t: float) -> np.ndarray:
        """μ_i n*_i(t), shape (n, d): the friction force per unit pressure at the contact points."""
        return self.coefficients_at(t).friction[:, None] * self.slip.n_star(t)

    def forces(self, pressure, reaction, t: float) -> np.ndarray:
        """Point forces on the foundation side, f_i = m_i (p_i (ν + μ_i n*_i) + λ_i ν), shape (n, d)."""
        b = self.nu[None, :] + self.friction_directions(t)
        return self.weights[:, None] * (pressure[:, None] * b + reaction[:, None] * self.nu[None, :])

    def largest_alpha(self) -> float:
        """Largest α = κ ‖v*‖ over the contact points and the speed table's nodes (s_v is piecewise linear)."""
        return float((self.coefficients.wear * self.slip.speed).max(initial=0.0)) * self._largest_factor()

    def largest_rate(self) -> float:
        """Largest α_i L_p,i over the contact points and time: the wear update's stiffness (its stability limit)."""
        slopes = self.law.slope(self.scene.contact.gap)
        with np.errstate(over="ignore"):
            return float((self.coefficients.wear * self.slip.speed * slopes).max(initial=0.0)) * self._largest_factor()

    def _largest_factor(self) -> float:
        if self.drive is not None:
            return self.drive.largest_speed
        return max((abs(f) for _, f in self.scene.foundation.speed_table), default=1.0)
