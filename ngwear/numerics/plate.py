"""A rigid plate on the boundary B, pressed by a force: its modes and their condensation.

B moves rigidly, u = Σ_k δ_k e_k on B, with e_1 = ν (the translation along the contact direction)
and, when the plate tilts, e_{1+l}(x) = ((a_l × (x − x_B))·ν) ν for the axes a_l ⟂ ν through the
centroid x_B of B (two in 3D, e_z in 2D); tangentially B is held.  The factorisation clamps B
(K_ZZ, invertible without other Dirichlet data), and the plate enters the contact problem through

    D = E − K_ZZ⁻¹ K_ZE       the body's response to unit plate motions (DOF vectors, one per mode),
    S = Eᵀ K D                the plate's stiffness through the body (0 for a body held by the plate only),
    Φ = P D,  Ψ = ν·Φ         displacement and normal displacement at the contact points per unit mode,
    f_B = Dᵀ f                the work of the body's loads on the modes,

so that u = s_F(t) K_ZZ⁻¹ f + D δ − K_ZZ⁻¹ Pᵀ f_c and the plate's force balance reads

    S δ + Σ_i m_i (p_i b_i·Φ_i + λ_i Ψ_i) = s_F(t) (f_B + F_B),   b_i = ν + μ n*_i,   F_B = (F·ν, 0, 0):

the plate force and the loads are carried by the contact; the tilts have zero moment.
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np


def plate_modes(fes: ngs.FESpace, boundary: str, nu: np.ndarray, tilt: bool) -> np.ndarray:
    """E (ndof × r): the DOF vectors of the plate's rigid motions e_k (zero off B)."""
    mesh, dim = fes.mesh, len(nu)
    region = mesh.Boundaries(boundary)
    coords = (ngs.x, ngs.y, ngs.z)[:dim]
    arm = [x - c for x, c in zip(coords, centroid(mesh, boundary))]
    normal = [ngs.CF(1.0)]
    if tilt:
        for axis in _tilt_axes(nu):
            # (a × r)·ν = a·(r × ν)
            if dim == 2:
                normal.append(-arm[1] * nu[0] + arm[0] * nu[1])
            else:
                r_x_nu = (arm[1] * nu[2] - arm[2] * nu[1], arm[2] * nu[0] - arm[0] * nu[2],
                          arm[0] * nu[1] - arm[1] * nu[0])
                normal.append(sum(a * c for a, c in zip(axis, r_x_nu)))
    modes = np.zeros((fes.ndof, len(normal)))
    gf = ngs.GridFunction(fes)
    for k, phi in enumerate(normal):
        gf.vec[:] = 0.0
        gf.Set(ngs.CF(tuple(phi * float(c) for c in nu)), ngs.BND, definedon=region)
        modes[:, k] = gf.vec.FV().NumPy()
    return modes


def centroid(mesh: ngs.Mesh, boundary: str) -> np.ndarray:
    """x_B: the centroid of the boundary B."""
    area = ngs.Integrate(ngs.CF(1.0) * ngs.ds(boundary), mesh)
    return np.array([ngs.Integrate(x * ngs.ds(boundary), mesh) / area for x in (ngs.x, ngs.y, ngs.z)[:mesh.dim]])


def rigid_normal(mesh: ngs.Mesh, boundary: str, nu: np.ndarray, tilt: bool, points: np.ndarray) -> np.ndarray:
    """ν·e_k(x_i) (n × r): the plate's rigid motions continued to points x_i off B (1; (a_l × (x_i − x_B))·ν)."""
    columns = [np.ones(len(points))]
    if tilt:
        arm = points - centroid(mesh, boundary)
        if len(nu) == 2:
            columns.append(-arm[:, 1] * nu[0] + arm[:, 0] * nu[1])
        else:
            columns += [np.cross(arm, nu) @ axis for axis in _tilt_axes(nu)]
    return np.column_stack(columns)


def _tilt_axes(nu: np.ndarray) -> list[np.ndarray]:
    """Axes of the plate's tilts: e_z in 2D; two orthonormal vectors ⟂ ν in 3D."""
    if len(nu) == 2:
        return [np.array([0.0, 0.0, 1.0])]
    helper = np.eye(3)[np.argmin(np.abs(nu))]
    first = np.cross(nu, helper)
    first /= np.linalg.norm(first)
    return [first, np.cross(nu, first)]


@dataclass(frozen=True)
class PlateCoupling:
    """D, S, Φ, Ψ of the module docstring for one mesh, material and plate."""

    response: np.ndarray      # D, (ndof × r)
    stiffness: np.ndarray     # S, (r × r)
    at_points: np.ndarray     # Φ, (n × d × r)
    normal: np.ndarray        # Ψ, (n × r)

    @property
    def modes(self) -> int:
        return self.stiffness.shape[0]

    @classmethod
    def of(cls, modes: np.ndarray, stiffness_matrix, solve, P, N) -> PlateCoupling:
        """From E, the full stiffness K, the clamped solve z ↦ K_ZZ⁻¹ z and the point maps P, N."""
        K_E = stiffness_matrix @ modes
        response = modes - solve(K_E)
        n = N.shape[0]
        return cls(response, modes.T @ (stiffness_matrix @ response),
                   (P @ response).reshape(n, -1, modes.shape[1]), N @ response)

    def directed(self, directions: np.ndarray) -> np.ndarray:
        """b_i·Φ_i per mode, shape (n × r), for force directions b_i (n × d)."""
        return np.einsum("idk,id->ik", self.at_points, directions)
