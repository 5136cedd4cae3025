"""The full-system reference: the step problem on the free DOFs, linearised by NGSolve at every iteration.

x = the free DOFs (and δ, in the basis u = T x); R = Tᵀ(K u + R_c(u) + (N P)ᵀ(m∘λ) − F) assembled by NGSolve
(``Apply`` / ``AssembleLinearization``) and each Newton step solved as a sparse saddle-point system.
"""
from __future__ import annotations

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..wear import PointLaw
from .newton import balance_along


class FullSystem:
    """The step problem on the free DOFs (and the plate's δ), linearised by NGSolve at every iteration.

    The unknowns x are the coefficients of u = T x in the basis T = [free DOFs | plate modes E];
    ``load`` is Tᵀ f at this step (the plate's rows include its force).  This is the reference path.
    For a body held by the plate alone, ``rigid`` is its translation along ν in these coordinates
    (the plate's translation is x's first entry after the free DOFs):
    when no point has contact stiffness (``law.derivative`` = 0), the step is the rigid motion to the
    force balance along ν, rigidᵀ R = 0 (:func:`balance_along`), as in :class:`CondensedSystem`.
    """

    def __init__(self, contact_form, basis: sp.csr_matrix, load, N, weights, d0, gap, stiffness,
                 law: PointLaw, rigid: np.ndarray | None = None):
        self.cf, self.T, self.load = contact_form, basis.tocsc(), load
        self.N = (N @ self.T).tocsr()                       # normal evaluation at the points
        self.m, self.d0, self.g = weights, d0, gap
        self._gf = ngs.GridFunction(contact_form.form.space)
        self._res = self._gf.vec.CreateVector()
        self.scale = max(np.abs(load).max(initial=0.0), 1e-300)
        diagonal = np.asarray(self.T.multiply(stiffness @ self.T).sum(axis=0)).ravel()
        self.c = np.maximum((self.N.multiply(self.N) @ diagonal) / weights, 1e-300)
        self._gscale = max(gap, 1e-300)
        self.law, self.rigid = law, rigid

    def _set(self, x):
        self._gf.vec.FV().NumPy()[:] = self.T @ x

    def start(self, x, lam):
        """The warm start (x, λ) Newton begins from: itself."""
        return x, lam

    def gap(self, x):
        return self.N @ x - self.d0 - self.g

    def residual(self, x, lam):
        self._set(x)
        self.cf.form.Apply(self._gf.vec, self._res)
        return self.T.T @ self._res.FV().NumPy() - self.load + self.N.T @ (self.m * lam)

    def merit(self, x, lam):
        comp = np.minimum(lam / self.c, -self.gap(x))
        return max(np.abs(self.residual(x, lam)).max(initial=0) / self.scale,
                   np.abs(comp).max(initial=0) / self._gscale)

    def step(self, x, lam, active):
        if self.rigid is not None and not active.any() and not self.law.derivative(self.gap(x) + self.g).any():
            return balance_along(lambda y: self.rigid @ self.residual(y, lam), x, self.rigid), lam
        self._set(x)
        self.cf.form.AssembleLinearization(self._gf.vec)
        vals, cols, ptr = self.cf.form.mat.CSR()
        n_all = len(self._gf.vec)
        J = sp.csr_matrix((np.array(vals), np.array(cols), np.array(ptr)), shape=(n_all, n_all))
        J = (self.T.T @ J @ self.T).tocsr()
        B = self.N[active]
        rhs_u = -self.residual(x, lam) + self.N.T @ (self.m * lam)
        rhs_g = -self.gap(x)[active]
        K = sp.bmat([[J, B.T.multiply(self.m[active][None, :])], [B, None]], format="csc")
        sol = spla.spsolve(K, np.concatenate([rhs_u, rhs_g]))
        nx = self.T.shape[1]
        lam_new = np.zeros(len(lam))
        lam_new[active] = sol[nx:]
        return sol[:nx], lam_new
