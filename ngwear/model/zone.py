"""Local refinement of Γ_C: ``mesh.contact_maxh`` within ``mesh.contact_zone`` of ``mesh.zone_center``.

The zone is the part of Γ_C whose projection on the foundation's plane lies within ρ = ``mesh.contact_zone`` of
the centre c: |P(x − c)| ≤ ρ with P = I − ν νᵀ (for the half-disk, its horizontal half-width).  Its default centre
is the part's first point of contact, where Γ_C comes nearest the foundation (the largest x·ν): the middle of the
region that touches first on a flat face (the pad's centre), the tip of a curved one (the sphere-ended pin's axis,
the half-disk's lowest point).

Netgen's local mesh size is held to h = ``mesh.contact_maxh`` at points of Γ_C in the zone h/2 apart
(``MeshingParameters.RestrictH``); Netgen's grading lets the size grow away from them by the factor 1 +
``mesh.grading`` per element, on Γ_C and into the body alike: the refinement fades out smoothly.  The shape is left
as it is (no face is split, no name changes), so CAD parts refine as the built-in kinds do.  The points of Γ_C
come from its OpenCASCADE shape: along its edges in 2D; in 3D from a surface mesh of its faces alone (cheap: a few
thousand triangles, of size h at the centre, growing slowly away from it), whose triangles are subdivided to
spacing h/2 in the zone.  Points off a curved face by more than a fraction of h would hold the wrong octree cells
of Netgen's local size: the triangles' chord error stays small (see :func:`sample`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import netgen.meshing as nm
import numpy as np
from netgen.occ import OCCGeometry

from .keys import SceneError
from .kinds import KINDS


def radius(geometry, mesh) -> float | None:
    """ρ, the zone's radius: ``mesh.contact_zone``, else the kind's default (R/4 for the half-disk); None: no zone.

    There is a zone only with ``mesh.contact_maxh`` (the size within it).
    """
    if mesh.contact_maxh is None:
        return None
    if mesh.contact_zone is not None:
        return mesh.contact_zone
    default = KINDS[geometry.kind].zone
    return None if default is None else default(geometry.size)


@dataclass(frozen=True)
class Sample:
    """Points of Γ_C and its cells between them: segments (2D) or triangles (3D), as indices into ``points``."""

    points: np.ndarray
    cells: np.ndarray

    @property
    def measures(self) -> np.ndarray:
        """Each cell's length or area."""
        corners = self.points[self.cells]
        if self.cells.shape[1] == 2:
            return np.linalg.norm(corners[:, 1] - corners[:, 0], axis=1)
        return 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)


def sample(shape, dim: int, size: float, seed=None, finest: float | None = None) -> Sample:
    """Γ_C (the shape's edges or faces named ``contact``) as cells of about ``size``; of ``finest`` at ``seed``.

    2D: points along the edges, exactly on them, ``finest``/2 apart if given.  3D: a surface mesh of the faces alone,
    its size ``finest`` at ``seed`` growing slowly (grading 0.1) away from it: its triangles stay within
    (finest + 0.1 r)² / 8R of a face of curvature radius R at a distance r from the seed, a small part of h.
    """
    contact = [part for part in (shape.edges if dim == 2 else shape.faces) if part.name == "contact"]
    if dim == 2:
        return _edges(contact, finest / 2 if finest else size)
    points, cells = [], []
    for face in contact:
        parameters = nm.MeshingParameters(maxh=size, grading=0.1, perfstepsend=nm.MeshingStep.MESHSURFACE)
        if seed is not None:
            parameters.RestrictH(*seed, finest)
        surface = OCCGeometry(face).GenerateMesh(parameters)
        cells.append(np.array([[v.nr - 1 for v in el.vertices] for el in surface.Elements2D()]) + len(points))
        points += [tuple(p.p) for p in surface.Points()]
    return Sample(np.array(points), np.vstack(cells))


