"""One time step's solve: the condensed contact problem (or the full system), its cut-backs, and the bulk iteration.

:class:`Stepper` builds the step's system from the discretization: dense (:class:`CondensedSystem`, the
Newton matrices kept while μ n* keeps its direction), matrix-free (:class:`PatchSystem` on the contact patch with
the compliance's columns kept for the run, or :class:`KrylovSystem` with the products remembered for the run) or the
full-system reference (:class:`FullSystem`).  For a body with a nonlinear law
(:mod:`ngwear.numerics.bulk`) each step iterates u = G(u): the contact problem with the load f − n(u), the
bulk recovered with one back-substitution, Anderson-mixed, warm-started from the previous step's u.
"""
from __future__ import annotations

import logging

import numpy as np

from ..numerics.bulk import Anderson, Remainder, change
from ..numerics.columns import Columns
from ..numerics.discrete import Discretization
from ..numerics.patch import PatchSystem
from ..numerics.recycle import ComplianceMemory, Recycler
from ..numerics.solver import (
    CondensedSystem,
    ConvergenceError,
    FullSystem,
    KrylovSystem,
    PlateRows,
    PointLaw,
    semismooth_newton,
)
from ..numerics.wear import WearIntegrator
from ..results.invariants import StepCheck

log = logging.getLogger(__name__)

BULK_ITERATIONS = 200
"""Most iterations of the bulk's fixed point in one step (each: one assembly of n(u), two back-substitutions)."""
CHORD = 2
"""Images with the operator a step starts with (the tangent the last step left) before Newton takes over."""
NEWTON = 12
"""Most Newton iterations (a factorised tangent each) before the step falls back on K₀ alone."""
RUNAWAY = 10.0
"""Iterates whose step |G(u) − u| exceeds the best one's this many times: the mixing restarts from the best."""
PATCH_SHARE = 0.9
"""Largest share of the contact points in the rigid body's patch for which ``auto`` solves on the patch (measured:
the patch 2–11× faster than GCR up to a share of 0.84, GCR 1.1–3.9× faster on pads pressed flat, share 1)."""


