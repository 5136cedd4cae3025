"""One time step: (discretization, caches, state, target) → (new state, Newton record), and the state it reads.

A run's changing state is one :class:`State`: what its next step reads and what its last step wrote.  The time loop
(:mod:`ngwear.runs.loop`) holds it; :func:`advance` makes the next one from it and a :class:`Target` (where the step
ends and its wear law, from the clock), and the loop's observers read it: the recording and the checks, the heat
(which sets the temperatures and the coefficients of the next step), the geometry updates (which move the layer's wear
into the body: the record keeps the total) and the checkpoints.  Everything else a run uses is either fixed for the
run (the scene, the :class:`~ngwear.numerics.discrete.Discretization`) or a cache (:class:`StepCaches`).

:func:`advance` solves the contact problem of the step that ends at ``target.instant`` with its wear law folded into
the compliance (:class:`~ngwear.numerics.wear.WearStep`), on the Newton system of :mod:`ngwear.numerics.systems`
(dense, matrix-free or the full-system reference), from the last step's unknowns, and returns the new state: s = ν·u,
p, λ, w, δ and the contact forces at the contact points.  A Newton failure
is retried from a load continuation (cut-back).  For a body with a nonlinear law (:mod:`ngwear.numerics.fixed_point`) each
step iterates u = G(u): the contact problem with the load f − n(u), the bulk recovered with one back-substitution,
Anderson-mixed (:func:`~ngwear.numerics.fixed_point.fixed_point`), warm-started from the last two steps' u.

The cut-back does not change the scheme: it solves the same step's problem (wear law, v*) at the loads
s_F = s_prev + θ (s_F(t) − s_prev), θ = 1/m … 1, each warm-starting the next, with m = 2, 4, 8; s_prev is the
last step's load factor, or 0 (the unloaded state) at step 0.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field, replace

import numpy as np

from ..model.coefficients import Coefficients
from ..numerics import systems
from ..numerics.contact import Instant
from ..numerics.fixed_point import Remainder, fixed_point
from ..numerics.systems import Caches, Drive
from ..numerics.systems.newton import ConvergenceError, NewtonRecord, semismooth_newton
from ..numerics.wear import WearStep

log = logging.getLogger(__name__)

BULK_ITERATIONS = 200
"""Most iterations of the bulk's fixed point in one step (each: one assembly of n(u), two back-substitutions)."""
CHORD = 2
"""Images with the operator a step starts with (the tangent the last step left) before Newton takes over."""
NEWTON = 12
"""Most Newton iterations (a factorised tangent each) before the step falls back on K₀ alone."""
CUTBACKS = (2, 4, 8)
"""The load continuations a failed step tries, each cutting its load change into m parts."""


@dataclass(frozen=True)
class Target:
    """Where the next step ends and what it solves: its instant and its wear law, from the clock.

    ``still``: the step slides nothing (a programme's crossing of a dwell: no wear, no frictional heat); ``jumped``:
    the stops a cycle jump applies on it; ``heat_steps``: the heat's backward-Euler steps over it; ``unloaded``: the
    step ends unloaded and at rest (a programme's last dwell), the unloaded body u = 0, p = λ = 0, without a solve.
    """

    instant: Instant
    wear: WearStep
    still: bool = False
    jumped: int = 0
    heat_steps: tuple[float, ...] = ()
    unloaded: bool = False


@dataclass
class State:
    """The state after a run's last recorded step (before step 0: the unloaded body).

    Attributes
    ----------
    instant : Instant or None
        t, s_v and s_F of the last step (None before step 0).
    x, lam : ndarray
        The solver's unknowns (s and δ, or the free DOFs) and multipliers λ: the next step's warm start.
    normal, pressure, wear, plate, forces : ndarray
        s = ν·u, p, w (the layer's), δ and the contact forces of the last step.
    coefficients : Coefficients
        μ, κ, L at the points for the next step: fields of x, or of the last step's state (:mod:`ngwear.runs.heating`).
    reference : ndarray or None
        With μ of the state, the reference μ whose dense factors precondition the steps'.
    displacements : tuple
        (t, u) of a nonlinear body's last two steps (the bulk's warm start); ``displacement`` the last step's u where
        it is not recovered from the contact forces (a nonlinear body), else None.
    record : NewtonRecord or None
        The last step's.
    steps : int
        The index of the last recorded step (−1: none).
    """

    x: np.ndarray
    lam: np.ndarray
    coefficients: Coefficients
    wear: np.ndarray
    instant: Instant | None = None
    normal: np.ndarray | None = None
    pressure: np.ndarray | None = None
    plate: np.ndarray | None = None
    forces: np.ndarray | None = None
    reference: np.ndarray | None = None
    displacements: tuple = ()
    displacement: np.ndarray | None = None
    record: NewtonRecord | None = None
    steps: int = -1


