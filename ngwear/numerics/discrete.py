"""The discrete problem of a scene: its pieces (:mod:`.body`, :mod:`.elastic`, :mod:`.condensation`), reused.

:class:`Discretization` holds a :class:`~ngwear.numerics.body.Body` (mesh, space, contact points), an
:class:`~ngwear.numerics.elastic.Elastic` (stiffness, factorisation), a
:class:`~ngwear.numerics.condensation.Condensation` (contact direction, compliance, plate),
:class:`~ngwear.numerics.condensation.Loads` and a :class:`~ngwear.numerics.contact.Contact` (what the contact points
read at each step: the motion, the coefficients, the laws), one of each.  :meth:`Discretization.with_scene` keeps
every piece a scene change leaves valid, as the keys declare (:meth:`~ngwear.model.scene.Scene.changed_from`):
friction, wear, gap, motion and time never invalidate anything.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import ngsolve as ngs
import numpy as np

from ..model.coefficients import at_points
from ..model.compliance import compliance_from
from ..model.keys import Level
from ..model.materials import region_laws, young_along
from ..model.scene import Scene
from ..model.scene_mesh import build_mesh
from .body import Body
from .condensation import Condensation, Loads
from .contact import Contact
from .elastic import Elastic
from .fixed_point import Remainder, fixed_point
from .forms import contact_form
from .operators import DENSE_LIMIT, SOFT_LIMIT

CONTACT_SOLVES = ("auto", "dense", "krylov", "patch")
BULK_RECOVERY = 500
"""Most iterations of a nonlinear material's displacement recovered from its contact forces (K₀ contracts)."""


@dataclass(frozen=True)
class Reuse:
    """What a discretization keeps for another scene: the levels kept and the first level rebuilt."""

    rebuilt: Level

    @property
    def kept(self) -> tuple[Level, ...]:
        return tuple(level for level in Level if level < self.rebuilt and level is not Level.NOTHING)

    def __str__(self) -> str:
        if self.rebuilt is Level.NOTHING:
            return "reuses everything"
        rebuilt = ", ".join(level.label for level in Level if self.rebuilt <= level < Level.NOTHING)
        kept = ", ".join(level.label for level in self.kept)
        return f"rebuilds {rebuilt}" + (f"; keeps {kept}" if kept else "")


