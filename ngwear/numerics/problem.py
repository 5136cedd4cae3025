"""One step's problem on a discretization, as the step solver sees it: its unknowns and its Newton system.

The unknowns x are the normal displacements s_i at the contact points and the plate's δ (condensed), or the free
DOFs and δ (the full-system reference).  :meth:`Problem.system` builds a step's system from the discretization's
pieces: dense (:class:`~ngwear.numerics.solver.CondensedSystem`, the Newton matrices kept while μ n* keeps its
direction), matrix-free (:class:`~ngwear.numerics.patch.PatchSystem` on the contact patch with the compliance's
columns kept for the run, or :class:`~ngwear.numerics.solver.KrylovSystem` with the products remembered for the run)
or the full system (:class:`~ngwear.numerics.solver.FullSystem`).  For a nonlinear body (:mod:`ngwear.numerics.bulk`) a
step's contact problem is solved under the load f − n(u): :meth:`Problem.shift` takes n(u) and moves the loads'
normal displacements and the plate's load by N K⁻¹ n(u) and Dᵀ n(u).
"""
from __future__ import annotations

import numpy as np

from .bulk import Remainder
from .columns import Columns
from .patch import PatchSystem
from .recycle import ComplianceMemory, Recycler
from .solver import CondensedSystem, Factors, FullSystem, KrylovSystem, PlateRows, PointLaw
from .wear import WearIntegrator

PATCH_SHARE = 0.9
"""Largest share of the contact points in the rigid body's patch for which ``auto`` solves on the patch: the patch
computes a compliance column for each of its points and factorises their matrix, which pays while the patch is a part
of Γ_C; on a pad pressed flat (share 1) GCR's products cost less (``benchmarks/contact_scaling.py --crossover``)."""


KEPT = 2
"""Matrix-free: the remembered products (or columns) of this many μ n* kept, the last used: a programme's stops go
from sliding to rest (μ n* = 0) and back, and each stop would otherwise start from no product."""


