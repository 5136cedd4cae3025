"""Semismooth Newton with a projection (primal–dual active set) for one time step.

Each step solves, for the normal displacements s_i = ν·u(x_i) at the contact points and the
reactions λ_i of the rigid foundation,

    R(x, λ) = 0,   s − d₀ − g ≤ 0,   λ ≥ 0,   λ·(s − d₀ − g) = 0,

with the complementarity written as C(x, λ) = λ − max(0, λ + c (s − d₀ − g)) = 0.  The active set
A = {i : λ_i + c_i (s_i − d₀,i − g) > 0} is fixed at s_i = d₀,i + g and λ_i = 0 off A; the Newton
matrix K + R'(u) is non-symmetric when μ > 0.  Steps are damped by backtracking on the merit
max(|R|, |min(λ/c, g + d₀ − s)|), whose overshoot of the layer (s − d₀ − g)₊ is measured against g itself
(the constraint holds to g·tolerance however soft the body).  Two systems implement the same protocol:

* :class:`CondensedSystem`: unknown x = s (n contact points); R = s − s_F + A (m∘p) + H (m∘λ) with
  H = ν·G·ν, A_ij = H_ij + μ ν·G_ij·n*_j, G = P K⁻¹ Pᵀ the point compliance (dense, small).  A rigid
  plate (:mod:`ngwear.numerics.plate`) borders it with its r unknowns δ: R_s gains −Ψ δ and the rows
  R_δ = S δ + Φ_bᵀ (m∘p) + Ψᵀ (m∘λ) − s_F (f_B + F_B) join, scaled to lengths.
* :class:`KrylovSystem`: the same, matrix-free (each product with H or A one back-substitution,
  remembered across the run; GCR with recycling for the Newton steps), for contact surfaces too large
  for dense n × n matrices; :class:`~ngwear.numerics.patch.PatchSystem` solves it on the contact patch.
* :class:`FullSystem`: unknown x = the free DOFs (and δ, in the basis u = T x); R = Tᵀ(K u + R_c(u) +
  (N P)ᵀ(m∘λ) − F) assembled by NGSolve (``Apply`` / ``AssembleLinearization``) and solved as a sparse
  saddle-point system.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import ngsolve as ngs
import numpy as np
import scipy.linalg as sla
import scipy.optimize as spo
import scipy.sparse as sp
import scipy.sparse.linalg as spla

log = logging.getLogger(__name__)


class ConvergenceError(RuntimeError):
    """Newton did not converge; ``record`` holds its history."""

    def __init__(self, message: str, record: NewtonRecord):
        super().__init__(message)
        self.record = record


@dataclass
class NewtonRecord:
    """History of one step's Newton solve.

    ``cutbacks``: the load continuations tried before the step converged (or before it was given up),
    each cutting the step's load change into m = 2, 4, 8 parts (:mod:`ngwear.runs.step`); the
    other fields are those of the last solve.
    A nonlinear material's step: ``bulk`` iterations of its fixed point, ``tangents`` factorised in the run so far.
    """

    converged: bool = False
    iterations: int = 0
    residuals: list[float] = field(default_factory=list)
    active: int = 0
    damped: int = 0
    bulk: int = 0
    tangents: int = 0
    cutbacks: int = 0


MEMORY = 5
UNDAMPED = 20
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


def semismooth_newton(system, x, lam, tol: float = 1e-10, max_iterations: int = 50):
    """Solve ``system`` from the warm start (x, λ); returns (x, λ, NewtonRecord).

    First the pure semismooth Newton iteration (full steps: for a piecewise-linear law it ends in
    finitely many steps, however stiff), for at most ``UNDAMPED`` iterations; if that does not
    converge, a damped restart from the warm start with a non-monotone line search
    (Grippo–Lampariello–Lucidi): a step is accepted when the merit drops below the largest of the
    last ``MEMORY`` merits; halving stops at θ = 1/1024.  Iterations of both phases count.
    """
    rec = NewtonRecord()
    start = system.start(x, lam)
    for damped in (False, True):
        x, lam = start
        merit = system.merit(x, lam)
        history = [merit]
        active_old = None
        budget = min(UNDAMPED, max_iterations) if not damped else max_iterations - rec.iterations
        for _ in range(budget):
            active = lam + system.c * system.gap(x) > 0
            dx, lam_new = system.step(x, lam, active)
            reference = max(history[-MEMORY:])
            theta = 1.0
            while True:
                x_try, lam_try = x + theta * dx, lam + theta * (lam_new - lam)
                with np.errstate(over="ignore", invalid="ignore"):  # a wild trial step is detected below
                    merit_try = system.merit(x_try, lam_try)
                if not np.isfinite(merit_try) and not damped:
                    break
                if not damped or merit_try <= (1 - 1e-4 * theta) * reference or theta < 1e-3:
                    break
                theta *= 0.5
            if not np.isfinite(merit_try):
                if damped:
                    merit = merit_try
                break
            rec.damped += theta < 1
            x, lam, merit = x_try, lam_try, merit_try
            rec.iterations, rec.active = rec.iterations + 1, int(active.sum())
            history.append(merit)
            rec.residuals.append(merit)
            if merit <= tol and (active_old is None or np.array_equal(active, active_old) or merit == 0):
                rec.converged = True
                return x, lam, rec
            active_old = active
        if rec.iterations >= max_iterations:
            break
    raise ConvergenceError(
        f"Newton did not converge in {rec.iterations} iterations (merit {merit:.2e} > {tol:.0e})", rec)


def balance_along(balance, x: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """The step Δ·direction that zeroes ``balance(x + Δ direction)``, a function increasing in Δ.

    The body's force balance along ν while it moves rigidly: the Newton step for a body held by a
    plate alone when no contact point has stiffness (lost contact, or the power law's zero slope at
    first touch), where the Newton matrix is singular.  Bracketing by doubling, then bisection.
    """
    value = lambda delta: balance(x + delta * direction)  # noqa: E731
    lo, hi = 0.0, 1e-6 * max(np.abs(x).max(initial=0.0), 1e-6)
    while value(hi) < 0 and hi < 1e30:
        lo, hi = hi, 2 * hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (mid, hi) if value(mid) < 0 else (lo, mid)
    return hi * direction


@dataclass
class PointLaw:
    """Nodal contact law at one step: pressure p(z) and dp/dz as functions of z = s − d₀."""

    pressure: callable
    derivative: callable


@dataclass(frozen=True)
class PlateRows:
    """The plate's unknowns δ bordering the condensed system: Ψ, Φ_b = b_i·Φ_i, S and the step's load."""

    normal: np.ndarray
    directed: np.ndarray
    stiffness: np.ndarray
    load: np.ndarray


class CondensedSystem:
    """The step problem condensed onto the n contact points (dense (n + r) × (n + r) algebra).

    ``factors`` caches LU factorisations of the Newton matrix by (active set, p'): with a
    piecewise-linear law the matrix repeats across iterations and steps and is factorised once
    (the 16 most recently used, fewer if they would take more than ``FACTOR_BYTES``).
    The plate's rows are multiplied by h / ‖Ψ_k‖∞ (h the largest point compliance H_ii), which turns
    forces into lengths comparable with the rows of s.  A body held by the plate alone (S = 0) with no
    contact stiffness in the Newton matrix moves rigidly to its force balance first
    (:func:`balance_along`).  The Jacobian's S gets, on the tilts only, a spring 10⁻¹² times the body's
    contact stiffness, which keeps them regular while few points touch (the translation's row stays
    exact: the force balance holds to round-off).
    """

    reference = None
    """(A, b_i·Φ_i) of the reference μ whose factors precondition this step's solves (:class:`Factors`); None: the
    step's own matrices are factorised (and the matrix-free systems factorise none)."""

    def __init__(self, H, A, weights, s_load, d0, gap, law: PointLaw, factors: Factors | None = None,
                 plate: PlateRows | None = None, tolerance: float = 1e-10):
        self.H, self.A = H, A
        self.factors = Factors() if factors is None else factors
        self.reference = self.factors.reference
        self._setup(np.diag(H), weights, s_load, d0, gap, law, plate, tolerance)

    def _setup(self, compliance, weights, s_load, d0, gap, law, plate, tolerance):
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

    def response(self, directed, normal):
        """A directed + H normal: normal displacements under point forces along b_i and along ν (zeros skipped)."""
        out = self.A @ directed if directed.any() else np.zeros(self.n)
        return out + self.H @ normal if normal.any() else out

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

    def _solve(self, active, dp, rhs, lam):
        return sla.lu_solve(self._factor(active, dp), rhs, check_finite=False)

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


class KrylovSystem(CondensedSystem):
    """The condensed step problem, matrix-free: for contact surfaces too large for dense algebra.

    Products with H and A = H + μ F go through ``recycler.memory``
    (:class:`~ngwear.numerics.recycle.ComplianceMemory`: one back-substitution with K's factorisation
    for each input direction not seen before in the run); the Newton matrix M of
    :class:`CondensedSystem` is applied, never formed, and its systems are solved by GCR with
    recycling (:class:`~ngwear.numerics.recycle.Recycler`), the columns of active points scaled by
    their estimated stiffness 1/(m_i h_i), h_i ≤ H_ii (``compliance``), to an absolute residual of
    ``tolerance``/100 of the problem's length scale, so that Newton's merit test sees exact steps.  A body held by
    the plate alone first moves rigidly to its force balance (:meth:`start`).
    """

    def __init__(self, recycler, compliance, weights, s_load, d0, gap, law: PointLaw, tolerance: float,
                 plate: PlateRows | None = None):
        self.recycler = recycler
        self._setup(compliance, weights, s_load, d0, gap, law, plate, tolerance)

    def response(self, directed, normal):
        return self.recycler.memory(directed, normal)

    def start(self, x, lam):
        """The warm start moved rigidly along ν to the plate's force balance, for a body held by the plate alone.

        The balance of the translation's row needs no product (the plate's rows see the contact forces directly):
        from rest it is the solution with the body rigid, the patch of a soft layer to a few points; from the last
        step, the wear increment's motion.  Towards the foundation the move stops where the first points reach it
        (u_ν = d₀ + g), and their reactions λ take the force the layer does not carry: Newton starts with them active
        instead of sweeping a step's worth of the plate's force over the whole face.
        """
        if self.plate is None or not self.floating:
            return x, lam
        slope = self.plate.normal[:, 0]
        rigid = np.concatenate([slope, np.eye(len(x) - self.n)[0]])
        value = self._plate_rows(x, lam)[0]
        if value == 0:
            return x, lam
        toward = 1.0 if value < 0 else -1.0                                 # the row increases along the move
        balance = lambda t: self._plate_rows(x + toward * t * rigid, lam)[0]  # noqa: E731
        reach = np.inf
        if toward > 0:
            ahead = slope > 0
            reach = np.min(-self.gap(x)[ahead] / slope[ahead], initial=np.inf)
            if reach <= 0:
                return x, lam
        near, far = 0.0, min(1e-3 * self.scale, reach)                     # bracketed by doubling, then Brent
        while np.sign(balance(far)) == np.sign(value):
            if far >= reach:                                                # points at the foundation carry the rest
                x = x + reach * rigid
                touching = (self.gap(x) >= -1e-12 * self.scale) & (slope > 0)
                lam = lam.copy()
                lam[touching] += -balance(reach) / (self.m[touching] * slope[touching]).sum()
                return x, lam
            if far > 1e30:
                return x, lam
            near, far = far, min(2 * far, reach)
        return x + toward * spo.brentq(balance, near, far, xtol=1e-15 * self.scale) * rigid, lam

    def _solve(self, active, dp, rhs, lam):
        n, m = self.n, self.m
        scaling = np.ones(len(rhs))
        scaling[:n][active] = self.c[active]
        weights = (m * dp * ~active, m * active.astype(float))
        image = lambda u, response: self._image(active, u, weights[0] * u[:n], weights[1] * u[:n], response)  # noqa: E731
        return self.recycler.solve(active.tobytes() + dp.tobytes(), weights, image, scaling, rhs, self.atol)


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