@dataclass
class Operator:
    """The operator K a step solves with and its run's caches: K₀'s (the discretization's) or a tangent's."""

    disc: object
    caches: Caches = field(default_factory=Caches)

    @property
    def remainder(self) -> Remainder:
        """n(u) = F(u) − K u with this K."""
        return Remainder(self.disc.elastic)


@dataclass
class StepCaches:
    """What a run keeps between its steps: K₀ with its caches, the operator in use, the kink's columns.

    ``current`` is K₀ (``base``) or, for a nonlinear body, the laws' tangent at a recent state (its own caches);
    ``columns``: K₀⁻¹Dᵀ of the kink points for this run (a tangent that updates K₀'s factorisation reuses them).
    """

    base: Operator
    current: Operator
    columns: dict = field(default_factory=dict)

    @classmethod
    def on(cls, disc) -> StepCaches:
        """Empty caches on ``disc``'s K₀."""
        base = Operator(disc)
        return cls(base, base)

    def expand(self, load: np.ndarray) -> None:
        """Solve the next steps under the thermal load f_th = ``load`` too (K₀'s and the tangent's)."""
        for operator in {id(o): o for o in (self.current, self.base)}.values():
            systems.expand(operator.disc, operator.caches, load)


def nonlinear(disc) -> bool:
    """Whether a step iterates the bulk (a nonlinear law on the condensed path; the full path linearises itself)."""
    return not disc.elastic.linear and not systems.full(disc)


def advance(disc, caches: StepCaches, state: State, target: Target) -> tuple[State, NewtonRecord]:
    """Solve the step to ``target`` from ``state``: the new state and its Newton record.

    Raises ConvergenceError (Newton, after its cut-backs) or ArithmeticError (a solution that is not finite).
    """
    instant = target.instant
    drive = Drive(instant.speed, instant.load, state.coefficients, state.reference, target.wear)
    previous = None if state.instant is None else state.instant.load
    if target.unloaded:                         # nothing pressed, nothing slides: no equation to solve
        x, lam, record = np.zeros_like(state.x), np.zeros_like(state.lam), NewtonRecord(converged=True)
        rest = None if state.displacement is None else np.zeros_like(state.displacement)
        displacements, shown = (() if rest is None or not nonlinear(disc) else
                                ((instant.t, rest), *state.displacements[:1])), rest
    elif nonlinear(disc):
        x, lam, record, u = _bulk(disc, caches, state, drive, previous, instant.t)
        displacements, shown = ((instant.t, u), *state.displacements[:1]), u
    else:
        x, lam, record = _contact(caches.current, drive, previous, state.x, state.lam)
        displacements = ()
        shown = systems.displacement(disc, x) if systems.full(disc) and not disc.elastic.linear else None
    d0 = disc.condensation.d0
    s, delta = systems.normal(disc, x), systems.plate(disc, x)
    pressure = drive.law.pressure(s - d0)
    if not all(np.all(np.isfinite(a)) for a in (s, lam, pressure, delta)):
        raise ArithmeticError(record)
    forces = disc.contact.forces(state.coefficients, pressure, lam, instant.speed)
    new = replace(state, instant=instant, x=x, lam=lam, normal=s, pressure=pressure, wear=target.wear.wear_at(s - d0),
                  plate=delta, forces=forces, record=record, displacements=displacements, displacement=shown,
                  steps=state.steps + 1)
    return new, record


def _contact(operator: Operator, drive: Drive, previous: float | None, x, lam):
    """The contact problem of the step (with the bulk's current load shift), cut back when Newton fails."""
    target = drive.load
    try:
        return _newton(operator, drive, target, x, lam)
    except ConvergenceError as first:
        start = 0.0 if previous is None else previous
        if previous is None:
            x, lam = np.zeros_like(x), np.zeros_like(lam)
        for tried, m in enumerate(CUTBACKS, start=1):
            try:
                xs, ls = x, lam
                for theta in np.arange(1, m + 1) / m:
                    xs, ls, record = _newton(operator, drive, start + theta * (target - start), xs, ls)
                log.info("converged after cutting the load step into %d", m)
                record.cutbacks = tried
                return xs, ls, record
            except ConvergenceError:
                continue
        first.record.cutbacks = len(CUTBACKS)
        raise first


def _newton(operator: Operator, drive: Drive, load_factor: float, x, lam):
    solver = operator.disc.scene.solver
    system = systems.system(operator.disc, operator.caches, drive, load_factor)
    return semismooth_newton(system, x, lam, solver.tolerance, solver.max_iterations)


@dataclass
class _Bulk:
    """A nonlinear body's step so far: the contact solution (x, λ) and record of the last image, and the counts."""

    x: np.ndarray
    lam: np.ndarray
    record: NewtonRecord | None = None
    newton: int = 0         # Newton iterations of the contact solves
    images: int = 0         # images G(u) evaluated


