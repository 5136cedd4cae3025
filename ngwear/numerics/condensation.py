"""A discretization's condensation onto Γ_C and its loads (the pieces of levels ``DIRECTION`` and ``LOADS``).

:class:`Condensation`: ν, the normal evaluation N = ν·P, the initial distance d₀, the rows ν·G of the contact
compliance, the rigid plate's modes and coupling, the strain estimate's segments; :class:`Loads`: the load vector f
and K⁻¹f at unit time factor.
"""
from __future__ import annotations

from functools import cached_property

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from ..model.scene import Scene
from .body import Body, Lazy
from .elastic import Elastic
from .forms import load_form
from .plate import PlateCoupling, plate_modes
from .points import initial_distance
from .strain import Segments, segments


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
