"""The discrete problem of a scene: mesh, spaces, assembled stiffness and loads, contact points.

Everything here depends only on mesh, material and load *patterns*; friction μ, wear κ, the gap g
and the foundation motion v* enter at solve time, so changing them reuses every factorisation.
Time dependence: f(t) = f · s_F(t) with a piecewise-linear table; v*(x, t) per contact point from
:class:`~ngwear.model.kinematics.Slip`.
"""
from __future__ import annotations

from functools import cached_property

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from ..model.geometry import build_mesh
from ..model.kinematics import Slip
from ..model.laws import compliance_from, piecewise_linear
from ..model.scene import Scene
from .condense import DENSE_LIMIT, SOFT_LIMIT, ElasticOperator
from .forms import contact_form, contact_points, displacement_space, elastic_form, initial_distance, load_form
from .plate import PlateCoupling, plate_modes


class Discretization:
    """Assembled, factorised pieces of a scene, built lazily and reused across steps and runs.

    ``contact_solve`` chooses how the contact problem is condensed: ``dense`` (the rows ν·G of the
    point compliance, then dense Newton algebra), ``krylov`` (matrix-free: every product with the
    compliance is one back-substitution) or ``auto``: dense up to ``condense.DENSE_LIMIT`` contact DOFs,
    or up to ``condense.SOFT_LIMIT`` when the layer is soft against the body (``layer_ratio`` < 1).
    """

    def __init__(self, scene: Scene, mesh: ngs.Mesh | None = None, contact_solve: str = "auto"):
        if contact_solve not in ("auto", "dense", "krylov"):
            raise ValueError(f"contact_solve: must be auto, dense or krylov (got {contact_solve!r})")
        self.scene = scene
        self.contact_solve = contact_solve
        self.mesh = mesh if mesh is not None else build_mesh(scene)
        self.fes = displacement_space(self.mesh, scene)
        self.free = np.array(list(self.fes.FreeDofs()), dtype=bool)
        self.points = contact_points(self.fes, scene.dim, scene.mesh.order)
        self.law = compliance_from(scene.contact)
        self._orient(scene)

    def _orient(self, scene: Scene) -> None:
        """Contact direction ν, normal evaluation N = ν·P, initial distance d₀ = max ν·x − ν·x_i, slip v*."""
        self.nu = np.array(scene.contact.direction)
        self.N = sp.csr_matrix(sp.kron(sp.eye(self.points.n), self.nu[None, :]) @ self.points.P)
        self.d0 = initial_distance(self.points.coords, self.nu)
        self.slip = Slip(scene.foundation, self.points.coords, self.nu)

    def with_scene(self, scene: Scene) -> Discretization:
        """A discretization of ``scene`` sharing every assembled/factorised piece the change leaves valid.

        Same body mesh, order and clamping: mesh, space and contact points are kept (a new gap g only
        rescales the displayed layer); same material too: K, its factorisation and G are kept; same
        loads too: K⁻¹f is kept.  Friction, wear, g, v* and time never invalidate anything.
        """
        old = self.scene
        body = lambda s: (s.geometry.kind, s.geometry.size, s.geometry.dirichlet, s.mesh,  # noqa: E731
                          s.loads.plate and (s.loads.plate.boundary, s.loads.plate.tilt))
        if body(old) != body(scene):
            return Discretization(scene, contact_solve=self.contact_solve)
        new = object.__new__(Discretization)
        new.__dict__.update({k: v for k, v in self.__dict__.items() if k in _MESH_PARTS})
        new.scene, new.law, new.contact_solve = scene, compliance_from(scene.contact), self.contact_solve
        new._orient(scene)
        if old.material == scene.material:
            new.__dict__.update({k: v for k, v in self.__dict__.items() if k in _MATERIAL_PARTS})
            if old.contact.direction == scene.contact.direction:
                new.__dict__.update({k: v for k, v in self.__dict__.items() if k in _DIRECTION_PARTS})
                if old.loads == scene.loads:
                    new.__dict__.update({k: v for k, v in self.__dict__.items() if k in _LOAD_PARTS})
        return new

    # ---- elastic part (mesh + material) ------------------------------------------------
    @cached_property
    def stiffness(self) -> sp.csr_matrix:
        a = elastic_form(self.fes, self.scene)
        a.Assemble()
        vals, cols, ptr = a.mat.CSR()
        n = self.fes.ndof
        K = sp.csr_matrix((np.array(vals), np.array(cols), np.array(ptr)), shape=(n, n))
        return _complete_symmetric(K)

    @cached_property
    def load(self) -> np.ndarray:
        """Load vector at unit time factor."""
        f = load_form(self.fes, self.scene)
        f.Assemble()
        return f.vec.FV().NumPy().copy()

    @cached_property
    def contact_dofs(self) -> np.ndarray:
        """The free DOFs the contact points see (sorted)."""
        dofs = np.unique(self.points.P.indices)
        return dofs[self.free[dofs]]

    @property
    def matrix_free(self) -> bool:
        """Whether the contact problem is solved matrix-free (see the class docstring)."""
        if self.contact_solve == "auto":
            size = len(self.contact_dofs)
            return size > DENSE_LIMIT or (size > SOFT_LIMIT and self.layer_ratio < 1.0)
        return self.contact_solve == "krylov"

    @cached_property
    def layer_ratio(self) -> float:
        """ρ = p'(g) t / E: the layer's stiffness against the body's (t its extent along ν, E Young's modulus).

        The Newton matrix of the contact problem is I + A diag(m p') on the points in contact, and the
        largest eigenvalue of A diag(m p') is of the order of ρ: for ρ < 1 a Krylov solve converges in a few
        products (from scratch: the brake pad, ρ = 0.12, about 11 per step; box3d, ρ = 2, about 35; with the
        products remembered across the run, ``numerics/recycle.py``: 0.5 and 22 per step).
        """
        lam, eta = self.scene.material.lame
        young = eta * (3 * lam + 2 * eta) / (lam + eta)
        contact = self.scene.contact
        e = contact.exponent if contact.law == "power" else 1.0
        heights = self.mesh.ngmesh.Coordinates() @ self.nu
        return contact.stiffness * e * contact.gap ** (e - 1) * np.ptp(heights) / young

    @cached_property
    def operator(self) -> ElasticOperator:
        """K's factorisation; for the dense contact solve with the Schur complement on the contact DOFs."""
        return ElasticOperator(self.stiffness, self.free, self.contact_dofs, schur=not self.matrix_free)

    @cached_property
    def u_load(self) -> np.ndarray:
        """K⁻¹ f at unit time factor."""
        return self.operator.solve(self.load)

    @cached_property
    def s_load(self) -> np.ndarray:
        return self.N @ self.u_load

    @cached_property
    def plate_modes(self) -> np.ndarray | None:
        """E: the rigid motions of the plate's boundary (None without a plate); see :mod:`ngwear.numerics.plate`."""
        plate = self.scene.loads.plate
        return None if plate is None else plate_modes(self.fes, plate.boundary, self.nu, plate.tilt)

    @cached_property
    def plate(self) -> PlateCoupling | None:
        """D, S, Φ, Ψ of the plate (None without a plate): one more back-substitution per mode."""
        if self.plate_modes is None:
            return None
        return PlateCoupling.of(self.plate_modes, self.stiffness, self.operator.solve, self.points.P, self.N)

    @property
    def plate_modes_count(self) -> int:
        """r: 0 without a plate, 1 for a plate that only translates, 2 (2D) or 3 (3D) with tilt."""
        return 0 if self.plate_modes is None else self.plate_modes.shape[1]

    @property
    def plate_force(self) -> np.ndarray:
        """F_B = (F·ν, 0, …): the plate force's work on the plate modes at unit time factor (tilts: no moment)."""
        force = np.zeros(self.plate_modes_count)
        if len(force):
            force[0] = float(np.dot(self.scene.loads.plate.force, self.nu))
        return force

    @cached_property
    def plate_load(self) -> np.ndarray:
        """f_B + F_B = Dᵀ f + F_B at unit time factor: the loads' and the plate force's work on the modes."""
        return np.zeros(0) if self.plate is None else self.plate.response.T @ self.load + self.plate_force

    @cached_property
    def rigid_translation(self) -> np.ndarray:
        """The translation u = ν of the whole body in the full-system path's coordinates x (u = T x)."""
        gf = ngs.GridFunction(self.fes)
        gf.Set(ngs.CF(tuple(self.nu)))
        rigid = np.zeros(self.full_basis.shape[1])
        rigid[:int(self.free.sum())] = gf.vec.FV().NumPy()[self.free]
        rigid[int(self.free.sum())] = 1.0
        return rigid

    @cached_property
    def full_basis(self) -> sp.csc_matrix:
        """T = [free DOFs | plate modes E]: the full-system path's unknowns are u = T x."""
        columns = sp.eye(self.fes.ndof, format="csc")[:, np.flatnonzero(self.free)]
        return sp.hstack([columns, sp.csc_matrix(self.plate_modes)] if self.plate_modes_count else [columns],
                         format="csc")

    @cached_property
    def normal_rows(self) -> np.ndarray:
        """R_ijb = ν·G_ij·e_b, shape (n, n, d): the ν rows of the point compliance G = P K⁻¹ Pᵀ.

        Only these enter the contact law, so G (n d × n d) is never formed: R = (P_c S⁻¹ N_cᵀ)ᵀ, one
        solve with the Schur complement's Cholesky factor for the n columns N_cᵀ (n_c² n flops).
        """
        op, P = self.operator, self.points.P
        columns = op.contact_solve(self.N[:, op.contact_dofs].T.toarray())
        n, d = self.points.n, self.scene.dim
        return np.ascontiguousarray((P[:, op.contact_dofs] @ columns).T).reshape(n, n, d)

    @cached_property
    def normal_compliance(self) -> np.ndarray:
        """H = ν·G·ν."""
        return self.normal_rows @ self.nu

    def friction_compliance(self, n_star: np.ndarray) -> np.ndarray:
        """F_ij = ν·G_ij·n*_j: normal displacement at x_i per unit tangential force along n*_j at x_j."""
        return np.einsum("ijb,jb->ij", self.normal_rows, n_star)

    def normal_response(self, normal: np.ndarray, directed: np.ndarray, directions: np.ndarray) -> np.ndarray:
        """ν·u(x_i) under the point forces f_j = normal_j ν + directed_j b_j: H normal + A directed, matrix-free.

        One back-substitution, u = K⁻¹ Pᵀ f; with b_j = ν + μ n*_j it is the product with A = H + μ F.
        """
        forces = normal[:, None] * self.nu[None, :] + directed[:, None] * directions
        return self.N @ self.operator.solve(self.points.P.T @ forces.ravel())

    @cached_property
    def compliance_estimate(self) -> np.ndarray:
        """h_i = 1/(ν·K_ii·ν) ≤ H_ii, the point's compliance with its neighbours held (no solve needed)."""
        stiffness = self.N.multiply(self.N) @ np.where(self.free, self.stiffness.diagonal(), 0.0)
        return np.divide(1.0, stiffness, out=np.zeros_like(stiffness), where=stiffness > 0)

    # ---- time-dependent data -----------------------------------------------------------
    def load_factor(self, t: float) -> float:
        return piecewise_linear(self.scene.loads.time_table, t)

    def velocity(self, t: float) -> np.ndarray:
        """v*(x_i, t) at the contact points, shape (n, d)."""
        return self.slip.velocity(t)

    def largest_alpha(self) -> float:
        """Largest α = κ ‖v*‖ over the contact points and the speed table's nodes (s_v is piecewise linear)."""
        factors = [abs(f) for _, f in self.scene.foundation.speed_table] or [1.0]
        return self.scene.contact.wear * float(self.slip.speed.max(initial=0.0)) * max(factors)

    def alpha(self, t: float) -> np.ndarray:
        """α_i(t) = κ ‖v*(x_i, t)‖ (0 where the foundation does not slide)."""
        return self.scene.contact.wear * self.slip.speeds(t)

    def n_star(self, t: float) -> np.ndarray:
        """n*_i(t) = −v*_τ/‖v*_τ‖ at the contact points, shape (n, d) (0 where the foundation does not slide)."""
        return self.slip.n_star(t)

    def contact_forces(self, pressure, reaction, t: float) -> np.ndarray:
        """Point forces on the foundation side, f_i = m_i (p_i (ν + μ n*_i) + λ_i ν), shape (n, d)."""
        m, mu = self.points.weights, self.scene.contact.friction
        b = self.nu[None, :] + mu * self.n_star(t)
        return m[:, None] * (pressure[:, None] * b + reaction[:, None] * self.nu[None, :])

    def recover(self, forces: np.ndarray, t: float, plate: np.ndarray) -> np.ndarray:
        """Displacement DOF vector u = s_F(t) K⁻¹ f + D δ − K⁻¹ Pᵀ f_c (one back-substitution)."""
        u = self.load_factor(t) * self.u_load - self.operator.solve(self.points.P.T @ forces.ravel())
        return u if self.plate is None else u + self.plate.response @ plate

    @cached_property
    def _in_body(self) -> np.ndarray:
        return np.array([el.mat == "body" for el in self.mesh.Elements(ngs.VOL)])

    def locate(self, points: np.ndarray):
        """NGSolve mesh points of reference points in the body (Γ_C points are taken from the body side)."""
        points = np.asarray(points, dtype=float)
        mips = self.mesh(*points.T)
        outside = (mips["nr"] < 0) | ~self._in_body[np.maximum(mips["nr"], 0)]
        for nudge in (1e-8, 1e-6, 1e-4):
            if not outside.any():
                break
            again = self.mesh(*(points[outside] - nudge * self.scene.mesh.maxh * self.nu).T)
            found = (again["nr"] >= 0) & self._in_body[np.maximum(again["nr"], 0)]
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

    @cached_property
    def full_form(self):
        """Elastic + contact terms as one NGSolve form (for the full-system reference path)."""
        cf = contact_form(self.fes, self.scene, self.law, with_elastic=True)
        cf.d0.vec.FV().NumPy()[:] = self.points.Q @ self.d0
        return cf

    def set_nodal(self, gf: ngs.GridFunction, values: np.ndarray) -> None:
        """A scalar GridFunction of the contact form's space with the given values at the contact points."""
        gf.vec.FV().NumPy()[:] = self.points.Q @ values


_MESH_PARTS = ("mesh", "fes", "free", "points", "contact_dofs", "_in_body", "plate_modes", "full_basis")
_MATERIAL_PARTS = ("stiffness", "operator", "plate")
_DIRECTION_PARTS = ("normal_rows", "normal_compliance", "compliance_estimate")
_LOAD_PARTS = ("load", "u_load", "s_load", "plate_load")


def _complete_symmetric(K: sp.csr_matrix) -> sp.csr_matrix:
    """Both triangles of K, whether NGSolve handed back one triangle or the whole matrix."""
    upper, lower = sp.triu(K, 1), sp.tril(K, -1)
    if upper.nnz == 0 and lower.nnz:
        return (K + lower.T).tocsr()
    if lower.nnz == 0 and upper.nnz:
        return (K + upper.T).tocsr()
    return K
