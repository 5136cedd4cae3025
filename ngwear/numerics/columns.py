"""Columns of the point compliance, computed for the points that come into contact and remembered for the run.

The condensed contact problem needs the compliance only where the foundation presses: a Newton matrix of
:class:`~ngwear.numerics.systems.condensed.CondensedSystem` has the columns A_:j m_j p'_j of the points with p'_j > 0 and
H_:j m_j of the active ones (u_ν = g); every other column is the identity's.  The residual needs A (m∘p) and
H (m∘λ), again columns on the support of p and λ only.  Where the contact patch is a part of Γ_C (a sphere, a
worn flat growing, a pin on a disc) these few columns are the whole of what the compliance contributes, and each
is computed once: A_:j = N K⁻¹ Pᵀ (e_j ⊗ b_j) and H_:j = N K⁻¹ Pᵀ (e_j ⊗ ν), b_j = ν + μ n*_j, one back-substitution
each, ``BLOCK`` at a time.

:class:`Columns` holds them in the order they were computed; a product A a + H b is one dense product with the
columns of the points where a and b are nonzero, exact (no tolerance).  A request for fewer than ``AHEAD`` columns
is filled with the points nearest to contact (the largest s_i − d₀,i among those without a column), which a growing
patch takes in over the next steps.
"""
from __future__ import annotations

import numpy as np

BLOCK = 64
"""Right-hand sides per back-substitution: a block reads the factor once for all its columns (a back-substitution is
memory-bound), so a column costs a fraction of a single one's; larger blocks gain little more."""
AHEAD = 16
"""Fewest columns a back-substitution computes: a smaller request is filled with the points next to come into
contact (a block costs much less than its columns one by one, see :data:`BLOCK`)."""


class _Store:
    """Columns X_:j of one kind (A or H), by point; ``slot[j]`` their position (−1: not computed)."""

    def __init__(self, n: int):
        self.values = np.empty((n, 0))
        self.slot = np.full(n, -1)
        self.size = 0

    def missing(self, points: np.ndarray) -> np.ndarray:
        return points[self.slot[points] < 0]

    def add(self, points: np.ndarray, columns: np.ndarray) -> None:
        if self.size + len(points) > self.values.shape[1]:
            grown = np.empty((self.values.shape[0], max(2 * self.values.shape[1], self.size + len(points), 16)))
            grown[:, :self.size] = self.values[:, :self.size]
            self.values = grown
        self.values[:, self.size:self.size + len(points)] = columns
        self.slot[points] = np.arange(self.size, self.size + len(points))
        self.size += len(points)

    def times(self, x: np.ndarray) -> np.ndarray:
        """X x for x on the points (zero where no column is computed)."""
        at = np.flatnonzero(x)
        coefficients = np.zeros(self.size)
        coefficients[self.slot[at]] = x[at]
        return self.values[:, :self.size] @ coefficients

    def block(self, rows: np.ndarray, points: np.ndarray) -> np.ndarray:
        """X_{rows, points}."""
        return self.values[np.ix_(rows, self.slot[points])]



class Columns:
    """The columns of A = H + μ F (force directions b_j) and H (along ν) computed so far in the run.

    ``respond(directed, normal)``: A directed + H normal for k columns (n × k), one back-substitution with k
    right-hand sides.  ``normal``: the H columns of an earlier instance (they do not depend on μ n*), shared;
    ``same``: A = H (no friction), one store for both.
    """

    def __init__(self, respond, n: int, normal: _Store | None = None, same: bool = False):
        self._respond, self.n = respond, n
        self.normal = normal if normal is not None else _Store(n)
        self.directed = self.normal if same else _Store(n)
        self.clearance = np.zeros(n)          # s − d₀ at the last Newton step: the points nearest to contact first

    def ensure(self, directed: np.ndarray, normal: np.ndarray) -> None:
        """Compute the missing columns of the points ``directed`` (A) and ``normal`` (H), one block solve."""
        need_a, need_h = self.directed.missing(directed), self.normal.missing(normal)
        if not len(need_a) and not len(need_h):
            return
        if self.normal is self.directed:
            need_a, need_h = np.union1d(need_a, need_h), np.zeros(0, int)
        if len(need_a):
            need_a = self._ahead(need_a)
        kinds = np.concatenate([np.zeros(len(need_a), bool), np.ones(len(need_h), bool)])
        points = np.concatenate([need_a, need_h])
        for start in range(0, len(points), BLOCK):
            at, normal = points[start:start + BLOCK], kinds[start:start + BLOCK]
            forces = np.zeros((self.n, len(at)))
            forces[at, np.arange(len(at))] = 1.0
            out = self._respond(forces * ~normal, forces * normal)
            self.directed.add(at[~normal], out[:, ~normal])
            self.normal.add(at[normal], out[:, normal])

    def _ahead(self, points: np.ndarray) -> np.ndarray:
        """``points``, filled up to AHEAD with points without a column, those nearest to contact first."""
        free = np.flatnonzero(self.directed.slot < 0)
        free = free[~np.isin(free, points)]
        count = min(AHEAD - len(points), len(free))
        if count <= 0:
            return points
        nearest = free[np.argpartition(-self.clearance[free], count - 1)[:count]]
        return np.concatenate([points, nearest])

    def __call__(self, directed: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """A directed + H normal, exact: a dense product with the columns of their supports."""
        self.ensure(np.flatnonzero(directed), np.flatnonzero(normal))
        out = self.directed.times(directed) if directed.any() else np.zeros(self.n)
        return out + self.normal.times(normal) if normal.any() else out
