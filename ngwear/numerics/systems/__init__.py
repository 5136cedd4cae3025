"""A step's Newton system on a discretization: its unknowns, and the system built from the pieces and a run's caches.

The unknowns x are the normal displacements s_i at the contact points and the plate's δ (condensed), or the free
DOFs and δ (the full-system reference).  :func:`system` builds a step's system from the discretization's pieces, one
of the classes of this package, which semismooth Newton (:mod:`.newton`) solves: dense (:class:`.DenseSystem`, the
Newton matrices kept while μ n* keeps its direction), matrix-free (:class:`.PatchSystem` on the contact patch with the
compliance's columns kept for the run, or :class:`.KrylovSystem` with the products remembered for the run) or the full
system (:class:`.FullSystem`).  What a run keeps between its steps on one operator K is one explicit
:class:`Caches` object.  For a nonlinear body (:mod:`ngwear.numerics.fixed_point`) a step's contact problem is solved under
the load f − n(u): :func:`shift` takes n(u) and moves the loads' normal displacements and the plate's load by
N K⁻¹ n(u) and Dᵀ n(u).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ...model.coefficients import Coefficients
from ..columns import Columns
from ..recycle import ComplianceMemory, Recycler
from ..wear import PointLaw, WearStep
from .condensed import DenseSystem, Factors
from .full import FullSystem
from .krylov import KrylovSystem
from .newton import PlateRows
from .patch import PatchSystem

PATCH_SHARE = 0.9
"""Largest share of the contact points in the rigid body's patch for which ``auto`` solves on the patch: the patch
computes a compliance column for each of its points and factorises their matrix, which pays while the patch is a part
of Γ_C; on a pad pressed flat (share 1) GCR's products cost less (``benchmarks/contact_scaling.py --crossover``)."""
KEPT = 2
"""Matrix-free: the remembered products (or columns) of this many μ n* kept, the last used: a programme's stops go
from sliding to rest (μ n* = 0) and back, and each stop would otherwise start from no product."""


@dataclass
class Caches:
    """What a run keeps between its steps on one operator K (K₀, or a nonlinear body's tangent), built on first use.

    ``matrices``: the Newton matrices of the last μ n* (dense: with their LU ``factors``; matrix-free: the products or
    columns of the last :data:`KEPT`, the last used last); ``patch``: whether the matrix-free solve is on the patch
    (decided at the first step); ``slip``, ``unit``, ``referred``: with μ of the state, n*, F(n*) and the reference μ
    the factors are of; ``shifted``: N K⁻¹ n(u), Dᵀ n(u) of the bulk's current iterate; ``thermal``: f_th, the
    thermal load of the step (:func:`expand`).
    """

    patch: bool | None = None
    matrices: dict = field(default_factory=dict)
    factors: Factors = field(default_factory=Factors)
    slip: np.ndarray | None = None
    unit: np.ndarray | None = None
    referred: np.ndarray | None = None
    shifted: tuple | None = None
    thermal: np.ndarray | None = None


@dataclass(frozen=True)
class Drive:
    """What a step's system is built with: s_v, s_F, the coefficients μ, κ, L, the reference μ and the wear step."""

    speed: float
    load: float
    coefficients: Coefficients
    reference: np.ndarray | None
    wear: WearStep

    @cached_property
    def law(self) -> PointLaw:
        """The nodal law p_j the solver sees (the wear step folded into the compliance)."""
        return self.wear.point_law()


def full(disc) -> bool:
    """Whether ``disc`` is solved as the full-system reference (``solver.method = "full"``)."""
    return disc.scene.solver.method == "full"


def unknowns(disc) -> np.ndarray:
    """The unknowns at rest: s at the contact points (condensed) or the free DOFs (full), then δ."""
    cond = disc.condensation
    return np.zeros(cond.full_basis.shape[1] if full(disc) else disc.points.n + cond.plate_modes_count)


def normal(disc, x: np.ndarray) -> np.ndarray:
    """The normal displacements s = ν·u at the contact points."""
    cond = disc.condensation
    return cond.N @ (cond.full_basis @ x) if full(disc) else x[:disc.points.n]


def plate(disc, x: np.ndarray) -> np.ndarray:
    """δ, the plate's displacement (and tilts): the unknowns after the contact points' s (after the free DOFs: full)."""
    return x[len(x) - disc.condensation.plate_modes_count:] if full(disc) else x[disc.points.n:]


def displacement(disc, x: np.ndarray) -> np.ndarray:
    """The displacement DOF vector of the full path's unknowns, u = T x."""
    return disc.condensation.full_basis @ x


