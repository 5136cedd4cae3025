"""What the contact points read at each step: the foundation's motion, the coefficients and the laws there.

    v*_i = s_v v*(x_i),   n*_i,   α_i = α(κ_i, μ_i, ‖v*_i‖),   w' = α g(p),   μ_i n*_i,
    f_i = m_i (p_i (ν + μ_i n*_i) + λ_i ν)   (the contact forces),

at a step's speed factor s_v (:class:`~ngwear.model.motion.Instant`, made by the time loop through
:attr:`Contact.motion`), with the coefficients μ_i, κ_i and the compliance's L_i at the contact points
(:class:`~ngwear.model.coefficients.Coefficients`), the compliance p and the wear law (:mod:`ngwear.model.wear_laws`).
Every key it reads invalidates nothing (:class:`~ngwear.model.keys.Level` ``NOTHING``): a :class:`Contact` is made
anew for each scene of a :class:`~ngwear.numerics.discrete.Discretization`, on the kept contact points and ν.

A contact does not change during a run: the coefficients a step is solved with are passed to it (a run's state holds
them).  A coefficient of state (one that names the temperature T, the pressure p or the sliding speed v,
:mod:`ngwear.model.coefficients`) is evaluated from the last step's state, explicitly, before each step
(:mod:`ngwear.runs.heating`), from the initial state (T₀, p = 0, ‖v*(x_i)‖ at the first step's s_v) before the first;
the others are fields of x, evaluated once (:attr:`Contact.coefficients`).
"""
from __future__ import annotations

import numpy as np

from ..model.coefficients import Coefficients, stateful
from ..model.compliance import compliance_from
from ..model.keys import SceneError
from ..model.motion import Motion
from ..model.rules import BIG
from ..model.wear_laws import wear_law


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
        μ_i, κ_i and L_i at the initial state (a run's state holds those of its steps, :mod:`ngwear.runs.state`).
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
        n, first = len(self.weights), self.motion.at(0.0, None if self.motion.schedule is None else (0, 0))
        return {"T": np.full(n, self.scene.heat.start), "p": np.zeros(n), "v": self.motion.speeds(first.speed)}

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

        α at the largest speed factor of the run (:attr:`~ngwear.model.motion.Motion.largest_speed`; s_v is piecewise
        linear), the coefficients of the initial state.
        """
        law, c = self.wear_law, self.coefficients
        with np.errstate(over="ignore"):
            slopes = law.slope(law.alpha(c.wear, c.friction, self.motion.speed), self.law, self.scene.contact.gap)
            return float(np.max(slopes, initial=0.0)) * law.factor_power(self.motion.largest_speed)