def _edges(edges, size: float) -> Sample:
    """Points along 2D contact edges at spacing about ``size`` (their parameters evenly spaced), and the segments."""
    points, cells = [], []
    for edge in edges:
        start, end = edge.parameter_interval
        count = max(8, math.ceil(edge.mass / size))
        cells += [(len(points) + k, len(points) + k + 1) for k in range(count)]
        points += [(p.x, p.y, p.z) for p in map(edge.Value, np.linspace(start, end, count + 1))]
    return Sample(np.array(points), np.array(cells))


def first_contact(part: Sample, nu: np.ndarray, extent: float) -> np.ndarray:
    """Where Γ_C first touches the foundation: the centroid of the cells at the largest x·ν, else the point there.

    A flat face touches all at once: the centroid of its cells (the pad's centre); a curved one at a point (the tip).
    """
    height = part.points @ nu
    top = height.max() - 1e-6 * extent
    touching = np.all(height[part.cells] >= top, axis=1)
    if touching.any():
        weights = part.measures[touching]
        return (part.points[part.cells[touching]].mean(axis=1) * weights[:, None]).sum(axis=0) / weights.sum()
    return part.points[np.argmax(height)]


def across(points: np.ndarray, center: np.ndarray, nu: np.ndarray) -> np.ndarray:
    """|P(x − c)|, P = I − ν νᵀ: the distance from the centre measured across ν (in the foundation's plane)."""
    return np.linalg.norm((points - center) @ (np.eye(3) - np.outer(nu, nu)), axis=-1)


def zone_points(part: Sample, center: np.ndarray, rho: float, nu: np.ndarray, spacing: float) -> np.ndarray:
    """Points of Γ_C whose projection along ν lies within ρ of the centre's, no farther apart than ``spacing``.

    The cells that reach into the zone are subdivided evenly (barycentric grids of ``n`` parts per side).
    """
    def inside(points, margin=0.0):
        return across(points, center, nu) <= rho + margin

    corners = part.points[part.cells]
    sides = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=-1).max(axis=1)
    near = inside(corners.mean(axis=1), sides)
    corners, parts = corners[near], np.maximum(1, np.ceil(sides[near] / spacing)).astype(int)
    points = []
    for n in np.unique(parts):
        grid = np.array([(i, j) for i in range(n + 1) for j in range(n + 1 - i)] if part.cells.shape[1] == 3 else
                        [(i, 0) for i in range(n + 1)]) / n
        some = corners[parts == n]
        edges = some[:, 1:] - some[:, :1]
        points.append((some[:, None, 0] + np.einsum("gk,ckd->cgd", grid[:, :edges.shape[1]], edges)).reshape(-1, 3))
    points = np.vstack(points) if points else np.zeros((0, 3))
    return points[inside(points)]


def restrict(parameters, shape, g, m, direction) -> int:
    """Hold Netgen's local mesh size to ``mesh.contact_maxh`` in the zone; the number of points held.

    ``g``, ``m`` are the scene's geometry and mesh sections, ``direction`` its ``contact.direction``.  Raises
    SceneError when the zone holds no point of Γ_C (a ``mesh.zone_center`` away from the part).
    """
    rho, h = radius(g, m), m.contact_maxh
    nu = np.zeros(3)
    nu[:g.dim] = direction
    center = None if m.zone_center is None else np.pad(np.asarray(m.zone_center, float), (0, 3 - g.dim))
    coarse = sample(shape, g.dim, m.maxh)
    if center is None:
        center = first_contact(coarse, nu, g.extent)
    seed = coarse.points[np.argmin(across(coarse.points, center, nu))]       # on Γ_C, nearest the centre
    part = sample(shape, g.dim, min(m.maxh, 2 * rho), seed, h)
    if m.zone_center is None:
        center = first_contact(part, nu, g.extent)
    points = zone_points(part, center, rho, nu, h / 2)
    if not len(points):
        raise SceneError(f"mesh.zone_center: no point of Γ_C within mesh.contact_zone = {rho:g} of "
                         f"({', '.join(f'{c:g}' for c in center[:g.dim])}) (measured across contact.direction)")
    for point in points:
        parameters.RestrictH(*point, h)
    return len(points)
