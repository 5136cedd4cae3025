"""Wear integrators for the wear law  w' = α g(p(u_ν − d₀ − w)),  α = α(κ, μ, ‖v*‖),  w(0) = 0.

Archard's law (the paper's) is α = κ‖v*‖, g(p) = p; the laws are declared in :mod:`ngwear.model.wear_laws`.  Every
integrator writes step j as the nodal relation  w_j = a_j + c_j g(p(z_j − w_j))  with z_j = s_j − d₀ known only
once step j is solved, so the solver sees the effective law p_j(z) = p(z − W(z)) with  W(z) = a + c g(p(z − W))
and  dp_j/dz = p'/(1 + c g'(p) p'):

with α = α_i per contact point (a rotating counterface slides faster away from its axis):

* ``explicit`` (paper eq. 15):  a_j = w_{j−1} + k α_{j−1} g(p_{j−1}),  c_j = 0  (first order;
  for p = L r₊ and Archard's law stable for k α L < 2, oscillating for k α L > 1);
* ``implicit`` (backward Euler):  a_j = w_{j−1},  c_j = k α_j  (first order, unconditionally stable);
* ``trapezoidal``:  a_j = w_{j−1} + k/2 α_{j−1} g(p_{j−1}),  c_j = k/2 α_j  (second order).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.compliance import Compliance
from ..model.programme import STEPS_PER_STOP
from ..model.wear_laws import WearLaw


@dataclass
class PointLaw:
    """Nodal contact law at one step: pressure p(z) and dp/dz as functions of z = s − d₀."""

    pressure: callable
    derivative: callable


INTEGRATORS = {
    # name: (weight of the previous rate in a_j, weight of the new rate in c_j)
    "explicit": (1.0, 0.0),
    "implicit": (0.0, 1.0),
    "trapezoidal": (0.5, 0.5),
}


def worn(law: Compliance, a: np.ndarray, c: np.ndarray, z: np.ndarray, wear_law) -> np.ndarray:
    """W(z) solving W = a + c g(p(z − W)) nodewise (W = a where z ≤ a or c = 0); g the wear law's."""
    if not np.any(c):
        return a
    r0 = z - a
    if law.is_linear and wear_law.linear:
        return a + c * law.stiffness * np.maximum(r0, 0.0) / (1 + c * law.stiffness)
    g, dg = wear_law.g, wear_law.dg
    lo, hi = a.copy(), np.maximum(z, a)
    p0 = law(r0)
    w = a + c * g(p0) / (1 + c * dg(p0) * law.derivative(r0))  # one Newton step from W = a
    w = np.clip(w, lo, hi)
    for _ in range(60):
        p = law(z - w)
        h = w - a - c * g(p)
        lo, hi = np.where(h < 0, w, lo), np.where(h > 0, w, hi)
        w_new = w - h / (1 + c * dg(p) * law.derivative(z - w))
        bad = (w_new <= lo) | (w_new >= hi)
        w_new[bad] = 0.5 * (lo + hi)[bad]
        if np.all(np.abs(w_new - w) <= 1e-15 * (1 + np.abs(w))):
            return w_new
        w = w_new
    return w


@dataclass(frozen=True)
class WearStep:
    """One step's nodal wear relation w_j = a + c g(p(z − w_j)) (:meth:`WearIntegrator.step`)."""

    a: np.ndarray
    c: np.ndarray
    law: Compliance
    wear_law: WearLaw

    def point_law(self) -> PointLaw:
        """The effective law p_j(z) the solver uses at this step."""
        law, a, c, wear_law = self.law, self.a, self.c, self.wear_law
        if not c.any():
            return PointLaw(lambda z: law(z - a), lambda z: law.derivative(z - a))
        if law.is_linear and wear_law.linear:  # closed form p = L (z − a)₊ / (1 + c L), free of cancellation in z − W
            scale = law.stiffness / (1 + c * law.stiffness)
            return PointLaw(lambda z: scale * np.maximum(z - a, 0.0), lambda z: np.where(z >= a, scale, 0.0))

        def derivative(z):
            r = z - worn(law, a, c, z, wear_law)
            dp = law.derivative(r)
            return dp / (1 + c * dp) if wear_law.linear else dp / (1 + c * wear_law.dg(law(r)) * dp)
        return PointLaw(lambda z: law(z - worn(law, a, c, z, wear_law)), derivative)

    def wear_at(self, z: np.ndarray) -> np.ndarray:
        """w_j for the solved z_j."""
        return worn(self.law, self.a, self.c, z, self.wear_law)


