"""The uniqueness hypothesis (H_S) of the paper (Theorem 1), in its own form and in the run's energy norm.

**The paper's form**  c₀² L_p ‖μ‖_∞ < m_F: c₀ is the trace constant of (9), ‖v‖_{L²(Γ_C)} ≤ c₀ ‖ε(v)‖_{L²(Ω)}
on V = {v = 0 on Γ_D}, m_F the strong monotonicity of F (2η for Hooke's law), L_p the largest slope of p on
[0, g].  On the scene's mesh c₀² is the largest eigenvalue of M_C v = c₀² A_ε v (M_C the Γ_C mass matrix, A_ε
the form (ε(u), ε(v))), on the contact DOFs through the Schur complement S of A_ε: densely, or, beyond
``operators.DENSE_LIMIT`` contact DOFs, by Lanczos in shift-invert mode on S v = c₀⁻² M_C v (each step one
back-substitution with A_ε's factorisation, a second factorisation of the mesh): :func:`smallness`.

**The energy form** (what ``ngwear run`` reports): with ‖v‖_K² = vᵀKv, K the run's own stiffness, the elastic
operator is strongly monotone with m = 1 and the trace inequality of the discrete problem,
Σ_i m_i |v(x_i)|² ≤ c_K² ‖v‖_K² (the nodal rule the contact terms use), holds with

    c_K² = λ_max(W^½ P K⁻¹ Pᵀ W^½),   W = diag(m_i) per component,  P the point evaluation,

the largest eigenvalue of the weighted point compliance.  The uniqueness argument of Theorem 1 then needs
c_K² L_p ‖μ‖_∞ < 1.  Since ‖v‖_K² ≥ m_F ‖ε(v)‖², c_K² ≤ c₀²/m_F (with c₀ for the nodal trace): the paper's
condition implies this one, which is sharper, needs no second factorisation (Lanczos on the compliance, each
product one back-substitution with the run's factorisation, or two triangular solves with the Cholesky factor
of its Schur complement), and stays meaningful for any symmetric positive definite K (several materials,
anisotropy; the tangent of a nonlinear law).  Both use the clamping of the run's factorisation (a plate's
boundary held).
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..numerics.discrete import Discretization


@dataclass(frozen=True)
class SmallnessCheck:
    """Numbers of the paper's (H_S) for a scene's mesh."""

    c0: float
    lipschitz: float
    friction: float
    monotonicity: float

    @property
    def product(self) -> float:
        return self.c0**2 * self.lipschitz * self.friction

    @property
    def holds(self) -> bool:
        return self.product < self.monotonicity

    def message(self) -> str:
        return (f"(H_S) c0² L_p μ = {self.c0:.3g}² · {self.lipschitz:.3g} · {self.friction:.3g} = "
                f"{self.product:.3g} {'<' if self.holds else '≥'} m_F = {self.monotonicity:.3g}: {verdict(self.holds)}")


@dataclass(frozen=True)
class EnergyCheck:
    """(H_S) in the run's energy norm: c_K² L_p μ < 1 (see the module docstring)."""

    trace: float
    lipschitz: float
    friction: float

    @property
    def product(self) -> float:
        return self.trace * self.lipschitz * self.friction

    @property
    def holds(self) -> bool:
        return self.product < 1.0

    def message(self) -> str:
        return (f"(H_S) c_K² L_p μ = {self.trace:.3g} · {self.lipschitz:.3g} · {self.friction:.3g} = "
                f"{self.product:.3g} {'<' if self.holds else '≥'} 1 (energy norm of K): {verdict(self.holds)}")


def verdict(holds: bool) -> str:
    """What (H_S) says about the scene: information, not a warning (it is sufficient for uniqueness, not necessary)."""
    if holds:
        return "the paper's uniqueness theorem covers this scene: its solution is unique"
    return "the paper's uniqueness theorem does not cover this scene (a sufficient condition, not a necessary one)"


