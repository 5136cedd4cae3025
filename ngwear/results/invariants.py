"""Invariants of a run, checked at every step as it is recorded and over whole runs (stress matrix, tests).

With z = u_ν − d₀ at the contact points, g the layer, w the wear, p the pressure, λ the reaction:

* ``finite``: no NaN or infinity;
* ``contact``: |min(λ/c, g − z)| / S ≤ solver.tolerance (+ round-off), the complementarity z ≤ g, λ ≥ 0,
  λ (z − g) = 0 in the form Newton's merit measures it (c_i ≥ the solver's scaling 1/(H_ii m_i), S its
  length scale max(‖s_F(t) K⁻¹f‖∞, g), or g on the full-system path); ``gap`` (z − g)₊ / S and
  ``reaction_sign`` (−λ)₊ / (c S) are its two halves;
* ``wear_sign`` (−w)₊ / g and ``wear_monotone`` (w_j − w_{j+1})₊ / g;
* ``pressure_law``: |p − p(z − w)| / max p, beyond the round-off of forming z − w;
* ``archard``: the integrator's nodal update |w_{j+1} − w_j − k (θ_old α_j p_j + θ_new α_{j+1} p_{j+1})| / g;
* ``wear_le_penetration``: (w_j − max_{m≤j} (z_m)₊)₊ / g, where the update is monotone
  (:func:`wear_bounded`).  The exact wear never passes the largest penetration reached so far
  (w' > 0 only while z > w); after lift-off w > z is physical, so the bound is the running maximum.

Each is dimensionless and held when ≤ its allowance (:func:`allowances`): ``TOL`` for what the scheme
makes exact (to round-off), the solver's tolerance for what Newton's convergence test guarantees.
"""
from __future__ import annotations

import math

import numpy as np

from ..model.laws import compliance_from
from ..numerics.wear import INTEGRATORS, largest_slope

#: allowance of the invariants the scheme makes exact (round-off)
TOL = 1e-8
EPS = np.finfo(float).eps
CONTACT = ("contact", "gap", "reaction_sign")


def k_alpha_slope(scene, alpha: float | None = None) -> float:
    """k·α·L_p: L_p the largest slope of p on [0, g], α the largest κ‖v*‖ (``Discretization.largest_alpha``).

    Without ``alpha``, that of the foundation's translation (a scene that was never discretized).
    """
    if alpha is None:
        speeds = [abs(f) for _, f in scene.foundation.speed_table] or [1.0]
        alpha = scene.contact.wear * float(np.linalg.norm(scene.foundation.velocity)) * max(speeds)
    return scene.dt * alpha * largest_slope(scene.contact)


def wear_bounded(scene, alpha: float | None = None) -> bool:
    """Whether the update guarantees w_j ≤ max_{m≤j} (z_m)₊ (≤ g): it is monotone.

    With p(r) ≤ L_p r on [0, g]: explicit w_j ≤ max(w_{j−1}, z_{j−1}) for k α L_p ≤ 1; implicit
    w_j ≤ max(w_{j−1}, z_j) always; trapezoidal w_j ≤ max(a_j, z_j), a_j ≤ max(w_{j−1}, z_{j−1}) for
    k α L_p ≤ 2.  Adaptive steps stay below these limits (:func:`ngwear.numerics.wear.stable_step`).
    """
    if scene.time.adaptive:
        return True
    limit = {"implicit": math.inf, "explicit": 1.0, "trapezoidal": 2.0}[scene.wear.integrator]
    return k_alpha_slope(scene, alpha) <= limit


def allowances(scene) -> dict[str, float]:
    """The largest value of each invariant a valid run can show."""
    exact = ("finite", "wear_sign", "wear_monotone", "pressure_law", "archard", "wear_le_penetration")
    return {**dict.fromkeys(exact, TOL), **dict.fromkeys(CONTACT, scene.solver.tolerance)}