class Discretization:
    """The pieces of a scene's discrete problem: built lazily, kept across steps and runs, reused across scenes.

    ``contact_solve`` chooses how the contact problem is condensed: ``dense`` (the rows ν·G of the point
    compliance, then dense Newton algebra), ``krylov`` (matrix-free: every product with the compliance is
    one back-substitution, GCR with recycling), ``patch`` (matrix-free: dense algebra on the contact patch from the
    compliance's columns of the points in contact, :mod:`~ngwear.numerics.systems.patch`) or ``auto``: dense up to
    ``operators.DENSE_LIMIT`` contact DOFs, or up to ``operators.SOFT_LIMIT`` when the layer is soft against the body
    (:meth:`layer_ratio` < 1); beyond, ``patch`` where the rigid body's patch is a part of Γ_C, else ``krylov``
    (``numerics.systems.PATCH_SHARE``).

    Parameters
    ----------
    scene : Scene
        What to discretize.
    mesh : ngsolve.Mesh, optional
        A mesh with the scene's named boundaries (default: Netgen's mesh of the scene, or the cache's).
    contact_solve : {"auto", "dense", "krylov", "patch"}
        How the contact problem is condensed (see above).

    Raises
    ------
    ValueError
        ``contact_solve`` is none of these.

    Attributes
    ----------
    scene : Scene
    body : Body
        Mesh, space and contact points (``mesh``, ``fes`` and ``points`` are the body's).
    matrix_free : bool
        Whether the contact problem is solved matrix-free (see above).
    elastic : Elastic
        The stiffness and its factorisation.
    condensation : Condensation
        ν, N, d₀, the contact compliance and the plate's coupling.
    loads : Loads
        The load vector and its response.
    contact : Contact
        What the contact points read at each step: load factor, slip v*, α, μ n*, the compliance p.
    """

    def __init__(self, scene: Scene, mesh: ngs.Mesh | None = None, contact_solve: str = "auto", *,
                 body: Body | None = None, elastic: Elastic | None = None, condensation: Condensation | None = None,
                 loads: Loads | None = None):
        if contact_solve not in CONTACT_SOLVES:
            raise ValueError(f"contact_solve: must be auto, dense, krylov or patch (got {contact_solve!r})")
        self.scene, self.contact_solve = scene, contact_solve
        self.body = body if body is not None else Body(scene, mesh if mesh is not None else build_mesh(scene))
        self.elastic = elastic or Elastic(scene, self.body, schur=self._dense(scene, self.body))
        self.condensation = condensation or Condensation(scene, self.body, self.elastic)
        self.loads = loads or Loads(scene, self.body, self.elastic, self.condensation)
        self.contact = Contact(scene, self.body.points, self.condensation.nu)
        self.mesh, self.fes, self.points = self.body.mesh, self.body.fes, self.body.points
        self.matrix_free = not self.elastic.schur

    def reuse(self, scene: Scene) -> Reuse:
        """What a discretization of ``scene`` keeps of this one (see :class:`Reuse`; ``str()`` for a status line).

        The keys of the scene declare what a change invalidates; a change that switches the automatic contact
        solve between dense and matrix-free (the layer's stiffness against the body's) needs a new factorisation.
        """
        level = scene.changed_from(self.scene)
        if level > Level.STIFFNESS and self._dense(scene, self.body) != self.elastic.schur:
            level = Level.STIFFNESS
        return Reuse(level)

    def with_scene(self, scene: Scene) -> Discretization:
        """A discretization of ``scene`` sharing every piece the change leaves valid (see :meth:`reuse`)."""
        rebuilt = self.reuse(scene).rebuilt
        if rebuilt is Level.MESH:
            return Discretization(scene, contact_solve=self.contact_solve)
        kept = {name: piece if rebuilt > level else None for name, piece, level in
                (("elastic", self.elastic, Level.STIFFNESS), ("condensation", self.condensation, Level.DIRECTION),
                 ("loads", self.loads, Level.LOADS))}
        body = self.body if rebuilt > Level.SPACE else Body(scene, self.body.mesh)
        return Discretization(scene, contact_solve=self.contact_solve, body=body, **kept)

    def moved(self, mesh: ngs.Mesh, regions: tuple[str, ...]) -> Discretization:
        """The discretization of ``mesh``: this one's elements, the vertices of ``regions`` moved (a geometry update).

        Everything is built anew on the moved mesh (the contact points, K and its factorisation, d₀, the loads, the
        plate) but what the move leaves: the space (on the same mesh object), the gradient blocks of the other regions
        (those of a pad's backing plate: a large part of K's assembly) and K's ordering (the same elements: METIS is
        skipped).
        """
        built = self.body.kept("gradient_blocks")
        body = Body(self.scene, mesh, {region: blocks for region, blocks in built.built.items() if region not in regions}
                    if built is not None else None, like=self.body)
        schur = self._dense(self.scene, body)
        elastic = Elastic(self.scene, body, schur, ordering=None if schur else self.elastic.factored_ordering)
        return Discretization(self.scene, contact_solve=self.contact_solve, body=body, elastic=elastic)

    def tangent(self, state: np.ndarray, columns: dict | None = None) -> Discretization:
        """The discretization with K the laws' tangent at the displacement ``state``.

        A new factorisation, or an update of this one's (see :class:`~ngwear.numerics.elastic.Elastic`, ``columns``).
        """
        elastic = Elastic(self.scene, self.body, self.elastic.schur, state, base=self.elastic, columns=columns)
        return Discretization(self.scene, contact_solve=self.contact_solve, body=self.body, elastic=elastic)

    def stages(self) -> list[tuple[str, callable]]:
        """(label, build) of what the condensed path still has to build before its first step (for a progress bar)."""
        ndof = f"{self.fes.ndof:,} DOFs".replace(",", " ")
        todo = [(self.elastic, "stiffness", f"assembling K ({ndof})"),
                (self.elastic, "operator", "factorising K (PARDISO)")]
        if not self.matrix_free:
            todo.append((self.condensation, "normal_rows", f"contact compliance ({self.points.n} points)"))
        todo += [(self.loads, "u_load", "loads"), (self.condensation, "plate", "plate")]
        return [(label, lambda piece=piece, name=name: getattr(piece, name))
                for piece, name, label in todo if not piece.built(name)]

    def gridfunction(self, u: np.ndarray) -> ngs.GridFunction:
        """The displacement with DOF vector ``u``."""
        return self.body.gridfunction(u)

    def set_nodal(self, gf: ngs.GridFunction, values: np.ndarray) -> None:
        """A scalar GridFunction of the contact form's space with the given values at the contact points."""
        self.body.set_nodal(gf, values)

    def locate(self, points: np.ndarray):
        """NGSolve mesh points of reference points in the body (Γ_C points are taken from the body side)."""
        return self.body.locate(points, -self.condensation.nu, self.scene.mesh.maxh or 1.0)

    # ---- how the contact problem is solved ----------------------------------------------
    @property
    def layer_ratio(self) -> float:
        """ρ of :func:`layer_ratio` for this scene and body."""
        return layer_ratio(self.scene, self.body)

    def _dense(self, scene: Scene, body: Body) -> bool:
        if self.contact_solve != "auto":
            return self.contact_solve == "dense"
        size = len(body.contact_dofs)
        return not (size > DENSE_LIMIT or (size > SOFT_LIMIT and layer_ratio(scene, body) < 1.0))

    def recover(self, forces: np.ndarray, load: float, plate: np.ndarray, nonlinear: bool = True) -> np.ndarray:
        """Displacement DOF vector under the point forces f_c and the loads' factor s_F: u = s_F K⁻¹ f + D δ − K⁻¹ Pᵀ f_c.

        One back-substitution for a linear body (or ``nonlinear=False``: the part a step solver adds to); with a
        nonlinear material the fixed point u = that − K⁻¹ n(u) (:mod:`ngwear.numerics.fixed_point`), solved to the
        Newton tolerance.
        """
        solve = self.elastic.operator.solve
        u = load * self.loads.u_load - solve(self.points.P.T @ forces.ravel())
        coupling = self.condensation.plate
        u = u if coupling is None else u + coupling.response @ plate
        if not nonlinear or self.elastic.linear:
            return u
        remainder, tolerance = Remainder(self.elastic), self.scene.solver.tolerance
        recovered, gap = fixed_point(lambda v: u - solve(remainder(v)), u, tolerance, BULK_RECOVERY)
        if not gap <= tolerance:
            raise ArithmeticError(f"the displacement of the nonlinear material did not converge in {BULK_RECOVERY} "
                                  "iterations")
        return recovered

    @cached_property
    def full_form(self):
        """Elastic + contact terms as one NGSolve form (for the full-system reference path)."""
        cf = contact_form(self.fes, self.scene, self.contact.law, self.elastic.laws)
        self.set_nodal(cf.d0, self.condensation.d0)
        self.set_nodal(cf.stiffness, self.contact.coefficients.stiffness)
        return cf


def layer_ratio(scene: Scene, body: Body) -> float:
    """ρ = p'(g) t / E: the layer's stiffness against the body's (t: the body's extent along ν, E: along ν).

    E is the smallest Young's modulus of the regions that carry Γ_C.

    The Newton matrix of the contact problem is I + A diag(m p') on the points in contact, and the
    largest eigenvalue of A diag(m p') is of the order of ρ: for ρ < 1 a Krylov solve converges in a few
    products, and the products remembered across the run (``numerics/recycle.py``) make most steps need fewer
    still (``benchmarks/contact_scaling.py`` counts them).
    """
    nu = np.array(scene.contact.direction)
    young = min(young_along(law, nu) for region, law in region_laws(scene).items() if region in body.contact_regions)
    heights = body.mesh.ngmesh.Coordinates() @ nu
    stiffness = at_points(scene.contact.stiffness, "stiffness", body.points.coords)
    slope = compliance_from(scene.contact, stiffness).slope(
        scene.contact.gap)
    return float(np.max(slope)) * np.ptp(heights) / young

