"""The pieces of a scene's discrete problem, each depending on the scene keys of one level and on the pieces before it.

* :class:`Body` (:attr:`~ngwear.model.keys.Level.MESH`, ``SPACE``): the mesh, the finite element space with
  its clamping, the contact points;
* :class:`Elastic` (``STIFFNESS``): K and its factorisation (with the Schur complement for the dense
  contact solve);
* :class:`Condensation` (``DIRECTION``): ν, the normal evaluation N = ν·P, the initial distance d₀, the rows
  ν·G of the contact compliance, the rigid plate's modes and coupling, the strain estimate's segments;
* :class:`Loads` (``LOADS``): the load vector f and K⁻¹f at unit time factor.

Their members are built on first use and kept; :class:`~ngwear.numerics.discrete.Discretization` decides
which pieces a new scene may keep.
"""
from __future__ import annotations

from functools import cached_property

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from ..model.materials import region_laws
from ..model.scene import Scene
from .forms import displacement_space, elastic_integrand, load_form, tangent_form
from .kink import Kink, kinked
from .operators import ElasticOperator, UpdatedOperator
from .plate import PlateCoupling, plate_modes
from .points import contact_points, initial_distance
from .stiffness import GradientBlocks, assembled
from .strain import Segments, outer_facets, segments

LOW_RANK = 32
"""Most kink points whose branch a tangent may change against a factorised K before it is factorised itself."""


class Lazy:
    """A piece whose members (``cached_property``) are built on first use and kept: :meth:`built` says which are."""

    def built(self, name: str) -> bool:
        """Whether the member ``name`` has been built (a cached_property keeps its value in the instance)."""
        return name in self.__dict__

    def kept(self, name: str):
        """The member ``name`` if it has been built, else None (without building it)."""
        return self.__dict__.get(name)


class Body(Lazy):
    """Mesh, displacement space (clamped on the Dirichlet and plate boundaries) and contact points.

    ``blocks``: gradient blocks kept from a body of the same elements, by region (see :class:`GradientBlocks`).
    ``like``: a body on the same mesh object, its vertices moved since (a geometry update): its space, clamping,
    outer facets and the blocks' patterns are kept (they hold the mesh's elements, not their coordinates).
    """

    def __init__(self, scene: Scene, mesh: ngs.Mesh, blocks: dict[str, dict] | None = None, like: Body | None = None):
        self.mesh, self._blocks, self._patterns = mesh, blocks, None
        if like is not None and like.mesh is mesh:
            self.fes, self.free = like.fes, like.free
            if like.built("gradient_blocks"):
                self._patterns = like.gradient_blocks.patterns
            if like.built("outer_facets"):
                self.outer_facets = like.outer_facets
        else:
            self.fes = displacement_space(mesh, scene)
            self.free = np.array(list(self.fes.FreeDofs()), dtype=bool)
        self.points = contact_points(self.fes, scene.dim, scene.mesh.order)

    @cached_property
    def gradient_blocks(self) -> GradientBlocks:
        """The scalar gradient matrices of each region: the stiffness of any linear laws by sparse sums."""
        return GradientBlocks(self.fes, self._blocks, self._patterns)

    @cached_property
    def outer_facets(self) -> np.ndarray:
        """The facets of the body's outer boundary (sorted vertex numbers; see :func:`~ngwear.numerics.strain.segments`)."""
        return outer_facets(self.mesh)

    @cached_property
    def contact_regions(self) -> tuple[str, ...]:
        """The regions (materials) whose elements carry Γ_C."""
        touching = self.mesh.Boundaries("contact").Neighbours(ngs.VOL).Mask()
        return tuple(name for i, name in enumerate(self.mesh.GetMaterials()) if touching[i])

    @cached_property
    def contact_dofs(self) -> np.ndarray:
        """The free DOFs the contact points see (sorted)."""
        dofs = np.unique(self.points.P.indices)
        return dofs[self.free[dofs]]

    def locate(self, points: np.ndarray, inward: np.ndarray, scale: float):
        """NGSolve mesh points of reference points in the body (Γ_C points are taken from the body side, −ν)."""
        points = np.asarray(points, dtype=float)
        mips = self.mesh(*points.T)
        outside = mips["nr"] < 0
        for nudge in (1e-8, 1e-6, 1e-4):
            if not outside.any():
                break
            again = self.mesh(*(points[outside] + nudge * scale * inward).T)
            found = again["nr"] >= 0
            idx = np.flatnonzero(outside)[found]
            mips[idx] = again[found]
            outside[idx] = False
        if outside.any():
            raise ValueError(f"points: {points[outside][0].tolist()} is not in the body")
        return mips

    def gridfunction(self, u: np.ndarray) -> ngs.GridFunction:
        gf = ngs.GridFunction(self.fes)
        gf.vec.FV().NumPy()[:] = u
        return gf

    def set_nodal(self, gf: ngs.GridFunction, values: np.ndarray) -> None:
        """A scalar GridFunction of the contact form's space with the given values at the contact points."""
        gf.vec.FV().NumPy()[:] = self.points.Q @ values


