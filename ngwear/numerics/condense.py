"""The elastic operator, factorised once, and its condensation onto the contact DOFs.

K is symmetric positive definite on the free DOFs.  Ordering the contact DOFs c last (after a
nested-dissection ordering of the interior, METIS) makes the trailing block of the LU factors the
Schur complement S = K_cc − K_ci K_ii⁻¹ K_ic, so the contact compliance (K⁻¹)_cc = S⁻¹ comes out of
the single factorisation instead of one back-substitution per contact DOF.
"""
from __future__ import annotations

import numpy as np
import pymetis
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def nested_dissection(K: sp.csr_matrix, nodes: np.ndarray) -> np.ndarray:
    """Fill-reducing ordering of a symmetric matrix: METIS nested dissection of its node graph.

    ``nodes[i]`` is the mesh node of unknown i; the d components of a node stay together, which
    halves (2D) or thirds (3D) the graph METIS orders at no cost in fill.
    """
    if K.shape[0] < 3:
        return np.arange(K.shape[0])
    ids, node = np.unique(nodes, return_inverse=True)
    B = sp.csr_matrix((np.ones(len(node)), (np.arange(len(node)), node)), shape=(len(node), len(ids)))
    graph = (B.T @ abs(K) @ B).tocsr()
    graph.setdiag(0)
    graph.eliminate_zeros()
    adjacency = pymetis.CSRAdjacency(graph.indptr.astype(np.int32), graph.indices.astype(np.int32))
    perm, _ = pymetis.nested_dissection(adjacency)
    rank = np.empty(len(ids), dtype=int)
    rank[np.asarray(perm)] = np.arange(len(ids))
    return np.argsort(rank[node], kind="stable")


class ElasticOperator:
    """K⁻¹ on the free DOFs, with (K⁻¹)_cc for the given contact DOFs (full numbering).

    ``nodes`` maps every DOF to its mesh node (for the ordering).
    """

    def __init__(self, K: sp.csr_matrix, free: np.ndarray, contact_dofs: np.ndarray, nodes: np.ndarray):
        self.ndof = K.shape[0]
        self.free = np.flatnonzero(free)
        local = np.full(self.ndof, -1)
        local[self.free] = np.arange(len(self.free))
        self.contact_dofs = np.asarray([d for d in contact_dofs if free[d]], dtype=int)
        c = local[self.contact_dofs]
        Kf = K[self.free][:, self.free].tocsr()
        interior = np.setdiff1d(np.arange(len(self.free)), c)
        inner = nested_dissection(Kf[interior][:, interior], nodes[self.free[interior]])
        order = np.concatenate([interior[inner], c]).astype(int)
        self._order = order
        self._lu = spla.splu(Kf[order][:, order].tocsc(), permc_spec="NATURAL",
                             diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        n, nc = len(order), len(c)
        if nc:
            L = self._lu.L[:, n - nc:][n - nc:].toarray()
            U = self._lu.U[:, n - nc:][n - nc:].toarray()
            self.contact_inverse = sla.inv(L @ U)
            self.contact_inverse = 0.5 * (self.contact_inverse + self.contact_inverse.T)
        else:
            self.contact_inverse = np.zeros((0, 0))

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """U = K⁻¹ rhs on the free DOFs, 0 on the others (rhs in full numbering, 1D or 2D)."""
        rhs = np.asarray(rhs)
        out = np.zeros(rhs.shape)
        sub = rhs[self.free][self._order]
        x = self._lu.solve(sub)
        full = np.empty_like(x)
        full[self._order] = x
        out[self.free] = full
        return out
