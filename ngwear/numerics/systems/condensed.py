"""The step problem condensed onto the contact points, and its dense algebra.

For the normal displacements s_i at the n contact points (and the plate's δ): R = s − s_F + A (m∘p) + H (m∘λ) with
H = ν·G·ν, A_ij = H_ij + μ ν·G_ij·n*_j, G = P K⁻¹ Pᵀ the point compliance.  A rigid plate (:mod:`ngwear.numerics.plate`)
borders it with its r unknowns δ: R_s gains −Ψ δ and the rows R_δ = S δ + Φ_bᵀ (m∘p) + Ψᵀ (m∘λ) − s_F (f_B + F_B)
join, scaled to lengths.  :class:`CondensedSystem` holds what every condensed system shares, :class:`DenseSystem` the
dense matrices; the matrix-free ones are :mod:`.krylov` (GCR with recycling) and :mod:`.patch` (on the contact patch).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..wear import PointLaw
from .newton import PlateRows, balance_along

FACTOR_BYTES = 2.5e8
"""Memory for the LU factors of the dense Newton matrices kept for patterns that recur (at most 16, LRU)."""
SWEEPS = 8
"""Most sweeps of iterative refinement with a reference μ's factors (:class:`Factors`) before M itself is factorised."""
CONTRACTION = 4.0
"""Least factor by which a sweep must shrink the residual, else refining costs more than a factorisation."""


class Factors(dict):
    """The factorised Newton matrices of a run by pattern (active set, p'), kept across iterations and steps.

    ``reference``: (A, b_i·Φ_i) of a reference μ, with which the matrices are factorised instead of the step's (None:
    the step's own).  While μ is a coefficient of the state it changes at every step (:mod:`ngwear.runs.heating`):
    the matrices M̃ of the reference μ (:attr:`~ngwear.numerics.contact.Contact.reference`) are factorised once and
    precondition iterative refinement with the step's M, z ← z + M̃⁻¹ (b − M z), M applied by products
    (:meth:`CondensedSystem.solve`).
    """

    def __init__(self, reference: tuple | None = None):
        super().__init__()
        self.reference = reference


