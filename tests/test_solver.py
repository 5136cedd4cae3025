"""The semismooth Newton solver on a hand-made complementarity problem: a few contact points, no mesh.

The condensed step problem (:class:`ngwear.numerics.systems.condensed.DenseSystem`) is, for the normal displacements s and
reactions λ at n points with weights m,

    R(s, λ) = s − s_F + A (m ∘ p(s − d₀)) + H (m ∘ λ) = 0,   s − d₀ − g ≤ 0,   λ ≥ 0,   λ · (s − d₀ − g) = 0,

H symmetric positive definite and A = H + μ F (non-symmetric with friction).  The problem is made backwards: a
solution (s*, λ*) is chosen with one point off the foundation, two pressed into the layer and one held at the bound,
and s_F is what makes it one.  For the piecewise-linear law p(r) = L r₊ the iteration ends in finitely many steps
with the exact solution (to round-off, far below the tolerance), however stiff the layer.
"""
import numpy as np
import pytest
import scipy.linalg as sla

from ngwear.numerics.systems.condensed import DenseSystem, Factors
from ngwear.numerics.systems.newton import semismooth_newton
from ngwear.numerics.wear import PointLaw

H = 0.01 * np.array([[2.0, 0.5, 0.2, 0.1], [0.5, 2.0, 0.5, 0.2], [0.2, 0.5, 2.0, 0.5], [0.1, 0.2, 0.5, 2.0]])
F = 0.01 * np.array([[0.3, -0.2, 0.1, 0.0], [0.2, 0.3, -0.2, 0.1], [-0.1, 0.2, 0.3, -0.2], [0.0, -0.1, 0.2, 0.3]])
M = np.array([0.25, 0.5, 0.5, 0.25])                     # the points' weights
D0 = np.array([0.0, 0.0, 0.01, 0.02])                    # initial distances
GAP = 0.2
PENETRATION = np.array([-0.05, 0.1, GAP, 0.15])          # s* − d₀: off, in the layer, at the bound, in the layer
REACTION = np.array([0.0, 0.0, 0.5, 0.0])                # λ*: only where the layer is compressed whole


def linear_law(L: float) -> PointLaw:
    """p(z) = L z₊ and its generalised derivative (L at the kink, as the compliance takes it)."""
    return PointLaw(lambda z: L * np.maximum(z, 0.0), lambda z: np.where(z >= 0, L, 0.0))


def problem(L: float, mu: float) -> tuple[DenseSystem, np.ndarray]:
    """The system whose solution is (s*, λ*), and s*."""
    A = H + mu * F
    s = D0 + PENETRATION
    s_load = s + A @ (M * L * np.maximum(PENETRATION, 0.0)) + H @ (M * REACTION)
    return DenseSystem(H, A, M, s_load, D0, GAP, linear_law(L)), s


@pytest.mark.parametrize("mu", [0.0, 0.8])
@pytest.mark.parametrize("L", [10.0, 1e6])
def test_the_solution_its_complementarity_and_active_set(L, mu):
    system, s_star = problem(L, mu)
    s, lam, record = semismooth_newton(system, np.zeros(4), np.zeros(4), tol=1e-10)
    scale = system.scale                                    # the largest |s_F|: round-off is relative to it
    assert record.converged
    assert np.abs(s - s_star).max() < 1e-14 * scale and np.allclose(lam, REACTION, rtol=1e-9, atol=0)
    assert np.abs(system.residual(s, lam)).max() < 1e-14 * scale
    gap = s - D0 - GAP
    assert gap.max() <= 0 and lam.min() >= 0 and np.abs(lam * gap).max() == 0             # complementarity
    assert record.active == 1 and np.array_equal(lam + system.c * gap > 0, REACTION > 0)   # the active set: point 2


@pytest.mark.parametrize("L", [10.0, 1e3, 1e6, 1e9])
def test_a_piecewise_linear_law_ends_in_finitely_many_steps_however_stiff(L):
    """Full Newton steps; the last one lands on the solution: its merit is round-off, not the tolerance."""
    system, s_star = problem(L, 0.8)
    s, lam, record = semismooth_newton(system, np.zeros(4), np.zeros(4), tol=1e-6)
    assert record.converged and record.damped == 0
    assert record.iterations <= 5                           # a branch or active-set change per step, then exact
    assert record.residuals[-1] < 1e-14                    # the merit is relative to the largest |s_F|
    assert np.abs(s - s_star).max() < 1e-14 * system.scale


def test_a_smooth_law_converges_but_does_not_end():
    """The contrast: p(r) = L r₊² is smooth where it presses, and Newton approaches the solution quadratically."""
    L = 10.0
    law = PointLaw(lambda z: L * np.maximum(z, 0.0) ** 2, lambda z: np.where(z > 0, 2 * L * np.maximum(z, 0.0), 0.0))
    s_star = D0 + PENETRATION
    s_load = s_star + H @ (M * law.pressure(PENETRATION)) + H @ (M * REACTION)
    system = DenseSystem(H, H, M, s_load, D0, GAP, law)
    s, lam, record = semismooth_newton(system, np.zeros(4), np.zeros(4), tol=1e-13)
    merits = np.array(record.residuals)
    assert record.converged and np.abs(s - s_star).max() < 1e-12
    assert merits[1] > 1e-8                                   # one step does not land on it, as it does above ...
    assert merits[2] < 10 * merits[1] ** 2                    # ... it converges quadratically instead


def test_the_factors_of_a_reference_friction_refine_newton_to_the_exact_solution(monkeypatch):
    """μ changed since the Newton matrices were factorised (a μ of the temperature): no new factorisation.

    The LU of M(μ_ref) (:class:`Factors` with the reference's A) preconditions iterative refinement with M(μ), and
    Newton lands on the exact solution of μ; a μ too far off for refinement to contract is solved with its own LU.
    """
    L, solved = 1e3, []
    lu = sla.lu_factor
    monkeypatch.setattr(sla, "lu_factor", lambda *a, **k: solved.append(1) or lu(*a, **k))
    factors = Factors((H + 0.8 * F, None))

    def solve(mu):
        system, s_star = problem(L, mu)
        system.factors, system.reference = factors, factors.reference
        s, lam, record = semismooth_newton(system, np.zeros(4), np.zeros(4), tol=1e-10)
        assert record.converged and np.abs(s - s_star).max() < 1e-12 * system.scale
        assert np.allclose(lam, REACTION, rtol=1e-9, atol=0)
        return record.iterations

    iterations = solve(0.8)                                   # the reference itself
    first = len(solved)
    assert first == len(factors) > 1
    assert solve(0.82) == iterations and len(solved) == first   # refined: the same patterns, no factorisation
    solve(8.0)                                                # refinement does not contract: M's own LU, not kept
    assert len(solved) > first and len(factors) == first
