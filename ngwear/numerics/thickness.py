"""The thickness of the worn region under each contact point, along the contact direction, measured on the mesh.

From a contact point x_i the ray x_i − t ν (t > 0) runs into the region that carries Γ_C (the friction material
of a pad, the body of a part without backing); its thickness there is the t at which the ray first leaves that
region: through the interface to a backing, the back face, or a side.  The region's boundary is every facet of
its elements that no other of its elements shares, and of them the ray can leave through those facing −ν
(:data:`FACING`); projected onto the plane ⟂ ν, a facet the ray crosses holds the point's projection, and the ray
meets it at the height interpolated from its vertices'.  Measured once, on
the mesh as built: the remaining thickness is this minus the accumulated wear.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .topology import coordinates, facets, lone_facets, simplices

FACING = 0.5
"""The facets a ray along −ν may leave through: those whose outward unit normal n has −n·ν at least this (within
60° of −ν).  The sides of a pad or a pin, parallel to ν, are not among them (a ray from the rim of Γ_C runs along
them), nor Γ_C, a chamfer or the ceiling of a slot (the ray enters the region through them)."""
INSIDE = 1e-9
"""Barycentric coordinates down to −INSIDE count as inside a projected facet (a point on its edge)."""
OUTSIDE = 0.5
"""A ray that crosses no facet (from a curved rim: outside the chords of the facets above it by their sagitta)
leaves through the nearest, its barycentric coordinates clipped, if it is within this of it."""


def thickness(mesh, points: np.ndarray, nu) -> np.ndarray:
    """The thickness along −ν of the region that carries Γ_C under each point of Γ_C (points: n × d).

    Raises
    ------
    ValueError
        A ray finds no way out of the region (a point not on Γ_C).
    """
    nu = np.asarray(nu, dtype=float)
    coords = coordinates(mesh)
    nodes, regions = simplices(mesh)
    faces, names = facets(mesh)
    carrying = np.unique(regions[np.isin(nodes, faces[names == "contact"]).any(axis=1)])
    boundary, inner = lone_facets(nodes[np.isin(regions, carrying)])
    plane = np.linalg.svd(nu[None, :])[2][1:]                       # an orthonormal basis of the plane ⟂ ν
    flat, height = coords @ plane.T, -(coords @ nu)
    corners = flat[boundary]                                        # m × d × (d − 1)
    edges = np.swapaxes(corners[:, 1:] - corners[:, :1], 1, 2)      # m × (d − 1) × (d − 1)
    spans = coords[boundary[:, 1:]] - coords[boundary[:, :1]]
    normal = np.cross(*np.moveaxis(spans, 1, 0)) if len(nu) == 3 else spans[:, 0] @ np.array([[0.0, 1.0], [-1.0, 0.0]])
    outward = np.sign(np.einsum("kd,kd->k", normal, coords[boundary].mean(axis=1) - coords[inner]))
    keep = -outward * (normal @ nu) >= FACING * np.linalg.norm(normal, axis=1)      # leaving the region along −ν
    corners, edges, heights = corners[keep], edges[keep], height[boundary[keep]]
    inverse = np.linalg.inv(edges)
    centres = corners.mean(axis=1)
    reach = np.linalg.norm(corners - centres[:, None], axis=2).max()
    tree = cKDTree(centres)
    start = np.asarray(points, dtype=float)
    out = np.empty(len(start))
    scale = np.ptp(height)
    for i, (q, h) in enumerate(zip(start @ plane.T, -(start @ nu))):
        near = np.array(tree.query_ball_point(q, reach * (1 + 1e-9)), dtype=int)
        lam = np.einsum("kij,kj->ki", inverse[near], q - corners[near, 0])
        lam = np.column_stack([1 - lam.sum(axis=1), lam])
        outside = np.maximum(-lam.min(axis=1), 0.0)
        clipped = np.maximum(lam, 0.0) / np.maximum(lam, 0.0).sum(axis=1, keepdims=True)
        t = np.einsum("ki,ki->k", clipped, heights[near]) - h
        ahead = t >= -1e-9 * scale
        if not (ahead & (outside < OUTSIDE)).any():
            raise ValueError(f"points: the ray from {start[i].tolist()} along −ν never leaves the worn region")
        inside = ahead & (outside <= INSIDE)
        out[i] = t[inside].min() if inside.any() else t[ahead][np.argmin(outside[ahead])]
    return np.maximum(out, 0.0)