def _bulk(disc, caches: StepCaches, state: State, drive: Drive, previous, t: float):
    """(x, λ, NewtonRecord, u) of a nonlinear body's step; ConvergenceError when it cannot be solved.

    The fixed point u = G(u) of :mod:`ngwear.numerics.fixed_point`, from the last two steps' u extrapolated to t.  First at
    most :data:`CHORD` Anderson-mixed images with the operator the last step left (the laws' tangent at its solution,
    or K₀): where little changed between steps they meet the tolerance with no factorisation.  Else Newton: the laws'
    tangent at the iterate and its image, :data:`NEWTON` times at most (3–4 from rest for the compaction law at
    β = 100η).  A kinked law (:mod:`ngwear.numerics.kink`) takes a new tangent only when a point's branch differs
    from the operator's, then CHORD images with it; that tangent is a low-rank update of the last factorisation when
    few points flipped (:class:`~ngwear.numerics.operators.UpdatedOperator`).  Should Newton not converge,
    Anderson-mixed images with K₀, with which the compaction law's iteration contracts (K₀ is its stiffest tangent),
    spend the rest of :data:`BULK_ITERATIONS`.
    """
    bulk, tolerance = _Bulk(state.x, state.lam), disc.scene.solver.tolerance
    u, gap = _predicted(disc, state.displacements, t), np.inf
    tangents = state.record.tangents if state.record is not None else 0
    for newton in range(NEWTON + 1):
        flips = caches.current.disc.elastic.flips(u)
        if (flips is None and newton > 0) or flips:
            caches.current = _tangent(caches, u)
            tangents += 1
        most = 1 if flips is None and newton > 0 else CHORD
        u, gap = _iterate(caches, u, drive, previous, bulk, most)
        if gap <= tolerance or gap == np.inf or bulk.images >= BULK_ITERATIONS:
            break
    if gap > tolerance:
        caches.current = caches.base
        u, gap = _iterate(caches, u, drive, previous, bulk, BULK_ITERATIONS)
    record = bulk.record
    record.bulk, record.iterations, record.tangents = bulk.images, bulk.newton, tangents
    if gap > tolerance:
        raise ConvergenceError(f"the bulk iteration of the nonlinear material did not converge in "
                               f"{bulk.images} iterations (change {gap:.1e})", record)
    return bulk.x, bulk.lam, record, u


def _tangent(caches: StepCaches, u: np.ndarray) -> Operator:
    """The operator with K the laws' tangent at u (its pieces built: factorisation, condensation, loads)."""
    current = caches.current
    shared = current.disc.elastic.root is caches.base.disc.elastic.root    # K₀ may serve other runs: a run's cache
    disc = current.disc.tangent(u, caches.columns if shared else None)
    for _, build in disc.stages():
        build()
    tangent = Operator(disc, Caches(patch=current.caches.patch, thermal=current.caches.thermal))
    return tangent


def _predicted(disc, displacements: tuple, t: float) -> np.ndarray:
    """The displacement at t extrapolated linearly from the last two steps (the last step's when there is one)."""
    if len(displacements) < 2:
        return displacements[0][1] if displacements else np.zeros(disc.fes.ndof)
    (t1, u1), (t0, u0) = displacements
    return u1 + (t - t1) / (t1 - t0) * (u1 - u0) if t1 > t0 else u1


def _iterate(caches: StepCaches, u, drive: Drive, previous, bulk: _Bulk, most: int) -> tuple[np.ndarray, float]:
    """(The best image, its change) of at most ``most`` images from u with the current K (and the step's rest)."""
    tolerance = caches.base.disc.scene.solver.tolerance
    return fixed_point(lambda v: _safe_image(caches, v, drive, previous, bulk), u, tolerance,
                       min(most, BULK_ITERATIONS - bulk.images))


def _safe_image(caches: StepCaches, u, drive: Drive, previous, bulk: _Bulk) -> np.ndarray | None:
    """G(u), or None when the contact problem of this iterate fails or its image is not finite."""
    try:
        image = _image(caches.current, u, drive, previous, bulk)
    except (ConvergenceError, ArithmeticError):
        return None
    finally:
        bulk.images += 1
    return image if np.isfinite(image).all() else None


def _image(operator: Operator, u, drive: Drive, previous, bulk: _Bulk) -> np.ndarray:
    """G(u): the contact problem under f − n(u), then u = K⁻¹(f − n(u) − Pᵀ f_c) + D δ."""
    disc = operator.disc
    response = systems.shift(disc, operator.caches, operator.remainder(u))
    bulk.x, bulk.lam, bulk.record = _contact(operator, drive, previous, bulk.x, bulk.lam)
    bulk.newton += bulk.record.iterations
    pressure = drive.law.pressure(systems.normal(disc, bulk.x) - disc.condensation.d0)
    forces = disc.contact.forces(drive.coefficients, pressure, bulk.lam, drive.speed)
    return disc.recover(forces, drive.load, systems.plate(disc, bulk.x), nonlinear=False) - response
