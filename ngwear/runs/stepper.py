"""One time step's solve: the contact problem (condensed or full), its cut-backs, and a nonlinear body's bulk iteration.

:class:`Stepper` solves a :class:`Step` on a :class:`~ngwear.numerics.problem.Problem` (the step's unknowns and its
Newton system, dense, matrix-free or the full-system reference).  For a body with a nonlinear law
(:mod:`ngwear.numerics.bulk`) each step iterates u = G(u): the contact problem with the load f − n(u), the bulk
recovered with one back-substitution, Anderson-mixed (:func:`~ngwear.numerics.bulk.fixed_point`), warm-started from
the previous step's u.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from ..numerics.bulk import fixed_point
from ..numerics.problem import Problem
from ..numerics.solver import ConvergenceError, NewtonRecord, PointLaw, semismooth_newton
from ..numerics.wear import WearIntegrator
from ..results.invariants import StepCheck
from ..results.validity import Validity

log = logging.getLogger(__name__)

BULK_ITERATIONS = 200
"""Most iterations of the bulk's fixed point in one step (each: one assembly of n(u), two back-substitutions)."""
CHORD = 2
"""Images with the operator a step starts with (the tangent the last step left) before Newton takes over."""
NEWTON = 12
"""Most Newton iterations (a factorised tangent each) before the step falls back on K₀ alone."""


@dataclass
class Step:
    """The step to solve: it ends at ``t``, the last one at ``t_prev`` (None at step 0).

    Its wear law, prepared in ``integrator``, is folded into the compliance: ``law``, the nodal law p_j the solver sees.
    """

    t: float
    t_prev: float | None
    integrator: WearIntegrator
    law: PointLaw = field(init=False)

    def __post_init__(self):
        self.law = self.integrator.point_law()


@dataclass
class Bulk:
    """A nonlinear body's step so far: the contact solution (x, λ) and record of the last image, and the counts."""

    x: np.ndarray
    lam: np.ndarray
    record: NewtonRecord | None = None
    newton: int = 0         # Newton iterations of the contact solves
    images: int = 0         # images G(u) evaluated


