"""The checks of a run: the scheme's invariants at every step as it is recorded and over whole runs, and ``wear.limit``.

With z = u_ν − d₀ at the contact points, g the layer, w the wear, p the pressure, λ the reaction:

* ``finite``: no NaN or infinity;
* ``contact``: |min(λ/c, g − z)| / S ≤ solver.tolerance (+ round-off), the complementarity z ≤ g, λ ≥ 0,
  λ (z − g) = 0 in the form Newton's merit measures it (c_i ≥ the solver's scaling 1/(H_ii m_i), S its
  length scale max(‖s_F(t) K⁻¹f‖∞, g), or g on the full-system path); ``reaction_sign`` (−λ)₊ / (c S) is
  its half for λ;
* ``gap``: (z − g)₊ / g, the unilateral constraint in absolute terms, beyond the round-off of forming z − g:
  S dwarfs g on a very soft body, so the complementarity's bound on it would let the layer be passed; the
  solver drives it to g·tolerance (an active point sits at z = g exactly);
* ``wear_sign`` (−w)₊ / g and ``wear_monotone`` (w_j − w_{j+1})₊ / g;
* ``pressure_law``: |p − p(z − w)| / max p, beyond the round-off of forming z − w;
* ``archard``: the integrator's nodal update |w_{j+1} − w_j − k (θ_old α_j g(p_j) + θ_new α_{j+1} g(p_{j+1}))| / g
  of the wear law w' = α g(p) (:mod:`ngwear.model.wear_laws`; α of the coefficients of step j + 1 at the speeds of
  steps j and j + 1: a coefficient of state is read at step j's state);
* ``wear_le_penetration``: (w_j − max_{m≤j} (z_m)₊)₊ / g, where the update is monotone
  (:func:`wear_bounded`).  The exact wear never passes the largest penetration reached so far
  (w' > 0 only while z > w); after lift-off w > z is physical, so the bound is the running maximum.

Each is dimensionless and held when ≤ its allowance (:func:`allowances`): ``TOL`` for what the scheme
makes exact (to round-off), the solver's tolerance for what Newton's convergence test guarantees.

:class:`StepCheck` holds them at each new row after the last one, O(n): the first step that breaks one stops the run
(status naming the step, the invariant and by how much), keeping the steps before it.  :func:`worn_out` ends a run
whose remaining thickness reached ``wear.limit`` (status ``worn_out``, a warning line saying when, where and in which
stop).  Whether a step stays where the model is valid is :mod:`ngwear.runs.validity`'s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.coefficients import bound
from ..model.compliance import largest_slope
from ..model.programme import Schedule
from ..numerics.wear import INTEGRATORS

#: allowance of the invariants the scheme makes exact (round-off)
TOL = 1e-8
EPS = np.finfo(float).eps
CONTACT = ("contact", "gap", "reaction_sign")


def k_alpha_slope(scene, rate: float | None = None) -> float:
    """k·α·L_p: ``rate`` the largest α_i L_p,i (:meth:`Discretization.largest_rate`).

    L_p,i is the largest slope of p_i on [0, g], α_i = κ_i‖v*_i‖.  Without ``rate``, that of the foundation's
    translation (a scene that was never discretized; NaN for a coefficient field, known only at the points).
    """
    if rate is None:
        speeds = [abs(f) for _, f in scene.foundation.speed_table] or [1.0]
        wear, slope = bound(scene.contact.wear), largest_slope(scene.contact)
        if wear is None or slope is None:
            return math.nan
        rate = wear * float(np.linalg.norm(scene.foundation.velocity)) * max(speeds) * slope
    return scene.dt * rate


def wear_bounded(scene, rate: float | None = None) -> bool:
    """Whether the update guarantees w_j ≤ max_{m≤j} (z_m)₊ (≤ g): it is monotone.

    With p(r) ≤ L_p r on [0, g]: explicit w_j ≤ max(w_{j−1}, z_{j−1}) for k α L_p ≤ 1; implicit
    w_j ≤ max(w_{j−1}, z_j) always; trapezoidal w_j ≤ max(a_j, z_j), a_j ≤ max(w_{j−1}, z_{j−1}) for
    k α L_p ≤ 2.  Adaptive steps stay below these limits (:func:`ngwear.numerics.wear.stable_step`).
    """
    if scene.time.adaptive:
        return True
    limit = {"implicit": math.inf, "explicit": 1.0, "trapezoidal": 2.0}[scene.wear.integrator]
    return k_alpha_slope(scene, rate) <= limit


def allowances(scene) -> dict[str, float]:
    """The largest value of each invariant a valid run can show."""
    exact = ("finite", "wear_sign", "wear_monotone", "pressure_law", "archard", "wear_le_penetration")
    return {**dict.fromkeys(exact, TOL), **dict.fromkeys(CONTACT, scene.solver.tolerance)}


@dataclass(frozen=True)
class Row:
    """The last checked step: its time, wear, pressure, slip speeds ‖v*‖ and the running maximum of (z)₊ up to it."""

    t: float
    w: np.ndarray
    p: np.ndarray
    v: np.ndarray
    peak: np.ndarray | float


class Checker:
    """The invariants of a run's rows on its discretization, vectorised: O(rows · n)."""

    def __init__(self, scene, disc):
        self.disc, self.law, self.g = disc, disc.contact.law, scene.contact.gap
        self.theta = INTEGRATORS[scene.wear.integrator]
        self.bounded = wear_bounded(scene, disc.contact.largest_rate())
        self.allowed = allowances(scene)
        self.inverse_c = disc.condensation.compliance_estimate * disc.points.weights   # 1/c_i = h_i m_i ≤ H_ii m_i
        self.s_load = 0.0 if scene.solver.method == "full" else float(np.abs(disc.loads.s_load).max(initial=0.0))
        self.d0 = disc.condensation.d0[None, :]
        self.height = float(np.abs(disc.condensation.d0).max(initial=0.0)) + self.g

    def scale(self, loads: np.ndarray) -> np.ndarray:
        """S_j, the length scale of Newton's merit at the loads' factors s_F of the rows."""
        return np.maximum(np.abs(loads) * self.s_load, self.g)

    def speeds(self, factors) -> np.ndarray:
        """‖v*(x_i)‖ at the rows' speed factors s_v (rows × points)."""
        return self.disc.contact.motion.speeds(np.asarray(factors, dtype=float))

    def violations(self, times, w, s, p, lam, speed, load, before: Row | None = None, halves: bool = True,
                   kappa: np.ndarray | None = None, friction: np.ndarray | None = None) -> dict[str, float]:
        """The invariants over rows (steps × points); ``before``: the step before the first row (None: none).

        ``speed``, ``load``: the rows' factors s_v, s_F.  ``halves``: also ``reaction_sign``, which ``contact``
        bounds (|min(a, b)| ≥ a₋).  ``kappa``, ``friction``: the κ_i, μ_i each row's step was solved with
        (coefficients of state, rows × points); None: the contact's fixed coefficients.  The update from t_j to t_{j+1}
        is k (θ_old α(κ_{j+1}, μ_{j+1}, ‖v*_j‖) g(p_j) + θ_new α(κ_{j+1}, μ_{j+1}, ‖v*_{j+1}‖) g(p_{j+1})).
        """
        if not all(np.isfinite(a).all() for a in (w, s, p, lam)):
            return {"finite": math.inf}
        g, z = self.g, s - self.d0
        scale = self.scale(load)[:, None]
        roundoff = 16 * EPS * (float(np.abs(s).max(initial=0.0)) + self.height) / scale   # of z, g − z and λ/c
        out = {"finite": 0.0,
               "contact": _excess(np.abs(np.minimum(lam * self.inverse_c, g - z)) / scale, roundoff),
               "wear_sign": max(-float(w.min(initial=0.0)), 0.0) / g,
               "pressure_law": self._pressure_law(z, w, p)}
        out["gap"] = _excess((z - g) / g, 16 * EPS * (np.abs(s) + self.height) / g)
        if halves:
            out["reaction_sign"] = _excess(-lam * self.inverse_c / scale, roundoff)
        v = self.speeds(speed)
        if before is not None:
            times, w, p, v = np.r_[before.t, times], np.vstack([before.w, w]), np.vstack([before.p, p]), \
                np.vstack([before.v, v])
        if len(times) > 1:
            dw = np.diff(w, axis=0)
            out["wear_monotone"] = max(-float(dw.min(initial=0.0)), 0.0) / g
            out["archard"] = float(np.abs(dw - self._update(times, p, v, kappa, friction)).max(initial=0.0)) / g
        if self.bounded:
            peak = 0.0 if before is None else before.peak
            reached = np.maximum.accumulate(np.maximum(np.maximum(z, 0), peak), axis=0)
            out["wear_le_penetration"] = max(float((w[len(w) - len(z):] - reached).max(initial=0.0)), 0.0) / g
        return out

    def _update(self, times, p, v, kappa, friction) -> np.ndarray:
        """K (θ_old α_old g(p_j) + θ_new α_new g(p_{j+1})) of each step (rows − 1 × points)."""
        contact, (old, new) = self.disc.contact, self.theta
        law, rows = contact.wear_law, len(times) - 1
        fixed = contact.coefficients
        k = kappa[len(kappa) - rows:] if kappa is not None else fixed.wear
        mu = friction[len(friction) - rows:] if friction is not None else fixed.friction
        gp = law.g(p)
        return np.diff(times)[:, None] * (old * law.alpha(k, mu, v[:-1]) * gp[:-1] + new * law.alpha(k, mu, v[1:]) * gp[1:])

    def _pressure_law(self, z, w, p) -> float:
        """The largest |p − p(z − w)| / max p beyond the round-off of z − w, which p amplifies by its slope (L = 1e12)."""
        r = z - w
        expected = self.law(r)
        slack = 8 * EPS * (float(np.abs(z).max(initial=0.0) + np.abs(w).max(initial=0.0)) + self.height)
        size = max(float(p.max(initial=0.0)), float(expected.max(initial=0.0)), np.finfo(float).tiny)
        slope = float(np.max(self.law.derivative(np.array(max(float(r.max(initial=0.0)), 0.0) + slack))))
        return _excess(np.abs(p - expected) / size, (slack * slope + 8 * EPS * size) / size)

    def broken(self, violations: dict[str, float]) -> tuple[str, float] | None:
        """The invariant beyond its allowance by the largest factor, or None when all hold."""
        ratios = {name: value / self.allowed[name] for name, value in violations.items() if value > self.allowed[name]}
        if not ratios:
            return None
        name = max(ratios, key=ratios.get)
        return name, violations[name]


