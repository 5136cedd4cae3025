"""The elastic operator, factorised once, and its condensation onto the contact DOFs.

K is symmetric positive definite on the free DOFs.  MKL PARDISO (:mod:`ngwear.numerics.pardiso`)
factorises it with the contact DOFs c ordered last and stops there: the dense Schur complement
S = K_cc − K_ci K_ii⁻¹ K_ic comes out of the one factorisation, and (K⁻¹)_cc = S⁻¹ is applied
through the Cholesky factor of S, never formed.  Beyond ``DENSE_LIMIT`` contact DOFs S does not
pay (its n_c² memory and n_c³ factorisation outgrow the per-step work it saves) and the operator
keeps the plain factorisation: the contact problem is then solved matrix-free
(:class:`~ngwear.numerics.systems.patch.PatchSystem` or :class:`~ngwear.numerics.systems.krylov.KrylovSystem`).  So
it is from ``SOFT_LIMIT`` contact DOFs when the layer is soft against the body (:attr:`Discretization.layer_ratio` < 1): its
Newton systems are then well conditioned, and with the products remembered (:mod:`~ngwear.numerics.recycle`) a
run needs about one back-substitution per step.  :class:`UpdatedOperator` solves with K changed on a few rows of a low
rank (a kinked law's tangent, :mod:`~ngwear.numerics.kink`) from K's factorisation.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .pardiso import Pardiso

DENSE_LIMIT = 12_000
"""Largest number of contact DOFs condensed densely by default (measured crossover: benchmarks/scale3d.py)."""
SOFT_LIMIT = 1_000
"""Largest number of contact DOFs condensed densely when the layer is soft (same benchmark)."""


class ElasticOperator:
    """K⁻¹ on the free DOFs (full numbering); with ``schur``, also S⁻¹ on the free contact DOFs.

    ``contact_dofs`` are the free DOFs among the given ones, sorted; S is kept as its Cholesky factor.  Without
    ``schur``, ``ordering`` is an earlier factorisation's :attr:`ordering` of a K on the same elements (METIS skipped).
    """

    def __init__(self, K: sp.csr_matrix, free: np.ndarray, contact_dofs: np.ndarray, schur: bool = True,
                 ordering: np.ndarray | None = None):
        self.ndof = K.shape[0]
        self.free = np.flatnonzero(free)
        local = np.full(self.ndof, -1)
        local[self.free] = np.arange(len(self.free))
        self.contact_dofs = np.unique([d for d in contact_dofs if free[d]]).astype(int)
        c = local[self.contact_dofs]
        self._factor = Pardiso(K[self.free][:, self.free], c if schur and len(c) else None, ordering)
        self._cholesky = None
        if self._factor.schur_upper is not None:   # S's upper triangle, row-major: the lower one of its transpose
            self._cholesky = sla.cho_factor(self._factor.schur_upper.T, lower=True, overwrite_a=True,
                                            check_finite=False)
            self._factor.schur_upper = None

    @property
    def condensed(self) -> bool:
        """Whether S is kept (as its Cholesky factor): :meth:`contact_solve` works."""
        return self._cholesky is not None

    @property
    def schur_complement(self) -> np.ndarray | None:
        """S = L Lᵀ from its Cholesky factor (None without ``schur``)."""
        if self._cholesky is None:
            return None
        L = np.tril(self._cholesky[0])
        return L @ L.T

    @property
    def factor_nonzeros(self) -> int:
        return self._factor.factor_nonzeros

    @property
    def ordering(self) -> np.ndarray | None:
        """The factorisation's fill-in reducing ordering of the free DOFs (None with the Schur complement)."""
        return self._factor.ordering

    def contact_solve(self, rhs: np.ndarray) -> np.ndarray:
        """S⁻¹ rhs = (K⁻¹)_cc rhs for rhs on the contact DOFs (1D or columns)."""
        return sla.cho_solve(self._cholesky, np.asarray(rhs), check_finite=False)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """U = K⁻¹ rhs on the free DOFs, 0 on the others (rhs in full numbering, 1D or 2D)."""
        rhs = np.asarray(rhs)
        out = np.zeros(rhs.shape)
        schur = self.contact_solve if self._cholesky is not None else None
        out[self.free] = self._factor.solve(rhs[self.free], schur)
        return out


class UpdatedOperator:
    """(K + Dᵀ diag(δ) D)⁻¹ from K's factorisation, for a few rows D (r × ndof), by Woodbury's identity.

        (K + Dᵀ Δ D)⁻¹ = K⁻¹ − Z C⁻¹ Zᵀ,     Z = K⁻¹ Dᵀ,     C = Δ⁻¹ + D Z,

    and on the contact DOFs (K_t⁻¹)_cc = S⁻¹ − Z_c C⁻¹ Z_cᵀ: r back-substitutions (``columns``, the columns of Z
    already computed for K, keyed by row) and an r × r LU instead of a factorisation.
    """

    def __init__(self, base: ElasticOperator, D: sp.csr_matrix, delta: np.ndarray, columns: dict, keys: np.ndarray):
        self.base, self.ndof, self.free, self.contact_dofs = base, base.ndof, base.free, base.contact_dofs
        missing = [i for i, key in enumerate(keys) if key not in columns]
        if missing:
            for key, column in zip(keys[missing], base.solve(D[missing].T.toarray()).T):
                columns[key] = column
        self.D = D
        self._Z = np.column_stack([columns[key] for key in keys])
        self._lu = sla.lu_factor(np.diag(1.0 / delta) + D @ self._Z, check_finite=False)

    @property
    def condensed(self) -> bool:
        return self.base.condensed

    @property
    def factor_nonzeros(self) -> int:
        return self.base.factor_nonzeros

    def contact_solve(self, rhs: np.ndarray) -> np.ndarray:
        Zc = self._Z[self.contact_dofs]
        return self.base.contact_solve(rhs) - Zc @ sla.lu_solve(self._lu, Zc.T @ np.asarray(rhs), check_finite=False)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        y = self.base.solve(rhs)
        return y - self._Z @ sla.lu_solve(self._lu, self.D @ y, check_finite=False)