class Elastic(Lazy):
    """The laws of the body's regions, a stiffness K and its factorisation.

    K is the laws' tangent at ε = 0 (K₀: for linear laws the stiffness), or with ``state`` their tangent at that
    displacement (the Newton iterate of a nonlinear law's step solver).  ``schur``: factorise with the
    Schur complement on the contact DOFs (the dense contact solve).  A tangent follows the operator ``base``; when it
    is an update of ``base``'s factorisation, ``columns`` caches that factorisation's K⁻¹Dᵀ (default: ``base``'s).
    ``ordering``: the fill-in reducing ordering K is factorised with (an earlier K's on the same elements, see
    :class:`~ngwear.numerics.operators.ElasticOperator`; None: METIS's).
    """

    def __init__(self, scene: Scene, body: Body, schur: bool, state: np.ndarray | None = None,
                 base: Elastic | None = None, columns: dict | None = None, ordering: np.ndarray | None = None):
        self.scene, self.body, self.schur, self.state, self.ordering = scene, body, schur, state, ordering
        self.laws = region_laws(scene)
        self.linear = all(law.is_linear for law in self.laws.values())   # K₀ is the stiffness: a step, one solve
        self.root, self.columns = self, {}  # the Elastic whose factorisation K's operator is; its K⁻¹Dᵀ by point
        self.changed = np.zeros(0, dtype=int)   # the kink points whose branch differs from the root's
        if base is not None:                # a tangent shares K_lin and the kink of the operator it follows
            for name in ("kink", "linear_stiffness"):
                if base.built(name):
                    setattr(self, name, getattr(base, name))
            changed = None if self.kink is None else np.flatnonzero(self.branches != base.root.branches)
            if changed is not None and len(changed) <= LOW_RANK:
                self.root, self.columns = base.root, base.columns if columns is None else columns
                self.changed = changed

    @cached_property
    def kink(self) -> Kink | None:
        """The compaction laws' kink as sparse algebra (:mod:`ngwear.numerics.kink`), where it is exact; else None."""
        return Kink(self.body.fes, self.laws) if kinked(self.body.fes, self.laws) else None

    @cached_property
    def linear_stiffness(self) -> sp.csr_matrix:
        """K_lin, the stiffness of the laws' linear parts (with :attr:`kink`: F(u) = K_lin u + kink forces)."""
        return self.body.gradient_blocks.stiffness({region: law if law.is_linear else law.linear_part()
                                                    for region, law in self.laws.items()})

    @cached_property
    def stiffness(self) -> sp.csr_matrix:
        """K: K₀ (the laws' tangent at ε = 0), or their tangent at ``state``; K_lin + the kink's tangent with a kink."""
        if self.root is not self:                                   # the root's K and the kink's rows that changed
            return (self.root.stiffness + self.kink.tangent(self._change, self.changed)).tocsr()
        if self.kink is not None:
            return (self.linear_stiffness + self.kink.tangent(self.branches)).tocsr()
        if self.state is None:
            return self.body.gradient_blocks.stiffness({r: law.tangent_at_zero() for r, law in self.laws.items()})
        return assembled(tangent_form(self.body.fes, self.laws, self.body.gridfunction(self.state)))

    @cached_property
    def branches(self) -> np.ndarray | None:
        """The kink's branches K is the tangent on (K₀: every point compressed); None without a kink."""
        if self.kink is None:
            return None
        return np.ones(len(self.kink.c), bool) if self.state is None else self.kink.compressed(self.state)

    def flips(self, u: np.ndarray) -> int | None:
        """The kink's points whose branch at u is not K's (K is F'(u) when 0); None without a kink."""
        return None if self.kink is None else int(np.count_nonzero(self.kink.compressed(u) != self.branches))

    def forces(self, u: np.ndarray) -> np.ndarray:
        """F(u), the internal forces Σ_r ∫_r σ_r(ε(u)) : ε(v) dx (for a linear body K u)."""
        if self.linear:
            return self.stiffness @ u
        if self.kink is not None:
            return self.linear_stiffness @ u + self.kink.forces(u)
        return self._apply(u)

    @cached_property
    def _apply(self):
        """F(u) by NGSolve's ``Apply`` of the symbolic form (any law)."""
        form = ngs.BilinearForm(elastic_integrand(self.body.fes, self.laws))
        u, out = ngs.GridFunction(self.body.fes), ngs.GridFunction(self.body.fes)

        def apply(values: np.ndarray) -> np.ndarray:
            u.vec.FV().NumPy()[:] = values
            form.Apply(u.vec, out.vec)
            return out.vec.FV().NumPy().copy()
        return apply

    @cached_property
    def operator(self) -> ElasticOperator | UpdatedOperator:
        """K's factorisation; for the dense contact solve with the Schur complement on the contact DOFs.

        A kinked law's tangent within :data:`LOW_RANK` branches of a factorised K (its :attr:`root`) is that
        factorisation's update by the kink's rows on those points (:class:`UpdatedOperator`), δ_q = ±c_q.
        """
        root, changed = self.root, self.changed
        if root is self:
            return ElasticOperator(self.stiffness, self.body.free, self.body.contact_dofs, schur=self.schur,
                                   ordering=self.ordering)
        if not len(changed):
            return root.operator
        return UpdatedOperator(root.operator, self.kink.D[changed], self.kink.c[changed] * self._change, self.columns,
                               changed)

    @property
    def factored_ordering(self) -> np.ndarray | None:
        """The ordering K's factorisation took (None before it is built, and with the Schur complement)."""
        operator = self.root.kept("operator")
        return None if operator is None else operator.ordering

    @property
    def _change(self) -> np.ndarray:
        """+1 where a changed point is compressed (the root's K released it), −1 where it is released."""
        return self.branches[self.changed].astype(float) - self.root.branches[self.changed]


