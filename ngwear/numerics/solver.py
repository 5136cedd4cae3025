"""Semismooth Newton with a projection (primal–dual active set) for one time step.

Each step solves, for the normal displacements s_i = ν·u(x_i) at the contact points and the
reactions λ_i of the rigid foundation,

    R(x, λ) = 0,   s − d₀ − g ≤ 0,   λ ≥ 0,   λ·(s − d₀ − g) = 0,

with the complementarity written as C(x, λ) = λ − max(0, λ + c (s − d₀ − g)) = 0.  The active set
A = {i : λ_i + c_i (s_i − d₀,i − g) > 0} is fixed at s_i = d₀,i + g and λ_i = 0 off A; the Newton
matrix K + R'(u) is non-symmetric when μ > 0.  Steps are damped by backtracking on the merit
max(|R|, |min(λ/c, g + d₀ − s)|).  Two systems implement the same protocol:

* :class:`CondensedSystem`: unknown x = s (n contact points); R = s − s_F + A (m∘p) + H (m∘λ) with
  H = ν·G·ν, A = H + (ν·G·n*) diag(μ), G = P K⁻¹ Pᵀ the point compliance (dense, small).
* :class:`FullSystem`: unknown x = u (all free DOFs); R = K u + R_c(u) + (N P)ᵀ(m∘λ) − F assembled by
  NGSolve (``Apply`` / ``AssembleLinearization``) and solved as a sparse saddle-point system.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import ngsolve as ngs
import numpy as np
import scipy.linalg as sla
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
    """History of one step's Newton solve."""

    converged: bool = False
    iterations: int = 0
    residuals: list[float] = field(default_factory=list)
    active: int = 0
    damped: int = 0


MEMORY = 5
UNDAMPED = 20


def semismooth_newton(system, x, lam, tol: float = 1e-10, max_iterations: int = 50):
    """Solve ``system`` from the warm start (x, λ); returns (x, λ, NewtonRecord).

    First the pure semismooth Newton iteration (full steps: for a piecewise-linear law it ends in
    finitely many steps, however stiff), for at most ``UNDAMPED`` iterations; if that does not
    converge, a damped restart from the warm start with a non-monotone line search
    (Grippo–Lampariello–Lucidi): a step is accepted when the merit drops below the largest of the
    last ``MEMORY`` merits; halving stops at θ = 1/1024.  Iterations of both phases count.
    """
    rec = NewtonRecord()
    start = (x, lam)
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


@dataclass
class PointLaw:
    """Nodal contact law at one step: pressure p(z) and dp/dz as functions of z = s − d₀."""

    pressure: callable
    derivative: callable


class CondensedSystem:
    """The step problem condensed onto the n contact points (dense n × n algebra).

    ``factors`` caches LU factorisations of the Newton matrix by (active set, p'): with a
    piecewise-linear law the matrix repeats across iterations and steps and is factorised once.
    """

    def __init__(self, H, A, weights, s_load, d0, gap, law: PointLaw, factors: dict | None = None):
        self.H, self.A, self.m = H, A, weights
        self.s_load, self.d0, self.g, self.law = s_load, d0, gap, law
        diag = np.maximum(np.diag(H) * weights, 1e-300)
        self.c = 1.0 / diag
        self.scale = max(np.abs(s_load).max(initial=0.0), gap)
        self.factors = {} if factors is None else factors

    def gap(self, s):
        return s - self.d0 - self.g

    def residual(self, s, lam):
        p = self.law.pressure(s - self.d0)
        return s - self.s_load + self.A @ (self.m * p) + self.H @ (self.m * lam)

    def merit(self, s, lam):
        comp = np.minimum(lam / self.c, -self.gap(s))
        return max(np.abs(self.residual(s, lam)).max(initial=0), np.abs(comp).max(initial=0)) / self.scale

    def _factor(self, active, dp):
        """LU of M = [J_{:,I} | H_{:,A} diag(m_A)] with J = I + A diag(m p')."""
        key = active.tobytes() + dp.tobytes()
        if key not in self.factors:
            inactive = ~active
            M = self.A * (self.m * dp * inactive)[None, :] + self.H * (self.m * active)[None, :]
            M[np.diag_indices(len(dp))] += inactive
            if len(self.factors) >= 16:
                self.factors.clear()
            self.factors[key] = sla.lu_factor(M, check_finite=False)
        return self.factors[key]

    def step(self, s, lam, active):
        dp = self.law.derivative(s - self.d0)
        ds = np.zeros(len(s))
        ds[active] = -self.gap(s)[active]
        rhs = -self.residual(s, lam) + self.H @ (self.m * lam) - ds - self.A @ (self.m * dp * ds)
        sol = sla.lu_solve(self._factor(active, dp), rhs, check_finite=False)
        lam_new = np.where(active, sol, 0.0)
        ds[~active] = sol[~active]
        return ds, lam_new


class FullSystem:
    """The step problem on all free DOFs, linearised by NGSolve at every iteration (reference path)."""

    def __init__(self, contact_form, load, free, N, weights, d0, gap, stiffness_diag):
        self.cf, self.load = contact_form, load
        self.free = np.flatnonzero(free)
        self.N = N[:, self.free].tocsr()  # normal evaluation at the points, free columns
        self.m, self.d0, self.g = weights, d0, gap
        self._gf = ngs.GridFunction(contact_form.form.space)
        self._res = self._gf.vec.CreateVector()
        self.scale = max(np.abs(load[self.free]).max(initial=0.0), 1e-300)
        local_stiffness = (self.N.multiply(self.N) @ stiffness_diag[self.free]) / weights
        self.c = np.maximum(local_stiffness, 1e-300)
        self._gscale = max(gap, 1e-300)

    def _set(self, x):
        vec = self._gf.vec.FV().NumPy()
        vec[:] = 0.0
        vec[self.free] = x

    def gap(self, x):
        return self.N @ x - self.d0 - self.g

    def residual(self, x, lam):
        self._set(x)
        self.cf.form.Apply(self._gf.vec, self._res)
        r = self._res.FV().NumPy()[self.free] - self.load[self.free]
        return r + self.N.T @ (self.m * lam)

    def merit(self, x, lam):
        comp = np.minimum(lam / self.c, -self.gap(x))
        return max(np.abs(self.residual(x, lam)).max(initial=0) / self.scale,
                   np.abs(comp).max(initial=0) / self._gscale)

    def step(self, x, lam, active):
        self._set(x)
        self.cf.form.AssembleLinearization(self._gf.vec)
        vals, cols, ptr = self.cf.form.mat.CSR()
        n_all = len(self._gf.vec)
        J = sp.csr_matrix((np.array(vals), np.array(cols), np.array(ptr)), shape=(n_all, n_all))
        J = J[self.free][:, self.free]
        B = self.N[active]
        rhs_u = -self.residual(x, lam) + self.N.T @ (self.m * lam)
        rhs_g = -self.gap(x)[active]
        K = sp.bmat([[J, B.T.multiply(self.m[active][None, :])], [B, None]], format="csc")
        sol = spla.spsolve(K, np.concatenate([rhs_u, rhs_g]))
        nf = len(self.free)
        lam_new = np.zeros(len(lam))
        lam_new[active] = sol[nf:]
        return sol[:nf], lam_new