class Stepper:
    """Solves one step; on a Newton failure it retries from a load continuation (cut-back).

    The cut-back does not change the scheme: it solves the same step's problem (wear law, v*) at
    the loads s_F = s_prev + θ (s_F(t) − s_prev), θ = 1/m … 1, each warm-starting the next, with
    m = 2, 4, 8; s_prev is the previous step's load factor, or 0 (the unloaded state) at step 0.
    """

    CUTBACKS = (2, 4, 8)

    def __init__(self, disc: Discretization, check: StepCheck):
        self.disc, self.scene, self.check = disc, disc.scene, check
        self._matrices: dict = {}
        self._factors: dict = {}
        nonlinear = not disc.elastic.linear and not self._full     # the full path linearises the laws itself
        self.base = disc                                            # K₀: the laws' tangent at ε = 0
        self.remainder = Remainder(disc.elastic) if nonlinear else None
        self.history: list = []                                     # (t, u) of the last two steps: the warm start
        self._shift = None                                          # N K⁻¹ n(u), Dᵀ n(u) of the current iterate
        self._kept: dict = {}                                       # K₀'s Newton matrices while a tangent is used
        self.tangents = 0                                           # tangents taken so far (factorised or updated)
        self._columns: dict = {}                                    # K₀⁻¹Dᵀ of the kink points, for this run
        self._patch = None                                          # matrix-free: on the patch (else GCR), once

    @property
    def _full(self) -> bool:
        return self.scene.solver.method == "full"

    def unknowns(self) -> np.ndarray:
        """The unknowns at rest: s at the contact points (condensed) or the free DOFs (full), then δ."""
        disc = self.disc
        size = disc.condensation.full_basis.shape[1] if self._full else disc.points.n + disc.condensation.plate_modes_count
        return np.zeros(size)

    def normal(self, x):
        """The normal displacements s = ν·u at the contact points."""
        return self.disc.condensation.N @ (self.disc.condensation.full_basis @ x) if self._full else x[:self.disc.points.n]

    def plate(self, x):
        """δ, the plate's displacement (and tilts)."""
        return x[len(x) - self.disc.condensation.plate_modes_count:]

    def solve(self, t, t_prev, law, x, lam, integrator):
        """(x, λ, NewtonRecord) of the step ending at t; ConvergenceError when it cannot be solved.

        A nonlinear material: the fixed point u = G(u) of :mod:`ngwear.numerics.bulk`, from the last two steps' u
        extrapolated to t.  First at most :data:`CHORD` Anderson-mixed images with the operator the last step
        left (the laws' tangent at its solution, or K₀): where little changed between steps they meet the
        tolerance with no factorisation.  Else Newton: the laws' tangent at the iterate and its image,
        :data:`NEWTON` times at most (3–4 from rest for the compaction law at β = 100η).  A kinked law
        (:mod:`ngwear.numerics.kink`) takes a new tangent only when a point's branch differs from the operator's,
        then CHORD images with it; that tangent is a low-rank update of the last factorisation when few points
        flipped (:class:`~ngwear.numerics.condense.UpdatedOperator`).  Should Newton not converge, Anderson-mixed
        images with K₀, with which the compaction law's iteration contracts (K₀ is its stiffest tangent), spend
        the rest of :data:`BULK_ITERATIONS`.
        """
        if self.remainder is None:
            return self._contact(t, t_prev, law, x, lam, integrator)
        state, tolerance = {"x": x, "lam": lam, "newton": 0, "count": 0}, self.scene.solver.tolerance
        u, gap = self._predicted(t), np.inf
        for newton in range(NEWTON + 1):
            flips = self.disc.elastic.flips(u)
            if (flips is None and newton > 0) or flips:
                shared = self.disc.elastic.root is self.base.elastic      # K₀ may serve other runs: a cache of this run
                self._use(self.disc.tangent(u, self._columns if shared else None))
                self.tangents += 1
            most = 1 if flips is None and newton > 0 else CHORD
            u, gap = self._iterate(u, t, t_prev, law, integrator, state, tolerance, most)
            if gap <= tolerance or gap == np.inf or state["count"] >= BULK_ITERATIONS:
                break
        if gap > tolerance:
            self._use(self.base)
            u, gap = self._iterate(u, t, t_prev, law, integrator, state, tolerance, BULK_ITERATIONS)
        record = state["record"]
        record.bulk, record.iterations, record.tangents = state["count"], state["newton"], self.tangents
        if gap > tolerance:
            raise ConvergenceError(f"the bulk iteration of the nonlinear material did not converge in "
                                   f"{state['count']} iterations (change {gap:.1e})", record)
        self.history = [(t, u), *self.history[:1]]
        return state["x"], state["lam"], record

    def displacement(self, x) -> np.ndarray | None:
        """The displacement of the step just solved when the body is nonlinear (None for a linear one: recovered)."""
        if self.remainder is not None:
            return self.history[0][1]
        return self.disc.condensation.full_basis @ x if self._full and not self.disc.elastic.linear else None

    def _predicted(self, t: float) -> np.ndarray:
        """The displacement at t extrapolated linearly from the last two steps (the last step's when there is one)."""
        if len(self.history) < 2:
            return self.history[0][1] if self.history else np.zeros(self.disc.fes.ndof)
        (t1, u1), (t0, u0) = self.history
        return u1 + (t - t1) / (t1 - t0) * (u1 - u0) if t1 > t0 else u1

    def _iterate(self, u, t, t_prev, law, integrator, state, tolerance, most: int) -> tuple[np.ndarray, float]:
        """(The best image, its change) of at most ``most`` Anderson-mixed images from u with the current K.

        It stops when the change meets the tolerance or the step's iterations are spent; when the step
        |G(u) − u| grows to :data:`RUNAWAY` times the best, or the best has not halved in as many images as the
        mixing remembers (a stalled history), the mixing starts afresh from the best image.
        """
        mixing, best, since = Anderson(), (np.inf, np.inf, u), 0     # best: (|G(u) − u|, its change, G(u))
        for _ in range(min(most, BULK_ITERATIONS - state["count"])):
            image = self._safe_image(u, t, t_prev, law, integrator, state)
            step = np.inf if image is None else float(np.abs(image - u).max(initial=0.0))
            since = 0 if step < 0.5 * best[0] else since + 1
            if step < best[0]:
                best = step, change(u, image), image
            if best[1] <= tolerance or best[0] == np.inf:
                break
            if step > RUNAWAY * best[0] or since > mixing.memory:
                mixing, u, since = Anderson(), best[2], 0
            else:
                u = mixing(u, image)
        return best[2], best[1]

    def _safe_image(self, u, t, t_prev, law, integrator, state) -> np.ndarray | None:
        """G(u), or None when the contact problem of this iterate fails or its image is not finite."""
        try:
            image = self._image(u, t, t_prev, law, integrator, state)
        except (ConvergenceError, ArithmeticError):
            return None
        finally:
            state["count"] += 1
        return image if np.isfinite(image).all() else None

    def _image(self, u, t, t_prev, law, integrator, state) -> np.ndarray:
        """G(u): the contact problem under f − n(u), then u = K⁻¹(f − n(u) − Pᵀ f_c) + D δ (``state``: x, λ, record)."""
        disc, cond = self.disc, self.disc.condensation
        n = self.remainder(u)
        response = disc.elastic.operator.solve(n)
        self._shift = cond.N @ response, np.zeros(0) if cond.plate is None else cond.plate.response.T @ n
        state["x"], state["lam"], state["record"] = self._contact(t, t_prev, law, state["x"], state["lam"], integrator)
        state["newton"] += state["record"].iterations
        forces = disc.contact_forces(law.pressure(self.normal(state["x"]) - cond.d0), state["lam"], t)
        return disc.recover(forces, t, self.plate(state["x"]), nonlinear=False) - response

    def _use(self, disc: Discretization) -> None:
        """Solve on with the operator K of ``disc`` (its factorisation, condensation and loads, built when new)."""
        if disc is self.disc:
            return
        for _, build in disc.stages():
            build()
        if self.disc is self.base:      # K₀ is kept for the fall-back; a tangent replaced is dropped (its factor freed)
            self._kept[id(self.disc)] = self.disc, self._matrices, self._factors
        self.disc = disc
        _, self._matrices, self._factors = self._kept.pop(id(disc), (disc, {}, {}))
        self.remainder = Remainder(disc.elastic)

    def _contact(self, t, t_prev, law, x, lam, integrator):
        """The contact problem of the step (with the bulk's current load shift), cut back when Newton fails."""
        target = self.disc.load_factor(t)
        try:
            return self._newton(t, target, law, x, lam, integrator)
        except ConvergenceError as first:
            start = 0.0 if t_prev is None else self.disc.load_factor(t_prev)
            if t_prev is None:
                x, lam = np.zeros_like(x), np.zeros_like(lam)
            for tried, m in enumerate(self.CUTBACKS, start=1):
                try:
                    xs, ls = x, lam
                    for theta in np.arange(1, m + 1) / m:
                        xs, ls, record = self._newton(t, start + theta * (target - start), law, xs, ls,
                                                      integrator)
                    log.info("t = %.4g: converged after cutting the load step into %d", t, m)
                    record.cutbacks = tried
                    return xs, ls, record
                except ConvergenceError:
                    continue
            first.record.cutbacks = len(self.CUTBACKS)
            raise first

    def _newton(self, t, load_factor, law, x, lam, integrator):
        sc = self.scene.solver
        system = self._system(t, load_factor, law, integrator)
        return semismooth_newton(system, x, lam, sc.tolerance, sc.max_iterations)

    def _system(self, t, load_factor, law, integrator):
        disc, cond = self.disc, self.disc.condensation
        if self._full:
            return _full_system(disc, t, load_factor, integrator)
        friction = disc.friction_directions(t)                              # μ_i n*_i
        if disc.matrix_free:
            if self._patch is None:
                self._patch = disc.contact_solve == "patch" or (
                    disc.contact_solve == "auto" and patch_share(disc) <= PATCH_SHARE)
            directions = cond.nu[None, :] + friction                         # A's force directions ν + μ n*
            key = ("patch" if self._patch else "krylov", directions.tobytes())
            if key not in self._matrices:
                before = next(iter(self._matrices.values()), None)
                self._matrices = {key: _columns(disc, friction, before) if self._patch else _recycler(disc, friction)}
                self._factors = {}
            directed = None if cond.plate is None else cond.plate.directed(directions)
            s_load, plate = self._loads(directed, load_factor)
            if self._patch:
                return PatchSystem(self._matrices[key], cond.compliance_estimate, disc.points.weights, s_load, cond.d0,
                                   self.scene.contact.gap, law, self._factors, plate)
            return KrylovSystem(self._matrices[key], cond.compliance_estimate, disc.points.weights, s_load, cond.d0,
                                self.scene.contact.gap, law, self.scene.solver.tolerance, plate)
        key = friction.tobytes()
        if key not in self._matrices:
            H = cond.normal_compliance
            A = H + cond.friction_compliance(friction) if friction.any() else H
            directed = None if cond.plate is None else cond.plate.directed(cond.nu[None, :] + friction)
            self._matrices = {key: (A, directed)}
            self._factors = {}
        A, directed = self._matrices[key]
        s_load, plate = self._loads(directed, load_factor)
        return CondensedSystem(cond.normal_compliance, A, disc.points.weights, s_load, cond.d0,
                               self.scene.contact.gap, law, self._factors, plate)

    def _loads(self, directed, load_factor: float):
        """The normal displacements under the loads, s_F N K⁻¹ f, and the plate's rows, less the bulk's shift."""
        disc = self.disc
        s_load = load_factor * disc.loads.s_load
        plate = _plate_rows(disc, directed, load_factor)
        if self._shift is not None:
            s_load = s_load - self._shift[0]
            if plate is not None:
                plate = PlateRows(plate.normal, plate.directed, plate.stiffness, plate.load - self._shift[1])
        return s_load, plate


