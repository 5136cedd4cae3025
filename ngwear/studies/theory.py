"""The paper's smallness hypothesis (H_S):  c₀² L_p ‖μ‖_∞ < m_F  (uniqueness, Theorem 1).

c₀ is the trace constant of (9), ‖v‖_{L²(Γ_C)} ≤ c₀ ‖ε(v)‖_{L²(Ω)} on V = {v = 0 on Γ_D}.  On the
scene's mesh, c₀² is the largest eigenvalue of  M_C v = c₀² A_ε v  (M_C the Γ_C mass matrix, A_ε the
form (ε(u), ε(v))), computed on the contact DOFs through the Schur complement S of A_ε: densely, or,
beyond ``condense.DENSE_LIMIT`` contact DOFs, by Lanczos in shift-invert mode on S v = c₀⁻² M_C v
(each step one back-substitution with A_ε's factorisation, which is a second factorisation of the mesh).
For Hooke's law m_F = 2η; L_p is the largest slope of p on [0, g].
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..numerics.discrete import Discretization
from ..numerics.wear import largest_slope


@dataclass(frozen=True)
class SmallnessCheck:
    """Numbers of (H_S) for a scene's mesh."""

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
        verdict = "holds: the solution is unique" if self.holds else "fails: uniqueness is not guaranteed"
        return (f"(H_S) c0² L_p μ = {self.c0:.3g}² · {self.lipschitz:.3g} · {self.friction:.3g} = "
                f"{self.product:.3g} {'<' if self.holds else '>='} m_F = {self.monotonicity:.3g}: {verdict}")


def trace_constant(disc: Discretization) -> float:
    """Discrete c₀ on the discretization's mesh and clamping."""
    strain_only = disc.with_scene(disc.scene.replace(material={"lame_lambda": 0.0, "lame_mu": 0.5}))
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
    """Evaluate (H_S) for the discretization's scene."""
    contact = disc.scene.contact
    _, eta = disc.scene.material.lame
    return SmallnessCheck(trace_constant(disc), largest_slope(contact), contact.friction, 2 * eta)