class Checker:
    """The invariants of a run's rows on its discretization: over consecutive rows, vectorised (O(rows · n))."""

    def __init__(self, scene, disc):
        self.scene, self.disc, self.law = scene, disc, compliance_from(scene.contact)
        self.g = scene.contact.gap
        self.theta = INTEGRATORS[scene.wear.integrator]
        self.bounded = wear_bounded(scene, disc.largest_alpha())
        self.allowed = allowances(scene)
        estimate = disc.compliance_estimate * disc.points.weights       # h_i m_i ≤ H_ii m_i: c_i ≥ the solver's
        self.c = np.divide(1.0, estimate, out=np.full_like(estimate, np.inf), where=estimate > 0)
        self.s_load = 0.0 if scene.solver.method == "full" else float(np.abs(disc.s_load).max(initial=0.0))

    def scale(self, times: np.ndarray) -> np.ndarray:
        """S_j, the length scale of Newton's merit at t_j."""
        factors = np.abs([self.disc.load_factor(t) for t in times])
        return np.maximum(factors * self.s_load, self.g)

    def violations(self, times, w, s, p, lam, peak: float | np.ndarray = 0.0) -> dict[str, float]:
        """The invariants over rows (steps × points); ``peak``: max (z)₊ per point before the first row."""
        arrays = (w, s, p, lam)
        if not all(np.isfinite(a).all() for a in arrays):
            return {"finite": math.inf}
        g, d0 = self.g, self.disc.d0[None, :]
        z = s - d0
        scale = self.scale(times)[:, None]
        roundoff = 16 * EPS * (np.abs(s) + np.abs(d0) + g)
        mixed = np.minimum(lam / self.c, g - z)
        out = {
            "finite": 0.0,
            "contact": _excess(np.abs(mixed), roundoff) / scale,
            "gap": _excess(np.maximum(z - g, 0), roundoff) / scale,
            "reaction_sign": _excess(np.maximum(-lam / self.c, 0), roundoff) / scale,
            "wear_sign": np.maximum(-w, 0) / g,
            "pressure_law": self._pressure_law(z, w, p),
        }
        out = {name: float(np.max(v, initial=0.0)) for name, v in out.items()}
        if len(times) > 1:
            out["wear_monotone"] = float(np.maximum(-np.diff(w, axis=0), 0).max(initial=0.0)) / g
            alpha = np.array([self.disc.alpha(t) for t in times])
            rate = alpha * p
            old, new = self.theta
            update = np.diff(times)[:, None] * (old * rate[:-1] + new * rate[1:])
            out["archard"] = float(np.abs(np.diff(w, axis=0) - update).max(initial=0.0)) / g
        if self.bounded:
            reached = np.maximum.accumulate(np.maximum(np.maximum(z, 0), peak), axis=0)
            out["wear_le_penetration"] = float(np.maximum(w - reached, 0).max(initial=0.0)) / g
        return out

    def _pressure_law(self, z, w, p) -> np.ndarray:
        """|p − p(z − w)| beyond the round-off of z − w, which p amplifies by its slope (a stiff law: L = 1e12)."""
        r = z - w
        slack = 8 * EPS * (np.abs(z) + np.abs(self.disc.d0[None, :]) + np.abs(w))
        allowance = slack * self.law.derivative(np.maximum(r, 0) + slack) + 8 * EPS * np.abs(p)
        excess = np.maximum(np.abs(p - self.law(r)) - allowance, 0)
        return excess / max(float(p.max(initial=0.0)), float(self.law(r).max(initial=0.0)), np.finfo(float).tiny)

    def broken(self, violations: dict[str, float]) -> tuple[str, float] | None:
        """The invariant beyond its allowance by the largest factor, or None when all hold."""
        ratios = {name: value / self.allowed[name] for name, value in violations.items() if value > self.allowed[name]}
        if not ratios:
            return None
        name = max(ratios, key=ratios.get)
        return name, violations[name]


def _excess(values: np.ndarray, roundoff: np.ndarray) -> np.ndarray:
    return np.maximum(values - roundoff, 0)


def invariants(result) -> dict[str, float]:
    """The invariants over a run's completed steps (needs its discretization for α, c and S)."""
    if len(result.times) == 0:
        return {"finite": 0.0}
    checker = Checker(result.scene, result.discretization)
    return checker.violations(result.times, result.wear, result.normal_displacement, result.pressure, result.reaction)


def worst(result, violations: dict[str, float]) -> tuple[str, float]:
    """The invariant nearest to (or furthest past) its allowance, and its value."""
    allowed = allowances(result.scene)
    name = max(violations, key=lambda k: violations[k] / allowed[k])
    return name, violations[name]


class StepCheck:
    """The invariants of each step as it is recorded (the time loop): the new row against the last one.

    O(n) per step; the running maximum of (z)₊ is carried (read from the rows kept when a run resumes).
    """

    def __init__(self, result):
        self.checker = Checker(result.scene, result.discretization)
        z = result.normal_displacement - result.discretization.d0[None, :]
        self.peak = np.maximum(z, 0).max(axis=0, initial=0.0)
        self.result = result

    def __call__(self, t: float, w, s, p, lam) -> tuple[str, float] | None:
        """The worst broken invariant of the step ending at t (None: all hold); keeps the running maximum."""
        r = self.result
        if len(r.times):
            rows = (np.array([r.times[-1], t]), *(np.stack([old[-1], new]) for old, new in
                                                   ((r.wear, w), (r.normal_displacement, s), (r.pressure, p),
                                                    (r.reaction, lam))))
            peak = self.peak
        else:
            rows, peak = (np.array([t]), w[None, :], s[None, :], p[None, :], lam[None, :]), 0.0
        broken = self.checker.broken(self.checker.violations(*rows, peak=peak))
        if broken is None:
            self.peak = np.maximum(peak, np.maximum(s - self.checker.disc.d0, 0))
        return broken


def overshoot(result) -> float:
    """max_j,i (w_j − max_{m≤j} (z_m)₊)₊ / g: wear past the largest penetration so far (the exact solution: 0).

    The explicit update overshoots once k α L > 1 (amplification 1 − kαL < 0), the trapezoidal one once
    k α L > 2, the implicit one never.  (w − z)₊ alone is no measure: after lift-off w > z is physical.
    """
    z = np.maximum(result.normal_displacement - result.d0[None, :], 0)
    reached = np.maximum.accumulate(z, axis=0)
    return float(np.maximum(result.wear - reached, 0).max(initial=0.0) / result.scene.contact.gap)