def _recycler(disc: Discretization, friction) -> Recycler:
    """The products with A = H + F(μ n*) (this μ n*) and H remembered for the run, and the Newton basis built on them."""
    directions = disc.condensation.nu[None, :] + friction
    respond = lambda directed, normal: disc.normal_response(normal, directed, directions)  # noqa: E731
    return Recycler(ComplianceMemory(respond, disc.points.n))


def _columns(disc: Discretization, friction, before) -> Columns:
    """The columns of A = H + F(μ n*) (this μ n*) and H for the run; H's are kept from ``before`` (other μ n*)."""
    directions = disc.condensation.nu[None, :] + friction
    respond = lambda directed, normal: disc.normal_response(normal, directed, directions)  # noqa: E731
    normal = before.normal if isinstance(before, Columns) else None
    return Columns(respond, disc.points.n, normal, same=not friction.any())


def patch_share(disc: Discretization) -> float:
    """The share of the contact points in the rigid body's contact patch under the largest load.

    The body moved rigidly to the plate's force balance (:meth:`PatchSystem.start`; held otherwise: the loads'
    displacement s_F): a soft layer's patch to a few points, and whether it is a part of Γ_C or all of it.  ``auto``
    solves on the patch up to ``PATCH_SHARE``.
    """
    cond, n = disc.condensation, disc.points.n
    largest = max((abs(f) for _, f in disc.scene.loads.time_table), default=1.0)
    directed = None if cond.plate is None else cond.plate.directed(cond.nu[None, :] + disc.friction_directions(0.0))
    system = PatchSystem(None, cond.compliance_estimate, disc.points.weights, largest * disc.loads.s_load, cond.d0,
                         disc.scene.contact.gap, PointLaw(disc.law, disc.law.derivative), {},
                         _plate_rows(disc, directed, largest))
    x, _ = system.start(np.concatenate([system.s_load, np.zeros(cond.plate_modes_count)]), np.zeros(n))
    return np.count_nonzero(disc.law.derivative(x[:n] - cond.d0)) / max(n, 1)