@dataclass(frozen=True)
class WearIntegrator:
    """One of the schemes of :data:`INTEGRATORS` for the compliance p and the wear law (any step size k each step)."""

    name: str
    law: Compliance
    wear_law: WearLaw

    def step(self, w: np.ndarray, pressure: np.ndarray, alpha: np.ndarray, alpha_next: np.ndarray,
             k: float) -> WearStep:
        """The step of size k from w_j, p_j and α_j, α_{j+1} (per contact point)."""
        theta_old, theta_new = INTEGRATORS[self.name]
        if theta_old and alpha.any():
            w = w + theta_old * k * alpha * self.wear_law.g(pressure)
        return WearStep(w, theta_new * k * alpha_next, self.law, self.wear_law)

    def rest(self, w: np.ndarray) -> WearStep:
        """A step that wears nothing from w (a programme's crossing of a dwell, step 0 of a run)."""
        return WearStep(w, np.zeros_like(w), self.law, self.wear_law)


def stable_step(scene, rate: float) -> float:
    """The largest step at which the wear update does not overshoot: 1/(αL_p) explicit, 2/(αL_p) trapezoidal.

    ``rate``: the largest α_i g'(p(g)) L_p,i over the points and time (:meth:`Contact.largest_rate`), L_p,i the
    largest slope of p_i over [0, g].  Implicit: no limit (inf).
    """
    limit = {"explicit": 1.0, "trapezoidal": 2.0, "implicit": np.inf}[scene.wear.integrator]
    return limit / rate if rate > 0 else np.inf


def steps_cap() -> int:
    """The largest ``time.steps`` the scene schema accepts."""
    from ..model.scene import Scene
    steps = Scene.model_fields["time"].annotation.model_fields["steps"]
    return next(m.le for m in steps.metadata if getattr(m, "le", None) is not None)


def steps_key(scene) -> str:
    """The key that sets the time step: ``time.steps``, or a programme's ``programme.steps_per_stop``."""
    return "time.steps" if scene.programme is None else "programme.steps_per_stop"


def _enough_steps(scene, rate: float) -> str:
    """', or time.steps >= N' with k α L_p ≤ 1, when N is within the schema's cap (else nothing).

    k = T/N; a programme's k = d/m of its longest stop, its key ``programme.steps_per_stop``.
    """
    if scene.programme is None:
        needed, cap = int(np.ceil(scene.time.T * rate * (1 - 1e-12))), steps_cap()
    else:
        needed, cap = int(np.ceil(scene.dt * scene.programme.steps_per_stop * rate * (1 - 1e-12))), STEPS_PER_STOP
    return f", or {steps_key(scene)} >= {needed}" if needed <= cap else ""


def diverging(scene, rate: float) -> str | None:
    """The one-line refusal of a uniform explicit run whose update diverges (k α L_p > 2), else None.

    ``wear.allow_unstable`` lets it run (with :func:`explicit_stability`'s warning).  The remedies never ask for
    more than the schema allows: the implicit and trapezoidal integrators always, ``time.steps >= N`` when N fits.
    """
    if scene.wear.integrator != "explicit" or scene.time.adaptive or scene.wear.allow_unstable:
        return None
    r = scene.dt * rate
    if r <= 2:
        return None
    return (f"{steps_key(scene)}: explicit wear with k·α·L = {r:.3g} > 2 diverges (the wear passes the surface); use "
            f"wear.integrator = 'implicit' or 'trapezoidal'{_enough_steps(scene, rate)}, "
            "or wear.allow_unstable = true to run it anyway")


def explicit_stability(scene, rate: float) -> str | None:
    """Warning text when the wear update overshoots at the scene's uniform step, else None.

    For p = L r₊ the explicit update has amplification 1 − k α L (overshoots for k α L > 1, grows
    for > 2: refused unless ``wear.allow_unstable``, :func:`diverging`), the trapezoidal one
    (1 − kαL/2)/(1 + kαL/2) (overshoots for k α L > 2); implicit never.
    ``rate``: the largest α_i L_p,i over the points and time (:func:`stable_step`).
    """
    integrator = scene.wear.integrator
    if integrator == "implicit" or rate == 0:
        return None
    r = scene.dt * rate
    if integrator == "trapezoidal":
        if r <= 2:
            return None
        return (f"{steps_key(scene)}: trapezoidal wear with k·α·L = {r:.3g} > 2 oscillates and can wear past the "
                f"surface; use wear.integrator = 'implicit'{_enough_steps(scene, rate / 2)}")
    if r <= 1:
        return None
    kind = "diverges" if r > 2 else "oscillates"
    return (f"{steps_key(scene)}: explicit wear with k·α·L = {r:.3g} > {1 if r <= 2 else 2} {kind}; "
            f"use wear.integrator = 'implicit' or 'trapezoidal'{_enough_steps(scene, rate)}")
