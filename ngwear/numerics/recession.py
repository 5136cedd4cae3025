"""Wear that removes material: the body's mesh moved by the accumulated wear of Γ_C, its quality, and a remesh.

The accumulated wear W (one value per vertex of Γ_C) moves the vertices of the regions that carry Γ_C from
their reference positions X₀ (the mesh as built, or as last remeshed) along −ν, into the body:

    X = X₀ − φ ν,    −div(∇φ) = 0 in Ω_w,   φ = W on Γ_C,   φ = 0 on the held faces,   ∂φ/∂n = 0 on the others,

Ω_w the regions that carry Γ_C.  A face is held unless it is parallel to ν (|n·ν| ≤ :data:`PARALLEL` on average): the sides
of a pad or a pin slide along themselves, while the back, a plate's face and the interface to a backing stay
where they are, as every vertex of the other regions does.  Every vertex moves along ν only, so a face parallel to
ν keeps its vertices (the part keeps its shape but for the worn layer), and the vector Laplace (harmonic)
extension reduces to one scalar problem, its matrix factorised once per reference mesh: an update is one
back-substitution, and X is a function of W alone (a resumed run recomputes it to the bit).  With P1 φ the map
X₀ ↦ X is affine on each element, J = I − ν ⊗ ∇φ, det J = 1 − ν·∇φ: an element stays valid while ν·∇φ < 1, and
over a worn region of thickness H the harmonic φ keeps ν·∇φ near W/H everywhere, the least any extension can
(benchmarks/motion.py compares it with a stiffened one and with an elastic extension).

:func:`quality` measures the elements (mean ratio, volume against the reference); below :data:`QUALITY` the body
is remeshed from its worn geometry (:func:`remeshed`: in 3D the part's solids cut by a B-spline surface through the
worn Γ_C, in 2D the moved boundary, meshed anew by Netgen), or the run stops with :attr:`Quality.reason`.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from .pardiso import Pardiso
from .topology import coordinates, facets, keys, place, signed_volumes, simplices

PARALLEL = 0.05
"""A boundary whose unit normal n has |n·ν| at most this on average (sin 3°) is parallel to ν: its vertices slide
along it (by up to this fraction of the wear off a face drafted so much)."""
QUALITY = 0.1
"""The smallest mean ratio of an element a moved mesh may keep (1: a regular simplex; see :func:`quality`)."""


def tilted(coords: np.ndarray, faces: np.ndarray, names: np.ndarray, nu: np.ndarray) -> tuple[str, ...]:
    """The boundaries but Γ_C that are not parallel to ν: their mean |n·ν| over their area exceeds :data:`PARALLEL`.

    The mean over a boundary, not each facet: a facet of a curved face parallel to ν (a cylinder's chord) tilts by
    up to h/R, while the face, and a vertex moved along ν on it, does not.
    """
    edges = coords[faces[:, 1:]] - coords[faces[:, :1]]
    if coords.shape[1] == 2:
        normal = np.column_stack([-edges[:, 0, 1], edges[:, 0, 0]])            # |normal| = the segment's length
    else:
        normal = 0.5 * np.cross(edges[:, 0], edges[:, 1])                       # |normal| = the triangle's area
    area = np.linalg.norm(normal, axis=1)
    return tuple(str(name) for name in np.unique(names) if name != "contact" and
                 np.abs(normal[names == name] @ nu).sum() > PARALLEL * area[names == name].sum())


class Extension:
    """The harmonic extension φ of Γ_C's wear into the regions that carry it, on the mesh as it is now (X₀).

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The body; its present vertices are the reference X₀ of every later move.
    nu : array_like
        ν, the contact direction.
    held : tuple of str
        Boundaries held besides those not parallel to ν (e.g. a plate's face).
    """

    def __init__(self, mesh: ngs.Mesh, nu, held: tuple[str, ...] = ()):
        self.mesh, self.nu = mesh, np.asarray(nu, dtype=float)
        self.reference = coordinates(mesh)
        nodes, regions = simplices(mesh)
        faces, names = facets(mesh)
        carrying = np.unique(regions[np.isin(nodes, faces[names == "contact"]).any(axis=1)])
        self.contact = np.unique(faces[names == "contact"])
        moving = np.zeros(mesh.nv, bool)
        moving[nodes[np.isin(regions, carrying)]] = True
        fixed = np.zeros(mesh.nv, bool)
        fixed[faces[np.isin(names, held + tilted(self.reference, faces, names, self.nu))]] = True
        self.free = np.flatnonzero(moving & ~fixed & ~np.isin(np.arange(mesh.nv), self.contact))
        touched = np.isin(nodes, np.concatenate([self.free, self.contact])).any(axis=1)
        self.regions = tuple(mesh.GetMaterials()[r] for r in np.unique(regions[touched]))
        """The regions whose elements a move changes: those with a vertex that may move."""
        laplacian = _laplacian(mesh, [mesh.GetMaterials()[r] for r in carrying])
        self._coupling = laplacian[self.free][:, self.contact]
        self._factor = Pardiso(laplacian[self.free][:, self.free]) if len(self.free) else None

    def __call__(self, wear: np.ndarray) -> np.ndarray:
        """φ at every vertex (nv,) for W at the vertices of Γ_C (:attr:`contact`, in that order)."""
        phi = np.zeros(self.mesh.nv)
        phi[self.contact] = wear
        if self._factor is not None:
            phi[self.free] = -self._factor.solve(self._coupling @ wear)
        return phi

    def moved(self, wear: np.ndarray) -> np.ndarray:
        """X = X₀ − φ ν for W at the vertices of Γ_C (nv × d)."""
        return self.reference - np.outer(self(wear), self.nu)


class Recession:
    """A body's mesh as its accumulated wear moves it: the wear at Γ_C's vertices, the moves, their quality.

    The wear since the last update is nodal at the contact points (``points``, a
    :class:`~ngwear.numerics.forms.ContactPoints`); the mesh is straight-sided, so a move realises it at the
    vertices of Γ_C and, in between, their linear interpolation.  A vertex takes the least wear of the points at it
    (its own, and P2's midpoints of its edges on Γ_C): the interpolation then never exceeds a point's wear, and
    what a point keeps (P2: up to h |∇w| of it) stays in the layer, w ≥ 0, for the next update.  P1: the whole.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The body as built (or as last remeshed): the reference of the moves.
    points : ContactPoints
        Its contact points.
    nu : array_like
        ν.
    held : tuple of str
        Boundaries held besides those not parallel to ν.
    """

    def __init__(self, mesh: ngs.Mesh, points, nu, held: tuple[str, ...] = ()):
        self.mesh, self.extension = mesh, Extension(mesh, nu, held)
        self.nodes = simplices(mesh)[0]
        contact = self.extension.contact
        column = {int(v): j for j, v in enumerate(contact)}
        rows, cols = [], []
        for i, (vertex, edge) in enumerate(zip(points.vertices, points.edges)):
            ends = [int(vertex)] if vertex >= 0 else [v.nr for v in mesh[ngs.NodeId(ngs.EDGE, int(edge))].vertices]
            rows += [i] * len(ends)
            cols += [column[end] for end in ends]
        rows, cols = np.array(rows), np.array(cols)
        self.scatter = sp.csr_matrix((1.0 / np.bincount(rows)[rows], (rows, cols)),
                                     shape=(points.n, len(contact)))            # points ← vertices: interpolation
        order = np.argsort(cols, kind="stable")
        self._incident, self._starts = rows[order], np.searchsorted(cols[order], np.arange(len(contact)))
        self._own = np.empty(len(contact), dtype=int)                           # the point at each vertex
        own = np.flatnonzero(np.asarray(points.vertices) >= 0)
        self._own[[column[int(v)] for v in np.asarray(points.vertices)[own]]] = own
        self.wear = np.zeros(len(contact))                                      # W at Γ_C's vertices, since X₀

    @classmethod
    def resumed(cls, mesh: ngs.Mesh, points, nu, held: tuple[str, ...], reference: np.ndarray,
                wear: np.ndarray) -> Recession:
        """The recession of a run that goes on from a checkpoint: ``mesh`` moved by ``wear`` (W) from ``reference`` (X₀).

        Built on X₀ as the first update built it (the same extension, to the bit), then the mesh is put back.
        """
        now = coordinates(mesh)
        place(mesh, reference)
        recession = cls(mesh, points, nu, held)
        place(mesh, now)
        recession.wear = np.array(wear, dtype=float)
        return recession

    def after(self, realised: np.ndarray) -> np.ndarray:
        """The vertices after the updates that realised ``realised`` (U, n: :meth:`accept`'s, at the points).

        A vertex's point realised the vertex's own move, so W is their sum in the order the updates added it, and the
        vertices are those the updates left (to the bit).
        """
        wear = np.zeros(len(self._own))
        for row in realised:
            wear += row[self._own]
        return self.extension.moved(wear)

    def at_vertices(self, since: np.ndarray) -> np.ndarray:
        """The wear a move realises at Γ_C's vertices: the least of the points at each."""
        return np.minimum.reduceat(since[self._incident], self._starts)

    def trial(self, since: np.ndarray) -> tuple[np.ndarray, Quality]:
        """(The vertices' coordinates, their quality) of the move by the wear ``since`` the last update (at the points)."""
        coords = self.extension.moved(self.wear + self.at_vertices(since))
        return coords, quality(coords, self.extension.reference, self.nodes)

    def accept(self, coords: np.ndarray, since: np.ndarray) -> np.ndarray:
        """Move the mesh to ``coords`` (from :meth:`trial` of ``since``); the wear it realised at the points."""
        step = self.at_vertices(since)
        place(self.mesh, coords)
        self.wear += step
        return self.scatter @ step


def _laplacian(mesh: ngs.Mesh, regions: list[str]) -> sp.csr_matrix:
    """∫ ∇φ·∇ψ dx over ``regions`` for the P1 hat functions of the vertices (vertex i is DOF i)."""
    fes = ngs.H1(mesh, order=1)
    u, v = fes.TnT()
    form = ngs.BilinearForm(ngs.grad(u) * ngs.grad(v) * ngs.dx(definedon=mesh.Materials("|".join(regions))),
                            symmetric=True)
    form.Assemble()
    rows, cols, values = form.mat.COO()
    return sp.csr_matrix((values.NumPy(), (rows.NumPy(), cols.NumPy())), shape=(mesh.nv, mesh.nv))


@dataclass(frozen=True)
class Quality:
    """The elements of a moved mesh against its reference: the worst mean ratio, the most squeezed, the inverted.

    ``worst``: the smallest mean ratio (:func:`mean_ratio`: 1 for a regular simplex, → 0 as it degenerates; 0 for
    an inverted one); ``squeezed``: the smallest V/V₀; ``inverted``: the number of elements whose volume changed
    sign; ``where``: the centroid of the worst element (of an inverted one first).
    """

    worst: float
    squeezed: float
    inverted: int
    where: np.ndarray

    @property
    def acceptable(self) -> bool:
        """No element inverted, and none below :data:`QUALITY`."""
        return self.inverted == 0 and self.worst >= QUALITY

    @property
    def reason(self) -> str | None:
        """One line saying why the mesh cannot be used (None when it can)."""
        at = ", ".join(f"{x:.4g}" for x in self.where)
        if self.inverted:
            return f"the worn mesh has {self.inverted} inverted elements (one at ({at}))"
        if self.worst < QUALITY:
            return (f"the worn mesh's worst element (at ({at})) has the mean ratio {self.worst:.3g} < {QUALITY} "
                    f"(squeezed to {self.squeezed:.2g} of its volume)")
        return None


def contact_height(mesh: ngs.Mesh) -> float:
    """The height of the smallest element at Γ_C: min over the elements with a facet on Γ_C of d |T| / |facet|.

    An update moves Γ_C once the wear since the last reaches ``wear.update`` × this (on the mesh as it is now).
    """
    d = mesh.dim
    faces, names = facets(mesh)
    contact = faces[names == "contact"]
    nodes, _ = simplices(mesh)
    nodes = nodes[np.isin(nodes, contact).sum(axis=1) >= d]           # those with d vertices on Γ_C
    on = keys(contact)
    coords = coordinates(mesh)
    heights = []
    for facet in itertools.combinations(range(d + 1), d):
        touching = np.isin(keys(nodes[:, facet]), on)
        if touching.any():
            elements = nodes[touching]
            sides = coords[elements[:, list(facet)[1:]]] - coords[elements[:, [facet[0]]]]
            area = np.linalg.norm(np.cross(sides[:, 0], sides[:, 1]), axis=1) / 2 if d == 3 else \
                np.linalg.norm(sides[:, 0], axis=1)
            heights.append(d * np.abs(signed_volumes(coords, elements)) / area)
    return float(np.concatenate(heights).min())


def mean_ratio(coords: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """The mean ratio 4√3 |A| / Σ l² (triangles), 12 (3|V|)^(2/3) / Σ l² (tetrahedra): 1 for a regular simplex."""
    d = coords.shape[1]
    pairs = [(a, b) for a in range(d + 1) for b in range(a)]
    lengths = sum(np.sum((coords[nodes[:, a]] - coords[nodes[:, b]]) ** 2, axis=1) for a, b in pairs)
    size = np.abs(signed_volumes(coords, nodes))
    return 4 * math.sqrt(3) * size / lengths if d == 2 else 12 * (3 * size) ** (2 / 3) / lengths


def quality(coords: np.ndarray, reference: np.ndarray, nodes: np.ndarray) -> Quality:
    """The :class:`Quality` of the simplices ``nodes`` at ``coords`` against their ``reference`` positions."""
    before, after = signed_volumes(reference, nodes), signed_volumes(coords, nodes)
    ratio = after / before
    q = np.where(ratio > 0, mean_ratio(coords, nodes), 0.0)
    flipped = ratio <= 0
    worst = int(np.argmax(flipped)) if flipped.any() else int(np.argmin(q))
    return Quality(float(q.min()), float(ratio.min()), int(flipped.sum()), coords[nodes[worst]].mean(axis=0))


class RemeshError(RuntimeError):
    """Netgen could not mesh the worn geometry (the message is one line)."""


def remeshed(mesh: ngs.Mesh, maxh: float, nu=None, shape=None, contact_maxh: float | None = None) -> ngs.Mesh:
    """A new Netgen mesh of the body as it is now: its regions and named boundaries, elements of at most ``maxh``.

    2D: the moved boundary (its segments, the regions on either side, the names) becomes a geometry Netgen meshes.
    3D: the part as built (``shape``, its OpenCASCADE solids with named faces) cut by the worn Γ_C: a B-spline
    surface through the moved Γ_C's height over the plane ⟂ ν (``nu``; Γ_C must be a graph over it), swept along
    −ν through the part; the cut face is ``contact`` (with ``contact_maxh``).  A part without a shape (a mesh file)
    cannot be remeshed in 3D.

    Raises
    ------
    RemeshError
        One line: Netgen or OpenCASCADE failed, or a 3D part has no shape.
    """
    if mesh.dim == 3 and shape is None:
        raise RemeshError("a part given as a mesh (no geometry) cannot be remeshed in 3D")
    try:
        return ngs.Mesh(_remesh3d(mesh, maxh, np.asarray(nu, dtype=float), shape, contact_maxh) if mesh.dim == 3
                        else _remesh2d(mesh, maxh))
    except Exception as err:  # noqa: BLE001 - Netgen and OpenCASCADE raise their own types, with their message
        reason = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise RemeshError(f"Netgen cannot remesh the worn body ({reason})") from None


def _remesh3d(mesh: ngs.Mesh, maxh: float, nu: np.ndarray, shape, contact_maxh: float | None):
    from netgen.occ import OCCGeometry, SplineSurfaceApproximation, Vec
    from scipy.interpolate import LinearNDInterpolator

    faces, names = facets(mesh)
    coords = coordinates(mesh)
    top = coords[np.unique(faces[names == "contact"])]
    plane = np.linalg.svd(nu[None, :])[2][1:]
    flat, height = top @ plane.T, -(top @ nu)
    low, high = flat.min(axis=0), flat.max(axis=0)
    margin = 0.05 * (high - low)
    size = contact_maxh or maxh
    n = int(np.clip(2 * (high - low).max() / size, 8, 120))
    axes = [np.linspace(a - m, b + m, n) for a, b, m in zip(low, high, margin)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 2)
    heights = LinearNDInterpolator(flat, height)(grid)
    outside = np.flatnonzero(np.isnan(heights))
    heights[outside] = _extrapolated(flat, height, grid[outside])
    points = (grid @ plane - np.outer(heights, nu)).reshape(n, n, 3)
    worn = SplineSurfaceApproximation(points, deg_min=1, deg_max=3, tol=1e-3 * size)
    worn.name = "contact"
    if contact_maxh is not None:
        worn.maxh = contact_maxh
    reach = 2 * np.ptp(coords, axis=0).max()
    cut = shape * worn.Extrude(reach, Vec(*(-nu)))
    return OCCGeometry(cut, dim=3).GenerateMesh(maxh=maxh)


def _extrapolated(points: np.ndarray, values: np.ndarray, at: np.ndarray, near: int = 8) -> np.ndarray:
    """Values beyond the points' hull: the plane fitted to the ``near`` nearest points (exact for an affine field)."""
    from scipy.spatial import cKDTree

    _, nearest = cKDTree(points).query(at, k=near)
    out = np.empty(len(at))
    for i, (x, k) in enumerate(zip(at, nearest)):
        design = np.column_stack([np.ones(near), points[k] - x])
        out[i] = np.linalg.lstsq(design, values[k], rcond=None)[0][0]
    return out


def _remesh2d(mesh: ngs.Mesh, maxh: float):
    from netgen.geom2d import SplineGeometry

    nodes, regions = simplices(mesh)
    coords = coordinates(mesh)
    left = {}
    for triangle, region in zip(nodes, regions + 1):
        orientation = np.sign(signed_volumes(coords, triangle[None])[0])
        for a, b in zip(triangle, np.roll(triangle, -1)):
            left[(a, b) if orientation > 0 else (b, a)] = region          # the triangle lies left of a → b
    geometry, points = SplineGeometry(), {}
    for a, b, name in ((*v, n) for v, n in zip(*facets(mesh))):
        for v in (a, b):
            if v not in points:
                points[v] = geometry.AppendPoint(*coords[v])
        geometry.Append(["line", points[a], points[b]], leftdomain=left.get((a, b), 0),
                        rightdomain=left.get((b, a), 0), bc=name)
    for i, name in enumerate(mesh.GetMaterials(), start=1):
        geometry.SetMaterial(i, name)
    return geometry.GenerateMesh(maxh=maxh)