def _plate_rows(disc: Discretization, directed, load_factor: float) -> PlateRows | None:
    """The plate's rows of a step (None without a plate), ``directed`` = b_i·Φ_i for this step's force directions."""
    plate = disc.condensation.plate
    return None if plate is None else PlateRows(plate.normal, directed, plate.stiffness,
                                                load_factor * disc.loads.plate_load)


def _full_system(disc: Discretization, t: float, load_factor: float, integrator: WearIntegrator) -> FullSystem:
    """The reference system: NGSolve form with w, μ, n* of this step (explicit wear: w = a, see the scene's rules)."""
    cf, cond = disc.full_form, disc.condensation
    disc.set_nodal(cf.w, integrator.a)
    for gf, component in zip(cf.friction, disc.friction_directions(t).T):
        disc.set_nodal(gf, component)
    load = cond.full_basis.T @ disc.loads.load
    load[len(load) - cond.plate_modes_count:] += disc.loads.plate_force
    floating = cond.plate_modes_count and not disc.scene.geometry.dirichlet
    return FullSystem(cf, cond.full_basis, load_factor * load, cond.N, disc.points.weights, cond.d0,
                      disc.scene.contact.gap, disc.elastic.stiffness, integrator.point_law(),
                      cond.rigid_translation if floating else None)


