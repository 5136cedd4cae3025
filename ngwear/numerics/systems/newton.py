"""Semismooth Newton with a projection (primal–dual active set) for one time step, on any of the step's systems.

Each step solves, for the normal displacements s_i = ν·u(x_i) at the contact points and the
reactions λ_i of the rigid foundation,

    R(x, λ) = 0,   s − d₀ − g ≤ 0,   λ ≥ 0,   λ·(s − d₀ − g) = 0,

with the complementarity written as C(x, λ) = λ − max(0, λ + c (s − d₀ − g)) = 0.  The active set
A = {i : λ_i + c_i (s_i − d₀,i − g) > 0} is fixed at s_i = d₀,i + g and λ_i = 0 off A; the Newton
matrix K + R'(u) is non-symmetric when μ > 0.  Steps are damped by backtracking on the merit
max(|R|, |min(λ/c, g + d₀ − s)|), whose overshoot of the layer (s − d₀ − g)₊ is measured against g itself
(the constraint holds to g·tolerance however soft the body). A system implements the
protocol ``start``, ``gap``, ``residual``, ``merit``, ``step`` and the multiplier scaling ``c``: the condensed ones
(:mod:`.condensed`, :mod:`.krylov`, :mod:`.patch`) and the full-system reference (:mod:`.full`).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

log = logging.getLogger(__name__)


class ConvergenceError(RuntimeError):
    """Newton did not converge; ``record`` holds its history."""

    def __init__(self, message: str, record: NewtonRecord):
        super().__init__(message)
        self.record = record


@dataclass
class NewtonRecord:
    """History of one step's Newton solve.

    ``cutbacks``: the load continuations tried before the step converged (or before it was given up),
    each cutting the step's load change into m = 2, 4, 8 parts (:mod:`ngwear.runs.step`); the
    other fields are those of the last solve.
    A nonlinear material's step: ``bulk`` iterations of its fixed point, ``tangents`` factorised in the run so far.
    """

    converged: bool = False
    iterations: int = 0
    residuals: list[float] = field(default_factory=list)
    active: int = 0
    damped: int = 0
    bulk: int = 0
    tangents: int = 0
    cutbacks: int = 0


MEMORY = 5
UNDAMPED = 20


def semismooth_newton(system, x, lam, tol: float = 1e-10, max_iterations: int = 50):
    """Solve ``system`` from the warm start (x, λ); returns (x, λ, NewtonRecord).

    First the pure semismooth Newton iteration (full steps: for a piecewise-linear law it ends in
    finitely many steps, however stiff), for at most ``UNDAMPED`` iterations; if that does not
    converge, a damped restart from the warm start with a non-monotone line search
    (Grippo–Lampariello–Lucidi): a step is accepted when the merit drops below the largest of the
    last ``MEMORY`` merits; halving stops at θ = 1/1024.  Iterations of both phases count.
    """
    rec = NewtonRecord()
    start = system.start(x, lam)
    for damped in (False, True):
        x, lam = start
        merit = system.merit(x, lam)
        history = [merit]
        active_old = None
        budget = min(UNDAMPED, max_iterations) if not damped else max_iterations - rec.iterations
        for _ in range(budget):
            active = lam + system.c * system.gap(x) > 0
            dx, lam_new = system.step(x, lam, active)
            reference = max(history[-MEMORY:])
            theta = 1.0
            while True:
                x_try, lam_try = x + theta * dx, lam + theta * (lam_new - lam)
                with np.errstate(over="ignore", invalid="ignore"):  # a wild trial step is detected below
                    merit_try = system.merit(x_try, lam_try)
                if not np.isfinite(merit_try) and not damped:
                    break
                if not damped or merit_try <= (1 - 1e-4 * theta) * reference or theta < 1e-3:
                    break
                theta *= 0.5
            if not np.isfinite(merit_try):
                if damped:
                    merit = merit_try
                break
            rec.damped += theta < 1
            x, lam, merit = x_try, lam_try, merit_try
            rec.iterations, rec.active = rec.iterations + 1, int(active.sum())
            history.append(merit)
            rec.residuals.append(merit)
            if merit <= tol and (active_old is None or np.array_equal(active, active_old) or merit == 0):
                rec.converged = True
                return x, lam, rec
            active_old = active
        if rec.iterations >= max_iterations:
            break
    raise ConvergenceError(
        f"Newton did not converge in {rec.iterations} iterations (merit {merit:.2e} > {tol:.0e})", rec)


def balance_along(balance, x: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """The step Δ·direction that zeroes ``balance(x + Δ direction)``, a function increasing in Δ.

    The body's force balance along ν while it moves rigidly: the Newton step for a body held by a
    plate alone when no contact point has stiffness (lost contact, or the power law's zero slope at
    first touch), where the Newton matrix is singular.  Bracketing by doubling, then bisection.
    """
    value = lambda delta: balance(x + delta * direction)  # noqa: E731
    lo, hi = 0.0, 1e-6 * max(np.abs(x).max(initial=0.0), 1e-6)
    while value(hi) < 0 and hi < 1e30:
        lo, hi = hi, 2 * hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (mid, hi) if value(mid) < 0 else (lo, mid)
    return hi * direction


@dataclass(frozen=True)
class PlateRows:
    """The plate's unknowns δ bordering the condensed system: Ψ, Φ_b = b_i·Φ_i, S and the step's load."""

    normal: np.ndarray
    directed: np.ndarray
    stiffness: np.ndarray
    load: np.ndarray