def _excess(values: np.ndarray, roundoff) -> float:
    """The largest value beyond its round-off (0 if none)."""
    return max(float((values - roundoff).max(initial=0.0)), 0.0)


def invariants(result) -> dict[str, float]:
    """The invariants over a run's completed steps (needs its discretization for α, c and S)."""
    if len(result.times) == 0:
        return {"finite": 0.0}
    checker = Checker(result.scene, result.discretization)
    return checker.violations(result.times, result.wear, result.normal_displacement, result.pressure, result.reaction,
                              result.speed_factor, result.load_factor, kappa=result.rows.get("step_wear_coefficient"),
                              friction=result.rows.get("step_friction"))


def worst(result, violations: dict[str, float]) -> tuple[str, float]:
    """The invariant nearest to (or furthest past) its allowance, and its value."""
    allowed = allowances(result.scene)
    name = max(violations, key=lambda k: violations[k] / allowed[k])
    return name, violations[name]


def overshoot(result) -> float:
    """max_j,i (w_j − max_{m≤j} (z_m)₊)₊ / g: wear past the largest penetration so far (the exact solution: 0).

    The explicit update overshoots once k α L > 1 (amplification 1 − kαL < 0), the trapezoidal one once
    k α L > 2, the implicit one never.  (w − z)₊ alone is no measure: after lift-off w > z is physical.
    """
    z = np.maximum(result.normal_displacement - result.d0[None, :], 0)
    reached = np.maximum.accumulate(z, axis=0)
    return float(np.maximum(result.wear - reached, 0).max(initial=0.0) / result.scene.contact.gap)