class Condensation(Lazy):
    """What the contact direction ν adds to the factorised body: N, d₀, the rows ν·G and the plate's coupling."""

    def __init__(self, scene: Scene, body: Body, elastic: Elastic):
        self.scene, self.body, self.elastic = scene, body, elastic
        self.nu = np.array(scene.contact.direction)
        points = body.points
        self.N = sp.csr_matrix(sp.kron(sp.eye(points.n), self.nu[None, :]) @ points.P)
        self.d0 = initial_distance(points.coords, self.nu)

    @cached_property
    def normal_rows(self) -> np.ndarray:
        """R_ijb = ν·G_ij·e_b, shape (n, n, d): the ν rows of the point compliance G = P K⁻¹ Pᵀ.

        Only these enter the contact law, so G (n d × n d) is never formed: R = (P_c S⁻¹ N_cᵀ)ᵀ, one
        solve with the Schur complement's Cholesky factor for the n columns N_cᵀ (n_c² n flops).
        """
        op, P = self.elastic.operator, self.body.points.P
        columns = op.contact_solve(self.N[:, op.contact_dofs].T.toarray())
        n, d = self.body.points.n, len(self.nu)
        return np.ascontiguousarray((P[:, op.contact_dofs] @ columns).T).reshape(n, n, d)

    @cached_property
    def normal_compliance(self) -> np.ndarray:
        """H = ν·G·ν."""
        return self.normal_rows @ self.nu

    def friction_compliance(self, friction: np.ndarray) -> np.ndarray:
        """F_ij = ν·G_ij·(μ n*)_j: normal displacement at x_i per unit pressure's friction force μ_j n*_j at x_j."""
        return np.einsum("ijb,jb->ij", self.normal_rows, friction)

    @cached_property
    def compliance_estimate(self) -> np.ndarray:
        """h_i = 1/(ν·K_ii·ν) ≤ H_ii, the point's compliance with its neighbours held (no solve needed)."""
        stiffness = self.N.multiply(self.N) @ np.where(self.body.free, self.elastic.stiffness.diagonal(), 0.0)
        return np.divide(1.0, stiffness, out=np.zeros_like(stiffness), where=stiffness > 0)

    @cached_property
    def plate_modes(self) -> np.ndarray | None:
        """E: the rigid motions of the plate's boundary (None without a plate); see :mod:`ngwear.numerics.plate`."""
        plate = self.scene.loads.plate
        return None if plate is None else plate_modes(self.body.fes, plate.boundary, self.nu, plate.tilt)

    @property
    def plate_modes_count(self) -> int:
        """r: 0 without a plate, 1 for a plate that only translates, 2 (2D) or 3 (3D) with tilt."""
        return 0 if self.plate_modes is None else self.plate_modes.shape[1]

    @cached_property
    def plate(self) -> PlateCoupling | None:
        """D, S, Φ, Ψ of the plate (None without a plate): one more back-substitution per mode."""
        if self.plate_modes is None:
            return None
        return PlateCoupling.of(self.plate_modes, self.elastic.stiffness, self.elastic.operator.solve,
                                self.body.points.P, self.N)

    @cached_property
    def segments(self) -> Segments:
        """The segments from the contact points along −ν to the supports: the strain estimate's (no solve)."""
        return segments(self.scene, self.body.mesh, self.body.points.coords, self.body.outer_facets)

    @cached_property
    def full_basis(self) -> sp.csc_matrix:
        """T = [free DOFs | plate modes E]: the full-system path's unknowns are u = T x."""
        free = self.body.free
        columns = sp.eye(self.body.fes.ndof, format="csc")[:, np.flatnonzero(free)]
        return sp.hstack([columns, sp.csc_matrix(self.plate_modes)] if self.plate_modes_count else [columns],
                         format="csc")

    @cached_property
    def rigid_translation(self) -> np.ndarray:
        """The translation u = ν of the whole body in the full-system path's coordinates x (u = T x)."""
        gf = ngs.GridFunction(self.body.fes)
        gf.Set(ngs.CF(tuple(self.nu)))
        free = int(self.body.free.sum())
        rigid = np.zeros(self.full_basis.shape[1])
        rigid[:free] = gf.vec.FV().NumPy()[self.body.free]
        rigid[free] = 1.0
        return rigid