class Stepper:
    """Solves one step; on a Newton failure it retries from a load continuation (cut-back).

    The cut-back does not change the scheme: it solves the same step's problem (wear law, v*) at
    the loads s_F = s_prev + θ (s_F(t) − s_prev), θ = 1/m … 1, each warm-starting the next, with
    m = 2, 4, 8; s_prev is the previous step's load factor, or 0 (the unloaded state) at step 0.
    """

    CUTBACKS = (2, 4, 8)

    def __init__(self, problem: Problem, check: StepCheck, validity: Validity):
        self.problem, self.scene, self.check, self.validity = problem, problem.scene, check, validity
        self.base = problem                                         # K₀: the laws' tangent at ε = 0
        nonlinear = not problem.linear and not problem.full        # the full path linearises the laws itself
        self.remainder = problem.remainder() if nonlinear else None
        self.history: list = []                                     # (t, u) of the last two steps: the warm start
        self.tangents = 0                                           # tangents taken so far (factorised or updated)
        self._columns: dict = {}                                    # K₀⁻¹Dᵀ of the kink points, for this run
        self.heating = None                                         # the run's Heating (:mod:`ngwear.runs.heating`)

    def unknowns(self) -> np.ndarray:
        """The unknowns at rest (see :meth:`Problem.unknowns`)."""
        return self.problem.unknowns()

    def solve(self, step: Step, x, lam):
        """(x, λ, NewtonRecord) of the step; ConvergenceError when it cannot be solved.

        A nonlinear material: the fixed point u = G(u) of :mod:`ngwear.numerics.bulk`, from the last two steps' u
        extrapolated to t.  First at most :data:`CHORD` Anderson-mixed images with the operator the last step
        left (the laws' tangent at its solution, or K₀): where little changed between steps they meet the
        tolerance with no factorisation.  Else Newton: the laws' tangent at the iterate and its image,
        :data:`NEWTON` times at most (3–4 from rest for the compaction law at β = 100η).  A kinked law
        (:mod:`ngwear.numerics.kink`) takes a new tangent only when a point's branch differs from the operator's,
        then CHORD images with it; that tangent is a low-rank update of the last factorisation when few points
        flipped (:class:`~ngwear.numerics.operators.UpdatedOperator`).  Should Newton not converge, Anderson-mixed
        images with K₀, with which the compaction law's iteration contracts (K₀ is its stiffest tangent), spend
        the rest of :data:`BULK_ITERATIONS`.
        """
        if self.remainder is None:
            return self._contact(step, x, lam)
        bulk, tolerance = Bulk(x, lam), self.scene.solver.tolerance
        u, gap = self._predicted(step.t), np.inf
        for newton in range(NEWTON + 1):
            flips = self.problem.flips(u)
            if (flips is None and newton > 0) or flips:
                shared = self.problem.root is self.base.root    # K₀ may serve other runs: a cache of this run
                self._use(self.problem.tangent(u, self._columns if shared else None))
                self.tangents += 1
            most = 1 if flips is None and newton > 0 else CHORD
            u, gap = self._iterate(u, step, bulk, most)
            if gap <= tolerance or gap == np.inf or bulk.images >= BULK_ITERATIONS:
                break
        if gap > tolerance:
            self._use(self.base)
            u, gap = self._iterate(u, step, bulk, BULK_ITERATIONS)
        record = bulk.record
        record.bulk, record.iterations, record.tangents = bulk.images, bulk.newton, self.tangents
        if gap > tolerance:
            raise ConvergenceError(f"the bulk iteration of the nonlinear material did not converge in "
                                   f"{bulk.images} iterations (change {gap:.1e})", record)
        self.history = [(step.t, u), *self.history[:1]]
        return bulk.x, bulk.lam, record

    def expand(self, load: np.ndarray) -> None:
        """Solve the next steps under the thermal load f_th = ``load`` too (:meth:`Problem.expand`; K₀'s and K's)."""
        for problem in {id(p): p for p in (self.problem, self.base)}.values():
            problem.expand(load)

    def displacement(self, x) -> np.ndarray | None:
        """The displacement of the step just solved when the body is nonlinear (None for a linear one: recovered)."""
        if self.remainder is not None:
            return self.history[0][1]
        return self.problem.displacement(x) if self.problem.full and not self.problem.linear else None

    def _predicted(self, t: float) -> np.ndarray:
        """The displacement at t extrapolated linearly from the last two steps (the last step's when there is one)."""
        if len(self.history) < 2:
            return self.history[0][1] if self.history else np.zeros(self.problem.disc.fes.ndof)
        (t1, u1), (t0, u0) = self.history
        return u1 + (t - t1) / (t1 - t0) * (u1 - u0) if t1 > t0 else u1

    def _iterate(self, u, step: Step, bulk: Bulk, most: int) -> tuple[np.ndarray, float]:
        """(The best image, its change) of at most ``most`` images from u with the current K (and the step's rest)."""
        return fixed_point(lambda v: self._safe_image(v, step, bulk), u, self.scene.solver.tolerance,
                           min(most, BULK_ITERATIONS - bulk.images))

    def _safe_image(self, u, step: Step, bulk: Bulk) -> np.ndarray | None:
        """G(u), or None when the contact problem of this iterate fails or its image is not finite."""
        try:
            image = self._image(u, step, bulk)
        except (ConvergenceError, ArithmeticError):
            return None
        finally:
            bulk.images += 1
        return image if np.isfinite(image).all() else None

    def _image(self, u, step: Step, bulk: Bulk) -> np.ndarray:
        """G(u): the contact problem under f − n(u), then u = K⁻¹(f − n(u) − Pᵀ f_c) + D δ."""
        problem = self.problem
        response = problem.shift(self.remainder(u))
        bulk.x, bulk.lam, bulk.record = self._contact(step, bulk.x, bulk.lam)
        bulk.newton += bulk.record.iterations
        forces = problem.contact.forces(step.law.pressure(problem.normal(bulk.x) - problem.d0), bulk.lam, step.t)
        return problem.recover(forces, step.t, problem.plate(bulk.x)) - response

    def _use(self, problem: Problem) -> None:
        """Solve on with the operator K of ``problem`` (K₀'s, kept for the fall-back, or a tangent's, dropped after)."""
        if problem is not self.problem:
            self.problem, self.remainder = problem, problem.remainder()

    def _contact(self, step: Step, x, lam):
        """The contact problem of the step (with the bulk's current load shift), cut back when Newton fails."""
        load_factor = self.problem.contact.load_factor
        target = load_factor(step.t)
        try:
            return self._newton(step, target, x, lam)
        except ConvergenceError as first:
            start = 0.0 if step.t_prev is None else load_factor(step.t_prev)
            if step.t_prev is None:
                x, lam = np.zeros_like(x), np.zeros_like(lam)
            for tried, m in enumerate(self.CUTBACKS, start=1):
                try:
                    xs, ls = x, lam
                    for theta in np.arange(1, m + 1) / m:
                        xs, ls, record = self._newton(step, start + theta * (target - start), xs, ls)
                    log.info("t = %.4g: converged after cutting the load step into %d", step.t, m)
                    record.cutbacks = tried
                    return xs, ls, record
                except ConvergenceError:
                    continue
            first.record.cutbacks = len(self.CUTBACKS)
            raise first

    def _newton(self, step: Step, load_factor: float, x, lam):
        sc = self.scene.solver
        system = self.problem.system(step.t, load_factor, step.law, step.integrator)
        return semismooth_newton(system, x, lam, sc.tolerance, sc.max_iterations)