class Problem:
    """The step problem of a :class:`~ngwear.numerics.discrete.Discretization` (its K: K₀ or a tangent).

    Attributes
    ----------
    contact : Contact
        What the contact points read at each step (load factor, μ n*, α, the forces).
    full : bool
        Whether this is the full-system reference path (``solver.method = "full"``).
    n, d0 : int, ndarray
        The number of contact points and their initial distance d₀.
    """

    def __init__(self, disc, patch: bool | None = None):
        self.disc, self.scene, self.contact = disc, disc.scene, disc.contact
        self.patch = patch                      # matrix-free: on the patch (else GCR), decided at the first step
        self.elastic, self.condensation, self.loads = disc.elastic, disc.condensation, disc.loads
        self.full = self.scene.solver.method == "full"
        self.n, self.d0 = disc.points.n, self.condensation.d0
        self.matrices: dict = {}                # the Newton matrices of the last μ n* (dense: with their LU factors;
                                                # matrix-free: of the last KEPT, the current last)
        self.factors: dict = Factors()
        self.slip: np.ndarray | None = None     # with μ of the state: n*, F(n*) and the reference μ of the factors
        self.unit: np.ndarray | None = None
        self.referred: np.ndarray | None = None
        self.shifted: tuple | None = None       # N K⁻¹ n(u), Dᵀ n(u) of the bulk's current iterate
        self.thermal: np.ndarray | None = None  # f_th, the thermal load of the step (:meth:`expand`)

    @property
    def linear(self) -> bool:
        """Whether the body is linear (a step is one contact solve)."""
        return self.elastic.linear

    @property
    def root(self):
        """The factorised stiffness whose factorisation K's operator is (a tangent may update another's)."""
        return self.elastic.root

    def flips(self, u: np.ndarray) -> int | None:
        """The kink's points whose branch at u is not K's (see :meth:`~ngwear.numerics.pieces.Elastic.flips`)."""
        return self.elastic.flips(u)

    def tangent(self, u: np.ndarray, columns: dict | None) -> Problem:
        """The problem with K the laws' tangent at u (its pieces built: factorisation, condensation, loads)."""
        disc = self.disc.tangent(u, columns)
        for _, build in disc.stages():
            build()
        tangent = Problem(disc, self.patch)
        tangent.thermal = self.thermal
        return tangent

    def remainder(self) -> Remainder:
        """n(u) = F(u) − K u with this problem's K."""
        return Remainder(self.elastic)

    def unknowns(self) -> np.ndarray:
        """The unknowns at rest: s at the contact points (condensed) or the free DOFs (full), then δ."""
        cond = self.condensation
        return np.zeros(cond.full_basis.shape[1] if self.full else self.n + cond.plate_modes_count)

    def normal(self, x: np.ndarray) -> np.ndarray:
        """The normal displacements s = ν·u at the contact points."""
        return self.condensation.N @ (self.condensation.full_basis @ x) if self.full else x[:self.n]

    def plate(self, x: np.ndarray) -> np.ndarray:
        """δ, the plate's displacement (and tilts)."""
        return x[len(x) - self.condensation.plate_modes_count:]

    def displacement(self, x: np.ndarray) -> np.ndarray:
        """The displacement DOF vector of the full path's unknowns, u = T x."""
        return self.condensation.full_basis @ x

    def shift(self, n: np.ndarray) -> np.ndarray:
        """Solve the next contact problems under the load f − n (+ f_th): keep N K⁻¹ n and Dᵀ n; returns K⁻¹ n.

        With a thermal load (:meth:`expand`) n stands for n − f_th: the load is f + f_th − n.
        """
        n = n if self.thermal is None else n - self.thermal
        response, plate = self.elastic.operator.solve(n), self.condensation.plate
        self.shifted = self.condensation.N @ response, np.zeros(0) if plate is None else plate.response.T @ n
        return response

    def expand(self, load: np.ndarray) -> None:
        """Solve the next steps under the thermal load f_th = ``load`` as well (a right-hand side: K stays).

        A linear body's loads move at once by N K⁻¹ f_th and Dᵀ f_th (one back-substitution); a nonlinear body's
        with each image's n(u) (:meth:`shift`); the full path adds it to its load vector.
        """
        self.thermal = load
        if self.linear and not self.full:
            self.shift(np.zeros_like(load))

    def recover(self, forces: np.ndarray, t: float, plate: np.ndarray) -> np.ndarray:
        """The displacement s_F(t) K⁻¹ f + D δ − K⁻¹ Pᵀ f_c: one back-substitution (what the bulk's image adds to)."""
        return self.disc.recover(forces, t, plate, nonlinear=False)

    def normal_response(self, normal: np.ndarray, directed: np.ndarray, directions: np.ndarray) -> np.ndarray:
        """ν·u(x_i) under the point forces f_j = normal_j ν + directed_j b_j: H normal + A directed, matrix-free.

        One back-substitution, u = K⁻¹ Pᵀ f; with b_j = ν + μ n*_j it is the product with A = H + μ F.  ``normal``
        and ``directed`` may be k columns (n × k): one back-substitution with k right-hand sides.
        """
        nu, columns = self.condensation.nu, np.ndim(normal) == 2
        normal, directed = (np.reshape(a, (len(a), -1)) for a in (normal, directed))
        forces = normal[:, None, :] * nu[None, :, None] + directed[:, None, :] * directions[:, :, None]
        out = self.condensation.N @ self.elastic.operator.solve(self.disc.points.P.T @ forces.reshape(-1, normal.shape[1]))
        return out if columns else out[:, 0]

    def system(self, t: float, load_factor: float, law, integrator: WearIntegrator):
        """The Newton system of the step at t under the loads' factor ``load_factor`` with the nodal law ``law``."""
        disc, cond = self.disc, self.condensation
        if self.full:
            return self._full_system(t, load_factor, integrator)
        friction = self.contact.friction_directions(t)                      # μ_i n*_i
        if disc.matrix_free:
            if self.patch is None:
                self.patch = disc.contact_solve == "patch" or (
                    disc.contact_solve == "auto" and patch_share(self) <= PATCH_SHARE)
            directions = cond.nu[None, :] + friction                         # A's force directions ν + μ n*
            key = ("patch" if self.patch else "krylov", directions.tobytes())
            if key != next(reversed(self.matrices), None):
                kept = self.matrices.pop(key, None)
                if kept is None:
                    before = next(reversed(self.matrices.values()), None)
                    kept = self._columns(friction, before) if self.patch else self._recycler(friction)
                self.matrices[key] = kept                                     # the last used last
                while len(self.matrices) > KEPT:
                    del self.matrices[next(iter(self.matrices))]
                self.factors = Factors()
            directed = None if cond.plate is None else cond.plate.directed(directions)
            s_load, plate = self._loads(directed, load_factor)
            if self.patch:
                return PatchSystem(self.matrices[key], cond.compliance_estimate, disc.points.weights, s_load, cond.d0,
                                   self.scene.contact.gap, law, self.factors, plate)
            return KrylovSystem(self.matrices[key], cond.compliance_estimate, disc.points.weights, s_load, cond.d0,
                                self.scene.contact.gap, law, self.scene.solver.tolerance, plate)
        key = friction.tobytes()
        if key not in self.matrices:
            A = self._compliance(t, friction)
            directed = None if cond.plate is None else cond.plate.directed(cond.nu[None, :] + friction)
            self.matrices = {key: (A, directed)}
        A, directed = self.matrices[key]
        s_load, plate = self._loads(directed, load_factor)
        return CondensedSystem(cond.normal_compliance, A, disc.points.weights, s_load, cond.d0,
                               self.scene.contact.gap, law, self.factors, plate, self.scene.solver.tolerance)

    def _compliance(self, t: float, friction: np.ndarray) -> np.ndarray:
        """A = H + F(μ n*) for a new μ n* at t, F_ij = ν·G_ij·(μ n*)_j.

        With μ a coefficient of the state it changes at every step while n* keeps its direction: A = H + F(n*) diag(μ)
        with F(n*) kept for the direction, and the dense factors are those of the contact's reference μ
        (:attr:`~ngwear.numerics.contact.Contact.reference`, :class:`~ngwear.numerics.solver.Factors`), kept while it is.
        """
        cond, reference = self.condensation, self.contact.reference
        H = cond.normal_compliance
        if reference is None:
            self.factors = Factors()
            return H + cond.friction_compliance(friction) if friction.any() else H
        slip = self.contact.n_star(t)
        if self.slip is None or not np.array_equal(slip, self.slip):
            self.slip, self.unit, self.factors = slip, cond.friction_compliance(slip), Factors()
        if self.factors.reference is None or self.referred is not reference:
            directed = None if cond.plate is None else cond.plate.directed(cond.nu[None, :] + reference[:, None] * slip)
            self.referred, self.factors = reference, Factors((H + self.unit * reference[None, :], directed))
        return H + self.unit * self.contact.coefficients_at(t).friction[None, :]

    def _loads(self, directed, load_factor: float):
        """The normal displacements under the loads, s_F N K⁻¹ f, and the plate's rows, less the bulk's shift."""
        s_load = load_factor * self.loads.s_load
        plate = self._plate_rows(directed, load_factor)
        if self.shifted is not None:
            s_load = s_load - self.shifted[0]
            if plate is not None:
                plate = PlateRows(plate.normal, plate.directed, plate.stiffness, plate.load - self.shifted[1])
        return s_load, plate

    def _recycler(self, friction) -> Recycler:
        """The products with A = H + F(μ n*) (this μ n*) and H remembered for the run, and the Newton basis on them."""
        directions = self.condensation.nu[None, :] + friction
        respond = lambda directed, normal: self.normal_response(normal, directed, directions)  # noqa: E731
        return Recycler(ComplianceMemory(respond, self.n))

    def _columns(self, friction, before) -> Columns:
        """The columns of A = H + F(μ n*) (this μ n*) and H for the run; H's are kept from ``before`` (other μ n*)."""
        directions = self.condensation.nu[None, :] + friction
        respond = lambda directed, normal: self.normal_response(normal, directed, directions)  # noqa: E731
        normal = before.normal if isinstance(before, Columns) else None
        return Columns(respond, self.n, normal, same=not friction.any())

    def _plate_rows(self, directed, load_factor: float) -> PlateRows | None:
        """The plate's rows of a step (None without a plate), ``directed`` = b_i·Φ_i for this step's force directions."""
        plate = self.condensation.plate
        return None if plate is None else PlateRows(plate.normal, directed, plate.stiffness,
                                                    load_factor * self.loads.plate_load)

    def _full_system(self, t: float, load_factor: float, integrator: WearIntegrator) -> FullSystem:
        """The reference system: NGSolve form with w, μ, n* of this step (explicit wear: w = a, see the scene's rules)."""
        disc, cf, cond = self.disc, self.disc.full_form, self.condensation
        disc.set_nodal(cf.w, integrator.a)
        for gf, component in zip(cf.friction, self.contact.friction_directions(t).T):
            disc.set_nodal(gf, component)
        load = cond.full_basis.T @ self.loads.load
        load[len(load) - cond.plate_modes_count:] += self.loads.plate_force
        load = load_factor * load if self.thermal is None else load_factor * load + cond.full_basis.T @ self.thermal
        floating = cond.plate_modes_count and not self.scene.geometry.dirichlet
        return FullSystem(cf, cond.full_basis, load, cond.N, disc.points.weights, cond.d0,
                          self.scene.contact.gap, self.elastic.stiffness, integrator.point_law(),
                          cond.rigid_translation if floating else None)


def patch_share(problem: Problem) -> float:
    """The share of the contact points in the rigid body's contact patch under the largest load.

    The body moved rigidly to the plate's force balance (:meth:`PatchSystem.start`; held otherwise: the loads'
    displacement s_F): a soft layer's patch to a few points, and whether it is a part of Γ_C or all of it.  ``auto``
    solves on the patch up to :data:`PATCH_SHARE`.
    """
    cond, n, law = problem.condensation, problem.n, problem.contact.law
    drive = problem.contact.drive
    largest = drive.largest_load if drive is not None else max((abs(f) for _, f in problem.scene.loads.time_table),
                                                                default=1.0)
    directed = None if cond.plate is None else cond.plate.directed(
        cond.nu[None, :] + problem.contact.friction_directions(0.0))
    system = PatchSystem(None, cond.compliance_estimate, problem.disc.points.weights, largest * problem.loads.s_load,
                         cond.d0, problem.scene.contact.gap, PointLaw(law, law.derivative), {},
                         problem._plate_rows(directed, largest))
    x, _ = system.start(np.concatenate([system.s_load, np.zeros(cond.plate_modes_count)]), np.zeros(n))
    return np.count_nonzero(law.derivative(x[:n] - cond.d0)) / max(n, 1)
