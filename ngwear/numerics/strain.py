"""A cheap lower bound of the body's largest strain, from the contact points' normal displacements and the supports.

The small-strain model holds while the strains are small.  Recovering u at every step to look at them would cost a
back-substitution per step; the normal displacements s_i = ν·u(x_i) and the plate's motion δ, which every step has
anyway, bound them from below.  From a contact point x_i the segment x_i − t ν, 0 ≤ t ≤ ℓ_i, runs through the body
until it leaves it at y_i.  Where it leaves through a support (a clamped boundary, u = 0, or the rigid plate B,
u = r(y) = Σ_m δ_m e_m(y), :mod:`ngwear.numerics.plate`), along the segment ν·∇u·ν = ε_νν (the skew part of ∇u
has no diagonal), so

    s_i − ν·r(y_i) = ∫₀^ℓᵢ ε_νν(x_i − t ν) dt,      ε̂ = max_i |s_i − ν·r(x_i)| / ℓ_i ≤ max |ε_νν| ≤ max ‖ε‖₂,

with ν·r(y_i) = ν·r(x_i), a rigid motion's normal part being the same all along a segment along ν.  It holds for
the discrete field u_h exactly (it is continuous); ε̂ is the mean strain across the part along ν, the largest over
the contact points.  Rigid motions give ε̂ = 0 (a floating body moving with its plate, s_i = ν·r(x_i), or tilting
with it); so does the layer's compression z − w, which is no strain of the body.  Contact points whose segment
leaves the body elsewhere (a strip clamped on its side) add nothing: bending there is mostly rotation, which ε̂
does not confuse with strain.

The segments are cast once per mesh, on the straight facets of the boundary (:func:`segments`); a step then costs
O(n).
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
from scipy.spatial import cKDTree

from . import topology
from .plate import rigid_normal

CLEAR = 1e-9
"""Relative to the body's size: how far along the segment a facet must be (those through x_i itself are not)."""


@dataclass(frozen=True)
class Segments:
    """ℓ_i of the contact points whose segment along −ν leaves the body through a support (inf elsewhere).

    ``plate_normal`` (n × r): ν·e_m(x_i), the plate's rigid motions at the points, for the points whose segment
    ends on the plate (rows of zeros elsewhere: a clamped support does not move); None without a plate.
    """

    lengths: np.ndarray
    plate_normal: np.ndarray | None

    @property
    def reach(self) -> float:
        """The share of the contact points whose segment ends on a support (ε̂ sees the strain across them)."""
        return float(np.isfinite(self.lengths).mean()) if len(self.lengths) else 0.0

    def estimate(self, s: np.ndarray, delta: np.ndarray):
        """ε̂ of the module docstring for the normal displacements s (n) and the plate's δ (r): O(n).

        Rows of them (m × n and m × r): ε̂ of each row.
        """
        moved = s if self.plate_normal is None else s - delta @ self.plate_normal.T
        return np.max(np.abs(moved) / self.lengths, axis=-1, initial=0.0)


def segments(scene, mesh: ngs.Mesh, coords: np.ndarray, facets: np.ndarray | None = None) -> Segments:
    """Cast the segments from the contact points ``coords`` along −ν through the body of ``mesh`` (no solve).

    ``facets``: the mesh's outer facets (:func:`outer_facets`), if known.
    """
    nu = np.asarray(scene.contact.direction, dtype=float)
    plate = scene.loads.plate
    vertices = topology.coordinates(mesh)
    facets = outer_facets(mesh) if facets is None else facets
    faces, names = topology.facets(mesh)
    on = {name: {tuple(face) for face in np.sort(faces[names == name], axis=1).tolist()}
          for name in (*scene.geometry.dirichlet, *((plate.boundary,) if plate else ()))}
    label_of = {face: k for k, faces in enumerate(on.values()) for face in faces}
    labels = np.array([label_of.get(tuple(face), -1) for face in facets.tolist()], dtype=int)
    i, f, t = _hits(vertices, facets, coords, -nu)
    first = np.full(len(coords), np.inf)
    np.minimum.at(first, i, t)
    leaving = t <= first[i] + CLEAR * float(np.ptp(vertices, axis=0).max())   # a ray through an edge: either facet
    support = np.full(len(coords), -1)
    np.maximum.at(support, i[leaving], labels[f[leaving]])
    lengths = np.where(support >= 0, first, np.inf)
    normal = None
    if plate is not None:
        on_plate = support == len(on) - 1
        normal = rigid_normal(mesh, plate.boundary, nu, plate.tilt, coords) * on_plate[:, None]
    return Segments(lengths, normal)


def outer_facets(mesh: ngs.Mesh) -> np.ndarray:
    """The facets (sorted vertex numbers from 0) of the body's outer boundary: those of one volume element only.

    (Not Netgen's surface elements: an imported Gmsh mesh's face descriptors carry no domains, and a boundary with
    no physical group has none.)  The vertices' positions do not enter: a moved body keeps them (``Body``).
    """
    return topology.lone_facets(topology.simplices(mesh)[0])[0]


def _hits(vertices: np.ndarray, facets: np.ndarray, points: np.ndarray, direction: np.ndarray):
    """(i, f, t): the rays x_i + t d, t > 0, cross facet f at t (straight facets; those along d by no ray)."""
    dim = len(direction)
    basis = np.linalg.svd(direction[None, :])[2][1:]                 # dim − 1 unit vectors ⟂ d
    corners = vertices[facets]                                       # facets × dim × dim
    flat, height = corners @ basis.T, corners @ direction            # in the plane ⟂ d; along d
    low, high = flat.min(axis=1), flat.max(axis=1)
    size = float(np.ptp(vertices, axis=0).max())
    radius = float(np.linalg.norm(high - low, axis=1).max()) / 2 + CLEAR * size
    projected = points @ basis.T
    near = cKDTree((low + high) / 2).query_ball_point(projected, radius)
    i = np.repeat(np.arange(len(points)), [len(n) for n in near])
    f = np.fromiter((k for n in near for k in n), dtype=np.int64, count=len(i))
    edges = np.swapaxes(flat[f, 1:] - flat[f, :1], 1, 2)            # pairs × (dim − 1) × (dim − 1)
    upright = np.abs(np.linalg.det(edges)) > 1e-12 * size ** (dim - 1)
    i, f, edges = i[upright], f[upright], edges[upright]
    weights = np.linalg.solve(edges, (projected[i] - flat[f, 0])[..., None])[..., 0]
    weights = np.column_stack([1 - weights.sum(axis=1), weights])    # barycentric in the projected facet
    t = np.einsum("pk,pk->p", weights, height[f]) - points[i] @ direction
    hit = (weights.min(axis=1) >= -1e-9) & (t > CLEAR * size)
    return i[hit], f[hit], t[hit]
