"""Nonlinear elasticity around few factorisations: F(u) = K u + n(u).

F(u) = Σ_r ∫_r σ_r(ε(u)) : ε(v) dx are the body's internal forces (:meth:`~ngwear.numerics.elastic.Elastic.forces`:
NGSolve's ``Apply``, or for the compaction law sparse algebra, :mod:`~ngwear.numerics.kink`), K a
factorised linear operator (K₀, the laws' tangent at ε = 0, or their tangent K_t at a recent state) and
n(u) = F(u) − K u the remainder.  A step's problem F(u) + Pᵀ f_c(u) = f is today's condensed contact problem
with the load f − n(u): the fixed point u = G(u) of

    G(u) = K⁻¹ (f − n(u) − Pᵀ f_c) + D δ,   (f_c, δ) the contact solution under the load f − n(u),

which :class:`Anderson` mixing accelerates (:func:`fixed_point`, the loop of the step solver and of the displacement's
recovery from contact forces).  Its rate is set by the spread of K⁻¹F'(u):
for the compaction law with K₀ (the compressed tangent) the tangent varies by (2η + d(λ + β))/(2η + dλ), so the
step solver refactorises at the current state when the iteration is slow (:mod:`ngwear.runs.step`).
"""
from __future__ import annotations

from collections import deque
from collections.abc import Callable

import numpy as np


class Remainder:
    """n(u) = F(u) − K u as a DOF vector: the internal forces (:meth:`Elastic.forces`) less the operator K."""

    def __init__(self, elastic):
        self.elastic, self.stiffness = elastic, elastic.stiffness

    def __call__(self, u: np.ndarray) -> np.ndarray:
        return self.elastic.forces(u) - self.stiffness @ u


class Anderson:
    """Anderson mixing (type II) of the last ``memory`` iterates for a fixed point u = G(u).

    With f_k = G(u_k) − u_k: u_{k+1} = G(u_k) − ΔG γ,  γ = argmin ‖f_k − ΔF γ‖₂, the columns of ΔF, ΔG the
    differences of consecutive f and G(u).  With no history it is the plain step u_{k+1} = G(u_k).
    """

    def __init__(self, memory: int = 6):
        self.memory = memory
        self.differences: deque = deque(maxlen=memory)
        self.last = None

    def __call__(self, u: np.ndarray, image: np.ndarray) -> np.ndarray:
        residual = image - u
        if self.last is not None:
            self.differences.append((residual - self.last[0], image - self.last[1]))
        self.last = residual, image
        if not self.differences:
            return image
        dF = np.column_stack([d[0] for d in self.differences])
        dG = np.column_stack([d[1] for d in self.differences])
        gamma = np.linalg.lstsq(dF, residual, rcond=1e-12)[0]
        return image - dG @ gamma


def change(u: np.ndarray, image: np.ndarray) -> float:
    """max|G(u) − u| / max|G(u)|: how far u is from the fixed point, relative to its size."""
    return float(np.abs(image - u).max(initial=0.0) / max(np.abs(image).max(initial=0.0), np.finfo(float).tiny))


RUNAWAY = 10.0
"""Iterates whose step |G(u) − u| exceeds the best one's this many times: the mixing restarts from the best."""


def fixed_point(image: Callable[[np.ndarray], np.ndarray | None], u: np.ndarray, tolerance: float,
                most: int) -> tuple[np.ndarray, float]:
    """(The best image, its :func:`change`) of at most ``most`` Anderson-mixed images u ← G(u) from u.

    ``image(u)`` is G(u), or None where it cannot be evaluated (counted as an infinite step).  The iteration stops
    when the best image's change meets ``tolerance`` or ``most`` images are spent; when the step |G(u) − u| grows to
    :data:`RUNAWAY` times the best, or the best has not halved in as many images as the mixing remembers (a stalled
    history), the mixing starts afresh from the best image.
    """
    mixing, best, since = Anderson(), (np.inf, np.inf, u), 0     # best: (|G(u) − u|, its change, G(u))
    for _ in range(most):
        g = image(u)
        step = np.inf if g is None else float(np.abs(g - u).max(initial=0.0))
        since = 0 if step < 0.5 * best[0] else since + 1
        if step < best[0]:
            best = step, change(u, g), g
        if best[1] <= tolerance or best[0] == np.inf:
            break
        if step > RUNAWAY * best[0] or since > mixing.memory:
            mixing, u, since = Anderson(), best[2], 0
        else:
            u = mixing(u, g)
    return best[2], best[1]