WORN_OUT = "worn_out"
"""The status of a run ended by ``wear.limit``."""


class StepCheck:
    """The invariants of each step as it is recorded (the time loop): the new row after the last one, O(n).

    It carries the last row and the running maximum of (z)₊ (read from the rows kept when a run resumes, or when a
    geometry update replaces the discretization).
    """

    def __init__(self, result, disc):
        self.checker = checker = Checker(result.scene, disc)
        self.last = None
        if len(result.times):
            peak = np.maximum(result.normal_displacement - checker.d0, 0).max(axis=0)
            self.last = Row(result.times[-1], result.wear[-1], result.pressure[-1],
                            checker.speeds(result.speed_factor[-1]), peak)

    def __call__(self, state) -> tuple[str, float] | None:
        """The worst broken invariant of the state's step (None: all hold, and the step becomes the last)."""
        checker, instant, c = self.checker, state.instant, state.coefficients
        w, s, p = state.wear, state.normal, state.pressure
        broken = checker.broken(checker.violations(np.array([instant.t]), w[None, :], s[None, :], p[None, :],
                                                   state.lam[None, :], [instant.speed], [instant.load], self.last,
                                                   halves=False, kappa=c.wear[None, :], friction=c.friction[None, :]))
        if broken is None:
            peak = np.maximum(s - checker.disc.condensation.d0, 0)
            self.last = Row(instant.t, w, p, checker.speeds(instant.speed),
                            peak if self.last is None else np.maximum(self.last.peak, peak))
        return broken

    def cross(self, t: float, w: np.ndarray) -> None:
        """The next step crosses a programme's dwell to t: from the wear ``w`` (a jump's added), no wear across it."""
        self.last = Row(t, w, np.zeros_like(w), np.zeros_like(w), self.last.peak)

    def allowed(self, name: str) -> float:
        """The allowance of the invariant ``name``."""
        return self.checker.allowed[name]


def worn_out(result) -> bool:
    """End the run (status ``worn_out``, a warning line) if its last row's remaining thickness reached ``wear.limit``."""
    limit = result.scene.wear.limit
    if limit is None or not len(result.times):
        return False
    remaining = result.remaining_thickness_of(result.total_wear_at(-1))
    if remaining.min() > limit:
        return False
    i = int(np.argmin(remaining))
    place = ", ".join(f"{x:.4g}" for x in result.contact_points[i])
    where = ""
    if result.scene.programme is not None:
        stop = int(Schedule.of(result.scene.programme).rows(result.jumped)[0][result.steps])
        where = f" in stop {stop}"
    result.status = WORN_OUT
    result.warnings.append(f"wear.limit: the remaining thickness reached {limit:g} (min {remaining[i]:.4g}) at "
                           f"t = {result.times[-1]:.6g}{where}, at ({place})")
    return True
