"""A kinked law's kink as sparse algebra: its forces and tangents without a symbolic assembly.

A kinked law (``law.kinked``: the compaction law, :class:`ngwear.model.materials.Compaction`) is a linear law plus a
term in tr ε alone, ψ = ψ_lin(ε) + β/2 min(tr ε, 0)².  With D the divergence at the quadrature points x_q of the
regions with β > 0, (D u)_q = tr ε(u)(x_q), and c_q = β w_q their weights,

    F(u) = K_lin u + Dᵀ (c ∘ min(D u, 0)),      F'(u) = K_lin + Dᵀ diag(c ∘ [D u ≤ 0]) D,

K_lin the stiffness of the laws' linear parts (``law.linear_part()``).  For P1 elements tr ε is constant on an
element, so one point per element (NGSolve's ``IntegrationRuleSpace`` of order 0) integrates both exactly: the same
numbers as the symbolic forms, a sparse product instead of an assembly (:func:`kinked` says when it applies).
"""
from __future__ import annotations

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from .stiffness import assembled


def kinked(fes: ngs.FESpace, laws: dict) -> bool:
    """Whether the nonlinear laws are all kinked laws on P1 elements (then :class:`Kink` is exact)."""
    nonlinear = [law for law in laws.values() if not law.is_linear]
    return bool(nonlinear) and fes.globalorder == 1 and all(law.kinked for law in nonlinear)


class Kink:
    """D and c of the kinked regions (see the module): the kink's forces, tangents and branches."""

    def __init__(self, fes: ngs.FESpace, laws: dict):
        mesh = fes.mesh
        points = ngs.comp.IntegrationRuleSpace(mesh, order=0)
        rules = points.GetIntegrationRules()
        u, q = fes.TrialFunction(), points.TestFunction()
        beta = {region: law.beta for region, law in laws.items() if law.kinked and law.beta > 0}
        divergence = ngs.BilinearForm(trialspace=fes, testspace=points)
        divergence += ngs.div(u) * q * ngs.dx(definedon=mesh.Materials("|".join(beta)), intrules=rules)
        weights = ngs.BilinearForm(points)
        weights += points.TrialFunction() * q * ngs.dx(intrules=rules)
        moduli = ngs.GridFunction(points)
        moduli.Interpolate(mesh.MaterialCF(beta, default=0.0))                        # β at the points
        B, w = assembled(divergence), assembled(weights).diagonal()
        c = moduli.vec.FV().NumPy() * w
        keep = c > 0
        self.D = sp.csr_matrix(sp.diags(1.0 / w[keep]) @ B[keep])
        self.c = c[keep]

    def compressed(self, u: np.ndarray) -> np.ndarray:
        """[tr ε(u)(x_q) ≤ 0]: the points on the stiff branch."""
        return self.D @ u <= 0

    def forces(self, u: np.ndarray) -> np.ndarray:
        """Dᵀ (c ∘ min(D u, 0)): the kink's part of the internal forces F(u)."""
        return self.D.T @ (self.c * np.minimum(self.D @ u, 0.0))

    def tangent(self, compressed: np.ndarray, points: np.ndarray | None = None) -> sp.csr_matrix:
        """Dᵀ diag(c ∘ compressed) D: the kink's part of F' on the branches ``compressed`` (of ``points``: all)."""
        D, c = (self.D, self.c) if points is None else (self.D[points], self.c[points])
        return sp.csr_matrix(D.T @ sp.diags(c * compressed) @ D)