def energy_trace(disc: Discretization, interrupted=None) -> float:
    """c_K², the largest eigenvalue of W^½ P K⁻¹ Pᵀ W^½ with the run's factorisation of K (Lanczos).

    ``interrupted``: called before each product; a true value aborts with KeyboardInterrupt.
    Raises scipy's ``ArpackNoConvergence`` when Lanczos does not converge.
    """
    op, P = disc.elastic.operator, disc.points.P
    root = np.sqrt(np.repeat(disc.points.weights, disc.scene.dim))
    c = op.contact_dofs
    local = P[:, c].tocsr()

    def compliance(x):
        if interrupted is not None and interrupted():
            raise KeyboardInterrupt
        f = root * np.ravel(x)
        if op.condensed:
            return root * (local @ op.contact_solve(local.T @ f))
        return root * (P @ op.solve(P.T @ f))

    n = P.shape[0]          # from the uniform load W^½ 1 (deterministic; about 20 products on the brake pad)
    top = spla.eigsh(spla.LinearOperator((n, n), matvec=compliance, dtype=float), k=1, which="LA", tol=1e-4,
                     v0=root, return_eigenvectors=False)
    return float(top[0])


def uniqueness(disc: Discretization, interrupted=None) -> EnergyCheck:
    """(H_S) in the energy norm of the run's K, from its factorisation (see :func:`energy_trace`)."""
    return EnergyCheck(energy_trace(disc, interrupted), *_largest_slope_and_friction(disc))


ELASTIC_ONLY = {"heat.model": "none", "contact.friction": 0.0, "contact.wear": 0.0}
"""What the strain-only scene of :func:`trace_constant` drops: its material has no thermal keys, so no heat and no
coefficient of the temperature (neither enters c₀)."""


def trace_constant(disc: Discretization) -> float:
    """Discrete c₀ on the discretization's mesh and clamping (the paper's, with A_ε's own factorisation)."""
    strain_only = disc.with_scene(disc.scene.replace(material={"lame_lambda": 0.0, "lame_mu": 0.5}, **ELASTIC_ONLY))
    op = strain_only.elastic.operator
    u, v = disc.fes.TnT()
    mass = ngs.BilinearForm(disc.fes)
    mass += ngs.InnerProduct(u, v) * ngs.ds("contact")
    mass.Assemble()
    vals, cols, ptr = mass.mat.CSR()
    M = sp.csr_matrix((np.array(vals), np.array(cols), np.array(ptr)), shape=(disc.fes.ndof,) * 2)
    c = op.contact_dofs
    Mcc = M[c][:, c]
    schur = op.schur_complement
    if schur is not None:
        top = sla.eigh(Mcc.toarray(), 0.5 * (schur + schur.T), eigvals_only=True,
                       subset_by_index=[len(c) - 1, len(c) - 1])
        return float(np.sqrt(top[0]))

    def contact_inverse(r):                                     # S⁻¹ r = (A_ε⁻¹)_cc r
        full = np.zeros(disc.fes.ndof)
        full[c] = r
        return op.solve(full)[c]

    n = len(c)
    inverse = spla.LinearOperator((n, n), matvec=contact_inverse, dtype=float)
    unused = spla.LinearOperator((n, n), matvec=lambda r: np.full(n, np.nan), dtype=float)   # mode 3 needs OPinv only
    smallest = spla.eigsh(unused, k=1, M=Mcc.tocsc(), sigma=0.0, OPinv=inverse, which="LM", tol=1e-8,
                          return_eigenvectors=False)
    return float(1.0 / np.sqrt(smallest[0]))


def smallness(disc: Discretization) -> SmallnessCheck:
    """Evaluate the paper's (H_S) for the discretization's scene (a second factorisation: the strain form's)."""
    return SmallnessCheck(trace_constant(disc), *_largest_slope_and_friction(disc), monotonicity(disc))


def monotonicity(disc: Discretization) -> float:
    """m_F of the body: Σ_r ∫_r F_r(ε) : ε ≥ min_r m_F,r ‖ε‖², the smallest over its regions' laws.

    A law without a closed form (a Python ψ) counts with its tangent at ε = 0.
    """
    return min(law.tangent_at_zero().monotonicity if law.estimated else law.monotonicity
               for law in disc.elastic.laws.values())


def _largest_slope_and_friction(disc: Discretization) -> tuple[float, float]:
    """max_i L_p,i and max_i μ_i over the contact points (their product bounds max_i μ_i L_p,i of a field)."""
    slopes = np.broadcast_to(disc.contact.law.slope(disc.scene.contact.gap), (disc.points.n,))
    return float(slopes.max(initial=0.0)), float(disc.contact.coefficients.friction.max(initial=0.0))