class CondensedSystem:
    """The step problem condensed onto the n contact points: what every condensed system shares.

    The unknowns x = (s, δ), the residual, the merit, the Newton step of the active set and its solve (refined with
    a reference μ's factors, :class:`Factors`), and the scalings: the plate's rows are multiplied by h / ‖Ψ_k‖∞ (h
    the largest point compliance H_ii), which turns forces into lengths comparable with the rows of s.  A body held by
    the plate alone (S = 0) with no contact stiffness in the Newton matrix moves rigidly to its force balance first
    (:func:`~.newton.balance_along`).  The Jacobian's S gets, on the tilts only, a spring 10⁻¹² times the body's
    contact stiffness, which keeps them regular while few points touch (the translation's row stays exact: the force
    balance holds to round-off).  How the compliance is applied and the Newton matrix solved is each system's:
    :class:`DenseSystem`, :class:`~.krylov.KrylovSystem`, :class:`~.patch.PatchSystem`.
    """

    reference = None
    """(A, b_i·Φ_i) of the reference μ whose factors precondition this step's solves (:class:`Factors`); None: the
    step's own matrices are factorised (and the matrix-free systems factorise none)."""

    def __init__(self, compliance, weights, s_load, d0, gap, law: PointLaw, plate: PlateRows | None = None,
                 tolerance: float = 1e-10):
        """Scalings from the point compliances ``compliance`` (H_ii, or an estimate of it); a solve's tolerance.

        A Newton step solved inexactly (matrix-free, or refined) meets ‖M z − b‖∞ ≤ ``atol``, 1/100 of Newton's
        ``tolerance`` on the problem's length scale, so that Newton's merit test sees exact steps.
        """
        self.m, self.s_load, self.d0, self.g, self.law = weights, s_load, d0, gap, law
        self.n = len(weights)
        self.c = 1.0 / np.maximum(compliance * weights, 1e-300)
        self.scale = max(np.abs(s_load).max(initial=0.0), gap)
        self.atol = 1e-2 * tolerance * self.scale
        self.plate, self._last = plate, (None, None)
        if plate is not None:
            reach = np.maximum(np.abs(plate.normal).max(axis=0, initial=0.0), 1e-300)
            self.rows = max(compliance.max(initial=0.0), 1e-300) / reach
            contact_stiffness = (plate.normal ** 2 / np.maximum(compliance, 1e-300)[:, None]).sum(axis=0)
            spring = np.maximum(1e-12 * contact_stiffness, 1e-300)
            spring[0] = 0.0
            self.jacobian_stiffness = plate.stiffness + np.diag(spring)
            self.floating = plate.stiffness[0, 0] <= 1e-9 * contact_stiffness[0]

    def gap(self, x):
        return x[:self.n] - self.d0 - self.g

    def residual(self, x, lam):
        """R(x, λ), remembered for the last (x, λ): Newton asks twice per iterate."""
        key = x.tobytes() + lam.tobytes()
        if self._last[0] != key:
            self._last = key, self._residual(x, lam)
        return self._last[1]

    def _residual(self, x, lam):
        s, p = x[:self.n], self.law.pressure(x[:self.n] - self.d0)
        r_s = s - self.s_load + self.response(self.m * p, self.m * lam)
        if self.plate is None:
            return r_s
        return np.concatenate([r_s - self.plate.normal @ x[self.n:], self.rows * self._plate_rows(x, lam)])

    def _plate_rows(self, x, lam):
        """The plate's force balance S δ + Φ_bᵀ (m∘p) + Ψᵀ (m∘λ) − s_F (f_B + F_B), unscaled (no product)."""
        plate, p = self.plate, self.law.pressure(x[:self.n] - self.d0)
        return plate.stiffness @ x[self.n:] + plate.directed.T @ (self.m * p) + plate.normal.T @ (self.m * lam) - plate.load

    def merit(self, x, lam):
        """max(|R|, |min(λ/c, −gap)|) / S, and the layer's overshoot max (s − d₀ − g)₊ / g in its own terms.

        S grows with the loads' displacements, which dwarf g on a very soft body: there a gap of S·tol would
        pass as converged; an active point's s is set to d₀ + g exactly, so the overshoot is driven to g·tol.
        """
        gap = self.gap(x)
        comp = np.minimum(lam / self.c, -gap)
        return max(np.abs(self.residual(x, lam)).max(initial=0) / self.scale, np.abs(comp).max(initial=0) / self.scale,
                   gap.max(initial=0) / self.g)

    def step(self, x, lam, active):
        n = self.n
        dp = self.law.derivative(x[:n] - self.d0)
        if self.plate is not None and self.floating and not active.any() and not dp.any():
            rigid = np.concatenate([self.plate.normal[:, 0], np.eye(len(x) - n)[0]])
            return balance_along(lambda y: self.residual(y, lam)[n], x, rigid), lam
        ds = np.zeros(n)
        ds[active] = -self.gap(x)[active]
        known = np.zeros(len(x))
        known[:n] = self.response(-self.m * dp * ds, self.m * lam) - ds
        if self.plate is not None:
            plate = self.plate
            known[n:] = self.rows * (plate.normal.T @ (self.m * lam) - plate.directed.T @ (self.m * dp * ds))
        sol = self.solve(active, dp, -self.residual(x, lam) + known, lam)
        lam_new = np.where(active, sol[:n], 0.0)
        dx = sol.copy()
        dx[:n] = np.where(active, ds, sol[:n])
        return dx, lam_new

    def solve(self, active, dp, rhs, lam):
        """The Newton step's solve: z = M⁻¹ rhs, M the Newton matrix of the pattern (active, dp).

        With the factors of a reference μ (:class:`Factors`) refined to ‖rhs − M z‖∞ ≤ ``atol``; should a sweep not
        shrink the residual ``CONTRACTION``-fold, or ``SWEEPS`` not reach it, M itself is factorised (not kept).
        """
        z = self._solve(active, dp, rhs, lam)
        if self.reference is None:
            return z
        last = np.inf
        for _ in range(SWEEPS):
            r = rhs - self.apply(active, dp, z)
            size = np.abs(r).max(initial=0.0)
            if size <= self.atol:
                return z
            if size > last / CONTRACTION:
                break
            z, last = z + self._solve(active, dp, r, lam), size
        return sla.lu_solve(sla.lu_factor(self.matrix(active, dp, *self._own()), check_finite=False), rhs,
                            check_finite=False)

    def apply(self, active, dp, z):
        """M z by products (M of :meth:`matrix` with this step's A)."""
        n, inactive = self.n, ~active
        directed, normal = self.m * dp * inactive * z[:n], self.m * active * z[:n]
        return self._image(active, z, directed, normal, self.response(directed, normal))

    def _image(self, active, z, directed, normal, response):
        """M z, given its contact part's inputs (directed, normal) and their response R(directed, normal).

        The inputs are (m p' z, m z) on the (inactive, active) points; :meth:`apply` computes the response by products,
        :class:`KrylovSystem` has it from its recycler.
        """
        n = self.n
        out = np.empty_like(z)
        out[:n] = ~active * z[:n] + response
        if self.plate is not None:
            plate = self.plate
            out[:n] -= plate.normal @ z[n:]
            out[n:] = self.rows * (plate.directed.T @ directed + plate.normal.T @ normal
                                   + self.jacobian_stiffness @ z[n:])
        return out

    def start(self, x, lam):
        """The warm start (x, λ) Newton begins from: itself (see :meth:`PatchSystem.start`)."""
        return x, lam

    def _remember(self, key, build):
        """The factors of ``key``, built by ``build()`` when new and kept LRU within ``FACTOR_BYTES`` (16 at most)."""
        if key in self.factors:
            self.factors[key] = self.factors.pop(key)       # the most recently used last
            return self.factors[key]
        factors = build()
        size = max(sum(a.nbytes for a in factors if isinstance(a, np.ndarray)), 1)
        while self.factors and len(self.factors) >= min(16, max(1, int(FACTOR_BYTES // size))):
            del self.factors[next(iter(self.factors))]      # the least recently used
        self.factors[key] = factors
        return factors


class DenseSystem(CondensedSystem):
    """The condensed step problem in dense (n + r) × (n + r) algebra, H and A = H + μ F given as matrices.

    ``factors`` caches LU factorisations of the Newton matrix by (active set, p'): with a piecewise-linear law the
    matrix repeats across iterations and steps and is factorised once (the 16 most recently used, fewer if they would
    take more than ``FACTOR_BYTES``).
    """

    def __init__(self, H, A, weights, s_load, d0, gap, law: PointLaw, factors: Factors | None = None,
                 plate: PlateRows | None = None, tolerance: float = 1e-10):
        super().__init__(np.diag(H), weights, s_load, d0, gap, law, plate, tolerance)
        self.H, self.A = H, A
        self.factors = Factors() if factors is None else factors
        self.reference = self.factors.reference

    def response(self, directed, normal):
        """A directed + H normal: normal displacements under point forces along b_i and along ν (zeros skipped)."""
        out = self.A @ directed if directed.any() else np.zeros(self.n)
        return out + self.H @ normal if normal.any() else out

    def _factor(self, active, dp):
        """LU of the pattern's Newton matrix (:meth:`matrix`), of the reference μ with :attr:`Factors.reference`."""
        A, directed = self._own() if self.reference is None else self.reference
        return self._remember(active.tobytes() + dp.tobytes(),
                              lambda: sla.lu_factor(self.matrix(active, dp, A, directed), check_finite=False))

    def _own(self) -> tuple:
        """(A, b_i·Φ_i) of this step."""
        return self.A, None if self.plate is None else self.plate.directed

    def matrix(self, active, dp, A, directed) -> np.ndarray:
        """The Newton matrix of the pattern (active, dp) with the compliance A and the plate's b_i·Φ_i ``directed``.

        M = [J_{:,I} | H_{:,A} diag(m_A) | −Ψ], J = I + A diag(m p'), bordered by the plate's rows.
        """
        inactive = ~active
        M = A * (self.m * dp * inactive)[None, :] + self.H * (self.m * active)[None, :]
        M[np.diag_indices(len(dp))] += inactive
        if self.plate is None:
            return M
        plate = self.plate
        below = (directed * (self.m * dp * inactive)[:, None] + plate.normal * (self.m * active)[:, None]).T
        return np.block([[M, -plate.normal], [self.rows[:, None] * below, self.rows[:, None] * self.jacobian_stiffness]])

    def _solve(self, active, dp, rhs, lam):
        return sla.lu_solve(self._factor(active, dp), rhs, check_finite=False)