class Loads(Lazy):
    """The loads at unit time factor: f, K⁻¹f, its normal part at the points, and their work on the plate."""

    def __init__(self, scene: Scene, body: Body, elastic: Elastic, condensation: Condensation):
        self.scene, self.body, self.elastic, self.condensation = scene, body, elastic, condensation

    @cached_property
    def load(self) -> np.ndarray:
        """Load vector at unit time factor."""
        f = load_form(self.body.fes, self.scene)
        f.Assemble()
        return f.vec.FV().NumPy().copy()

    @cached_property
    def u_load(self) -> np.ndarray:
        """K⁻¹ f at unit time factor."""
        return self.elastic.operator.solve(self.load)

    @cached_property
    def s_load(self) -> np.ndarray:
        return self.condensation.N @ self.u_load

    @property
    def plate_force(self) -> np.ndarray:
        """F_B = (F·ν, 0, …): the plate force's work on the plate modes at unit time factor (tilts: no moment)."""
        force = np.zeros(self.condensation.plate_modes_count)
        if len(force):
            force[0] = float(np.dot(self.scene.loads.plate.force, self.condensation.nu))
        return force

    @cached_property
    def plate_load(self) -> np.ndarray:
        """f_B + F_B = Dᵀ f + F_B at unit time factor: the loads' and the plate force's work on the modes."""
        plate = self.condensation.plate
        return np.zeros(0) if plate is None else plate.response.T @ self.load + self.plate_force