def shift(disc, caches: Caches, n: np.ndarray) -> np.ndarray:
    """Solve the next contact problems under the load f − n (+ f_th): keep N K⁻¹ n and Dᵀ n; returns K⁻¹ n.

    With a thermal load (:func:`expand`) n stands for n − f_th: the load is f + f_th − n.
    """
    n = n if caches.thermal is None else n - caches.thermal
    response, coupling = disc.elastic.operator.solve(n), disc.condensation.plate
    caches.shifted = disc.condensation.N @ response, np.zeros(0) if coupling is None else coupling.response.T @ n
    return response


def expand(disc, caches: Caches, load: np.ndarray) -> None:
    """Solve the next steps under the thermal load f_th = ``load`` as well (a right-hand side: K stays).

    A linear body's loads move at once by N K⁻¹ f_th and Dᵀ f_th (one back-substitution); a nonlinear body's with
    each image's n(u) (:func:`shift`); the full path adds it to its load vector.
    """
    caches.thermal = load
    if disc.elastic.linear and not full(disc):
        shift(disc, caches, np.zeros_like(load))


def normal_response(disc, normal_, directed: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """ν·u(x_i) under the point forces f_j = normal_j ν + directed_j b_j: H normal + A directed, matrix-free.

    One back-substitution, u = K⁻¹ Pᵀ f; with b_j = ν + μ n*_j it is the product with A = H + μ F.  ``normal_``
    and ``directed`` may be k columns (n × k): one back-substitution with k right-hand sides.
    """
    cond, columns = disc.condensation, np.ndim(normal_) == 2
    normal_, directed = (np.reshape(a, (len(a), -1)) for a in (normal_, directed))
    forces = normal_[:, None, :] * cond.nu[None, :, None] + directed[:, None, :] * directions[:, :, None]
    out = cond.N @ disc.elastic.operator.solve(disc.points.P.T @ forces.reshape(-1, normal_.shape[1]))
    return out if columns else out[:, 0]


def system(disc, caches: Caches, drive: Drive, load_factor: float | None = None):
    """The Newton system of a step under the loads' factor ``load_factor`` (default: the drive's s_F)."""
    cond, scene = disc.condensation, disc.scene
    load_factor = drive.load if load_factor is None else load_factor
    if full(disc):
        return _full_system(disc, caches, drive, load_factor)
    friction = disc.contact.friction_directions(drive.coefficients, drive.speed)        # μ_i n*_i
    if disc.matrix_free:
        if caches.patch is None:
            caches.patch = disc.contact_solve == "patch" or (
                disc.contact_solve == "auto" and patch_share(disc) <= PATCH_SHARE)
        directions = cond.nu[None, :] + friction                                     # A's force directions ν + μ n*
        key = ("patch" if caches.patch else "krylov", directions.tobytes())
        if key != next(reversed(caches.matrices), None):
            kept = caches.matrices.pop(key, None)
            if kept is None:
                before = next(reversed(caches.matrices.values()), None)
                kept = _columns(disc, friction, before) if caches.patch else _recycler(disc, friction)
            caches.matrices[key] = kept                                               # the last used last
            while len(caches.matrices) > KEPT:
                del caches.matrices[next(iter(caches.matrices))]
            caches.factors = Factors()
        directed = None if cond.plate is None else cond.plate.directed(directions)
        s_load, rows = _loads(disc, caches, directed, load_factor)
        kind = PatchSystem if caches.patch else KrylovSystem
        last = (caches.factors, rows) if caches.patch else (scene.solver.tolerance, rows)
        return kind(caches.matrices[key], cond.compliance_estimate, disc.points.weights, s_load, cond.d0,
                    scene.contact.gap, drive.law, *last)
    key = friction.tobytes()
    if key not in caches.matrices:
        A = _compliance(disc, caches, drive, friction)
        directed = None if cond.plate is None else cond.plate.directed(cond.nu[None, :] + friction)
        caches.matrices = {key: (A, directed)}
    A, directed = caches.matrices[key]
    s_load, rows = _loads(disc, caches, directed, load_factor)
    return DenseSystem(cond.normal_compliance, A, disc.points.weights, s_load, cond.d0, scene.contact.gap,
                           drive.law, caches.factors, rows, scene.solver.tolerance)


def _compliance(disc, caches: Caches, drive: Drive, friction: np.ndarray) -> np.ndarray:
    """A = H + F(μ n*) for a new μ n*, F_ij = ν·G_ij·(μ n*)_j.

    With μ a coefficient of the state it changes at every step while n* keeps its direction: A = H + F(n*) diag(μ)
    with F(n*) kept for the direction, and the dense factors are those of the reference μ (``drive.reference``,
    :class:`~ngwear.numerics.systems.condensed.Factors`), kept while it is.
    """
    cond, reference = disc.condensation, drive.reference
    H = cond.normal_compliance
    if reference is None:
        caches.factors = Factors()
        return H + cond.friction_compliance(friction) if friction.any() else H
    slip = disc.contact.motion.n_star(drive.speed)
    if caches.slip is None or not np.array_equal(slip, caches.slip):
        caches.slip, caches.unit, caches.factors = slip, cond.friction_compliance(slip), Factors()
    if caches.factors.reference is None or caches.referred is not reference:
        directed = None if cond.plate is None else cond.plate.directed(cond.nu[None, :] + reference[:, None] * slip)
        caches.referred, caches.factors = reference, Factors((H + caches.unit * reference[None, :], directed))
    return H + caches.unit * drive.coefficients.friction[None, :]


def _loads(disc, caches: Caches, directed, load_factor: float):
    """The normal displacements under the loads, s_F N K⁻¹ f, and the plate's rows, less the bulk's shift."""
    s_load = load_factor * disc.loads.s_load
    rows = plate_rows(disc, directed, load_factor)
    if caches.shifted is not None:
        s_load = s_load - caches.shifted[0]
        if rows is not None:
            rows = PlateRows(rows.normal, rows.directed, rows.stiffness, rows.load - caches.shifted[1])
    return s_load, rows


def _recycler(disc, friction) -> Recycler:
    """The products with A = H + F(μ n*) (this μ n*) and H remembered for the run, and the Newton basis on them."""
    directions = disc.condensation.nu[None, :] + friction
    respond = lambda directed, normal_: normal_response(disc, normal_, directed, directions)  # noqa: E731
    return Recycler(ComplianceMemory(respond, disc.points.n))


def _columns(disc, friction, before) -> Columns:
    """The columns of A = H + F(μ n*) (this μ n*) and H for the run; H's are kept from ``before`` (other μ n*)."""
    directions = disc.condensation.nu[None, :] + friction
    respond = lambda directed, normal_: normal_response(disc, normal_, directed, directions)  # noqa: E731
    kept = before.normal if isinstance(before, Columns) else None
    return Columns(respond, disc.points.n, kept, same=not friction.any())


def plate_rows(disc, directed, load_factor: float) -> PlateRows | None:
    """The plate's rows of a step (None without a plate), ``directed`` = b_i·Φ_i for this step's force directions."""
    coupling = disc.condensation.plate
    return None if coupling is None else PlateRows(coupling.normal, directed, coupling.stiffness,
                                                   load_factor * disc.loads.plate_load)


def _full_system(disc, caches: Caches, drive: Drive, load_factor: float) -> FullSystem:
    """The reference system: NGSolve form with w, μ, n* of this step (explicit wear: w = a, see the scene's rules)."""
    cf, cond = disc.full_form, disc.condensation
    disc.set_nodal(cf.w, drive.wear.a)
    for gf, component in zip(cf.friction, disc.contact.friction_directions(drive.coefficients, drive.speed).T):
        disc.set_nodal(gf, component)
    load = cond.full_basis.T @ disc.loads.load
    load[len(load) - cond.plate_modes_count:] += disc.loads.plate_force
    load = load_factor * load if caches.thermal is None else load_factor * load + cond.full_basis.T @ caches.thermal
    floating = cond.plate_modes_count and not disc.scene.geometry.dirichlet
    return FullSystem(cf, cond.full_basis, load, cond.N, disc.points.weights, cond.d0, disc.scene.contact.gap,
                      disc.elastic.stiffness, drive.law, cond.rigid_translation if floating else None)


def patch_share(disc) -> float:
    """The share of the contact points in the rigid body's contact patch under the largest load.

    The body moved rigidly to the plate's force balance (:meth:`PatchSystem.start`; held otherwise: the loads'
    displacement s_F): a soft layer's patch to a few points, and whether it is a part of Γ_C or all of it.  ``auto``
    solves on the patch up to :data:`PATCH_SHARE`.
    """
    cond, n, contact = disc.condensation, disc.points.n, disc.contact
    law, largest = contact.law, contact.motion.largest_load
    directed = None if cond.plate is None else cond.plate.directed(
        cond.nu[None, :] + contact.friction_directions(contact.coefficients, contact.motion.first().speed))
    patch = PatchSystem(None, cond.compliance_estimate, disc.points.weights, largest * disc.loads.s_load, cond.d0,
                        disc.scene.contact.gap, PointLaw(law, law.derivative), {}, plate_rows(disc, directed, largest))
    x, _ = patch.start(np.concatenate([patch.s_load, np.zeros(cond.plate_modes_count)]), np.zeros(n))
    return np.count_nonzero(law.derivative(x[:n] - cond.d0)) / max(n, 1)

