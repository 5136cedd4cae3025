"""The condensed step problem on the contact patch: Newton matrices from the compliance columns the patch needs.

The Newton matrix M of :class:`~ngwear.numerics.systems.condensed.CondensedSystem` is the identity's in the columns of the
points out of contact (O: p' = 0, not active).  With C the patch (p' > 0 or active) and the plate's rows,

    [M_CC  −Ψ_C] [z_C]   [b_C]
    [B_C    S_J] [z_δ] = [b_δ],      z_O = b_O − M_OC z_C + Ψ_O z_δ,

so a Newton step needs the |C| columns of the compliance that M has (:class:`~ngwear.numerics.columns.Columns`,
computed when a point first enters C) and the (|C| + r)² matrix R of the left.

From step to step the patch moves by a few points, so R is factorised for one pattern, the *base* (C₀, its LU),
and a later pattern is solved with it by Woodbury's identity.  In the frame F = C₀ ∪ C (the base's points, the
plate, the points N = C − C₀ that came in), the base's matrix M₀ is block lower triangular,

    M₀ = [R₀ 0; L I],   L = rows N of the base's columns:   M₀⁻¹ b = [R₀⁻¹ b₁; b₂ − L R₀⁻¹ b₁],

and the pattern's matrix M₁ differs from it in the k columns J of the points whose state changed (p', active, in or
out of C): M₁ = M₀ + (W − M₀ E) Eᵀ, W the new columns, E = I_{:,J}.  Then

    z = M₀⁻¹ (b − W c) + E c,     c = (Eᵀ M₀⁻¹ W)⁻¹ Eᵀ M₀⁻¹ b:

two solves with R₀'s LU and a k × k LU instead of an LU of R.  Beyond ``RANK`` changed columns the pattern becomes
the base.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg as sla

from ..wear import PointLaw
from .condensed import CondensedSystem
from .krylov import KrylovSystem
from .newton import PlateRows

RANK = 32
"""Most columns a pattern's matrix may differ in from the base's before it is factorised itself."""
BASE = "base"
"""The key of the base in the store a run keeps (beside ``"patterns"``, the updates by pattern)."""


class Base(NamedTuple):
    """The pattern (``active``, ``dp``) whose matrix R₀ on its patch and the plate is factorised (``lu``)."""

    patch: np.ndarray
    active: np.ndarray
    dp: np.ndarray
    lu: tuple


class Update(NamedTuple):
    """A pattern against the base: N (the points that came in), L, W, the frame positions of J, Eᵀ M₀⁻¹ W's LU.

    ``lu`` is None when no column changed (k = 0).
    """

    new: np.ndarray
    L: np.ndarray
    W: np.ndarray
    at: np.ndarray
    lu: tuple | None


class PatchSystem(CondensedSystem):
    """The condensed step problem on the contact patch (see the module docstring).

    ``columns``: :class:`~ngwear.numerics.columns.Columns`, the compliance's columns kept for the run; ``store``:
    the base and the patterns' updates (LRU as the factors of :class:`CondensedSystem`), kept across iterations and
    steps.  The columns of active points, H_:j m_j, are scaled by c_j = 1/(m_j h_j) to the order of the others: LU
    with pivoting does not mind a column's scale, Woodbury's k × k matrix does (unscaled, its error turned the pin's
    active set in circles at 1 000 N).  c and the plate's row scaling come from the estimate h_i ≤ H_ii
    (``compliance``) as in :class:`~.krylov.KrylovSystem`; the iterates are the dense system's up to
    round-off.  A body held by the plate alone first moves rigidly to its force balance (:meth:`start`).
    """

    def __init__(self, columns, compliance, weights, s_load, d0, gap, law: PointLaw, store: dict,
                 plate: PlateRows | None = None, tolerance: float = 1e-10):
        super().__init__(compliance, weights, s_load, d0, gap, law, plate, tolerance)
        self.columns, self.store = columns, store
        self.factors = store.setdefault("patterns", {})
        self.modes = 0 if plate is None else len(self.rows)

    def response(self, directed, normal):
        return self.columns(directed, normal)

    start = KrylovSystem.start
    """The warm start moved rigidly to the plate's force balance (:meth:`KrylovSystem.start`)."""

    def step(self, x, lam, active):
        self.columns.clearance = x[:self.n] - self.d0
        return super().step(x, lam, active)

    # ---- the matrices --------------------------------------------------------------------------------------
    def _block(self, rows, points, active, dp) -> np.ndarray:
        """M's columns of ``points`` in the pattern (active, dp): the rows ``rows``, then the plate's (scaled)."""
        m, touching = self.m, active[points]
        pressing = ~touching & (dp[points] > 0)
        self.columns.ensure(points[pressing], points[touching])
        out = np.zeros((len(rows) + self.modes, len(points)))
        out[:len(rows), pressing] = self.columns.directed.block(rows, points[pressing]) * (m * dp)[points[pressing]]
        out[:len(rows), touching] = self.columns.normal.block(rows, points[touching]) * (m * self.c)[points[touching]]
        position = np.full(self.n, -1)
        position[rows] = np.arange(len(rows))
        own = (position[points] >= 0) & ~touching
        out[position[points[own]], np.flatnonzero(own)] += 1.0
        if self.plate is not None:
            below = (self.plate.directed[points] * (m * dp * ~active)[points, None]
                     + self.plate.normal[points] * (m * self.c * active)[points, None])
            out[len(rows):] = self.rows[:, None] * below.T
        return out

    def _core(self, rows: np.ndarray, points: np.ndarray, active, dp) -> np.ndarray:
        """[rows of the points; the plate's rows] × [columns of the points | the plate's columns −Ψ, S_J]."""
        block = self._block(rows, points, active, dp)
        if self.plate is None:
            return block
        return np.hstack([block, np.vstack([-self.plate.normal[rows], self.rows[:, None] * self.jacobian_stiffness])])

    def _factor(self, active, dp) -> tuple[Base, Update]:
        """The base's LU and the pattern's update against it (a new base beyond ``RANK`` changed columns)."""
        base = self.store.get(BASE)
        changed = None if base is None else np.flatnonzero((active != base.active) | ((dp != base.dp) & ~active))
        if changed is None or len(changed) > RANK:
            patch = np.flatnonzero(active | (dp > 0))
            self.factors.clear()
            base = self.store[BASE] = Base(patch, active.copy(), dp.copy(),
                                           sla.lu_factor(self._core(patch, patch, active, dp), check_finite=False))
            changed = np.zeros(0, int)

        def build() -> Update:
            new = np.setdiff1d(np.flatnonzero(active | (dp > 0)), base.patch)
            L = self._core(new, base.patch, base.active, base.dp)[:len(new)]       # rows N of M₀'s core columns
            frame = np.concatenate([base.patch, new])
            position = np.full(self.n, -1)
            position[frame] = np.arange(len(frame))
            at = position[changed]
            at = np.where(at < len(base.patch), at, at + self.modes)         # the frame: base, plate, N
            block = self._block(frame, changed, active, dp)
            W = np.vstack([block[:len(base.patch)], block[len(frame):], block[len(base.patch):len(frame)]])
            lu = None
            if len(changed):
                lu = sla.lu_factor(self._base_solve(base, L, W)[at], check_finite=False)
            return Update(new, L, W, at, lu)
        return base, self._remember(active.tobytes() + dp.tobytes(), build)

    @staticmethod
    def _base_solve(base: Base, L: np.ndarray, b: np.ndarray) -> np.ndarray:
        """M₀⁻¹ b in the frame (the base's patch, the plate, the points that came in)."""
        core = len(base.lu[1])
        first = sla.lu_solve(base.lu, b[:core], check_finite=False)
        return np.concatenate([first, b[core:] - L @ first])

    def _solve(self, active, dp, rhs, lam):
        base, update = self._factor(active, dp)
        n, size = self.n, len(base.patch)
        core = size + self.modes
        b = np.concatenate([rhs[base.patch], rhs[n:], rhs[update.new]])
        z = self._base_solve(base, update.L, b)
        if update.lu is not None:
            c = sla.lu_solve(update.lu, z[update.at], check_finite=False)
            z = self._base_solve(base, update.L, b - update.W @ c)
            z[update.at] += c
        on = np.zeros(n)
        on[base.patch], on[update.new] = z[:size], z[core:]
        on *= np.where(active, self.c, 1.0)                     # the active points' columns are scaled by c_i
        out = rhs.copy()
        out[:n] -= self.response(self.m * dp * ~active * on, self.m * active * on)
        if self.plate is not None:
            out[:n] += self.plate.normal @ z[size:core]
            out[n:] = z[size:core]
        out[base.patch], out[update.new] = on[base.patch], on[update.new]
        return out
