"""Fields of a run on one mesh evaluated on another mesh of the same part (convergence against a finer reference).

Two meshes of a curved part differ near its curved faces (the pad's arcs, the pin's cylinder and spherical
end, CAD faces): a point of one lies outside the other by up to the chords' sagitta, O(h²/R).  NGSolve's
point search finds no element there, and ``GridFunction.Set`` of a function of another mesh silently sets 0.
Here a point outside the body, at most ``reach`` from it, is evaluated with the polynomial of the nearest body
element (nearest by the distance to its nearest point, the barycentric coordinates clipped to the simplex):
an extension that reproduces the element's polynomials and leaves every point inside the body as it is.

* :class:`Simplices`: the nearest simplex of a set (volume elements, or Γ_C facets) and the barycentric
  coordinates of the nearest point on it;
* :class:`Locator`: NGSolve mesh points for points of (or just outside) a region, the body by default;
* :class:`StrainQuadrature`: ‖ε(u) − ε(u_ref)‖_{L²} over every region of the reference mesh, u of the other mesh
  evaluated at the reference's quadrature points, each in its own region (no interpolation onto the reference's
  space); on the reference's own mesh eᵀ G e with G the Gram matrix of ε (a k-study: no point evaluations); P1
  strains are constant on each simplex (:func:`element_strains`), so there a point takes its element's;
* :class:`ContactTrace`: the nodal wear of Γ_C as the finite element function it is (P1: linear on each facet;
  P2: quadratic through the vertex and edge-midpoint values) at points on (or near) Γ_C.
"""
from __future__ import annotations

from functools import cached_property

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from .stiffness import assembled
from .topology import coordinates, gradients, simplices, vertex_p1

CANDIDATES = 16


class Simplices:
    """Simplices (m × (k+1) × d corners, k ≤ d) with the nearest point of the nearest one to given points."""

    def __init__(self, corners: np.ndarray):
        self.corners = corners
        self.origin = corners[:, -1]
        edges = np.swapaxes(corners[:, :-1] - self.origin[:, None], 1, 2)        # m × d × k
        self.pinv = np.linalg.pinv(edges)                                         # m × k × d: orthogonal projection
        self.centroids = corners.mean(axis=1)
        self.tree = cKDTree(self.centroids)

    def nearest(self, x: np.ndarray):
        """(simplex index, barycentric coordinates of x's projection on its plane, distance) for each row of x.

        The nearest simplex is the one whose nearest point (barycentric coordinates clipped to the simplex) is
        nearest, among the ``CANDIDATES`` with the nearest centroids.
        """
        k = min(CANDIDATES, len(self.corners))
        _, cand = self.tree.query(x, k=k)
        cand = cand.reshape(len(x), k)
        lam = np.einsum("mkij,mkj->mki", self.pinv[cand], x[:, None, :] - self.origin[cand])
        lam = np.concatenate([lam, 1 - lam.sum(axis=-1, keepdims=True)], axis=-1)
        clipped = np.maximum(lam, 0)
        clipped /= clipped.sum(axis=-1, keepdims=True)
        near = np.einsum("mki,mkij->mkj", clipped, self.corners[cand])
        dist = np.linalg.norm(near - x[:, None, :], axis=-1)
        best = dist.argmin(axis=1)
        rows = np.arange(len(x))
        return cand[rows, best], lam[rows, best], dist[rows, best]


def _corners(mesh: ngs.Mesh, elements) -> np.ndarray:
    coords = mesh.ngmesh.Coordinates()[:, :mesh.dim]
    return coords[np.array([[v.nr for v in el.vertices] for el in elements])]


def _same(mesh: ngs.Mesh, other: ngs.Mesh) -> bool:
    """Whether two meshes are one: the same vertices and the same elements (their vertices and regions) in the same order."""
    return np.array_equal(coordinates(mesh), coordinates(other)) and all(
        np.array_equal(a, b) for a, b in zip(simplices(mesh), simplices(other)))


class Locator:
    """Mesh points of a region of ``mesh`` (default the body) for points in it or at most ``reach`` outside it."""

    def __init__(self, mesh: ngs.Mesh, reach: float | None = None, region: str = "body"):
        """``reach``: how far outside a point may be (default: the largest edge of the mesh's elements)."""
        self.mesh = mesh
        nodes, regions = simplices(mesh)
        self.in_region = regions == mesh.GetMaterials().index(region)
        self.numbers = np.flatnonzero(self.in_region)
        corners = coordinates(mesh)[nodes[self.numbers]]
        self.simplices = Simplices(corners)
        if reach is None:
            pairs = [(a, b) for a in range(mesh.dim + 1) for b in range(a)]
            reach = max(float(np.linalg.norm(corners[:, a] - corners[:, b], axis=1).max()) for a, b in pairs)
        self.reach = reach

    def __call__(self, points: np.ndarray):
        points = np.asarray(points, dtype=float)
        mips = self.mesh(*points.T)
        outside = (mips["nr"] < 0) | ~self.in_region[np.maximum(mips["nr"], 0)]
        if outside.any():
            x = points[outside]
            index, lam, dist = self.simplices.nearest(x)
            if dist.max() > self.reach:
                far = int(dist.argmax())
                raise ValueError(f"points: {x[far].tolist()} is not in the body ({dist[far]:.3g} from it, more "
                                 f"than {self.reach:.3g})")
            mips[outside] = self._at(self.numbers[index], lam)
        return mips

    def _at(self, numbers: np.ndarray, lam: np.ndarray):
        """Mesh points at barycentric coordinates λ of elements (NGSolve's local coordinates are λ_0 … λ_{d−1})."""
        out = np.repeat(self.mesh(*self.simplices.centroids[:1].T), len(numbers))
        out["nr"] = numbers
        for axis, name in enumerate(("x", "y", "z")):
            out[name] = lam[:, axis] if axis < self.mesh.dim else 0.0
        return out


class StrainQuadrature:
    """∫_Ω |ε(u) − ε(u_ref)|² dx over every region of the reference mesh, by a rule of the given degree on its elements.

    The rule's points must lie inside the elements (not the degree-2 triangle rule).
    """

    def __init__(self, fes_ref: ngs.FESpace, degree: int):
        mesh = fes_ref.mesh
        rule = ngs.IntegrationRule(ngs.TET if mesh.dim == 3 else ngs.TRIG, degree)
        local = np.array([p[:mesh.dim] for p in rule.points])
        if min(local.min(), 1 - local.sum(axis=1).max()) <= 0:
            # a point on a face (the degree-2 triangle rule's edge midpoints) would be found in the neighbour of
            # its element by a search in another mesh, even an identical one (ε of P1 jumps across faces)
            raise ValueError(f"degree {degree}: the rule has points on the elements' faces; use another degree")
        self.mips = mesh.MapToAllElements(rule, ngs.VOL)
        self.regions = np.array(mesh.GetMaterials())[simplices(mesh)[1][self.mips["nr"]]]
        jacobian = np.abs(np.asarray(ngs.Det(ngs.specialcf.JacobianMatrix(mesh.dim))(self.mips))).ravel()
        self.weights = np.tile(np.asarray(rule.weights), mesh.ne) * jacobian
        self.points = np.asarray(ngs.CF((ngs.x, ngs.y, ngs.z)[:mesh.dim])(self.mips)).reshape(-1, mesh.dim)
        self.ref = ngs.GridFunction(fes_ref)
        self._other: tuple = (None, None)           # (a space, its element_strains)

    def on(self, mesh: ngs.Mesh):
        """The mesh points of this rule's points on another mesh, each in its own region (once per mesh).

        ε jumps across the faces between regions, so a point is taken from its region's elements (:class:`Locator`).
        None for the reference's own mesh (the same vertices and elements): :meth:`error2` needs no points there.
        """
        if _same(mesh, self.ref.space.mesh):
            return None
        at = self.mips.copy()
        for region in np.unique(self.regions):
            inside = self.regions == region
            at[inside] = Locator(mesh, region=region)(self.points[inside])
        return at

    @cached_property
    def gram(self) -> sp.csr_matrix:
        """G_ij = ∫_Ω ε(φ_j) : ε(φ_i) dx over every region, the reference space's basis φ (exact: a polynomial)."""
        u, v = self.ref.space.TnT()
        return assembled(ngs.BilinearForm(ngs.InnerProduct(ngs.Sym(ngs.Grad(u)), ngs.Sym(ngs.Grad(v))) * ngs.dx))

    def error2(self, u: ngs.GridFunction, at, u_ref: np.ndarray) -> float:
        """‖ε(u) − ε(u_ref)‖², u on the other mesh (``at`` from :meth:`on`), u_ref the reference's DOF vector.

        On the reference's own mesh (``at`` None): eᵀ G e, e = u − u_ref (:attr:`gram`).  P1 on both meshes: each
        point takes the strain of its element (:func:`element_strains`), else NGSolve evaluates ε at the points.
        """
        if at is None:
            e = u.vec.FV().NumPy() - u_ref
            return float(e @ (self.gram @ e))
        if self._elementwise is not None and (other := self._strains(u.space)) is not None:
            size = self.ref.space.mesh.dim ** 2
            diff = ((other @ u.vec.FV().NumPy()).reshape(-1, size)[at["nr"]]
                    - (self._elementwise @ u_ref).reshape(-1, size)[self.mips["nr"]])
        else:
            self.ref.vec.FV().NumPy()[:] = u_ref
            strain = lambda gf, mips: np.asarray(ngs.Sym(ngs.Grad(gf))(mips)).reshape(len(mips), -1)  # noqa: E731
            diff = strain(u, at) - strain(self.ref, self.mips)
        return float(self.weights @ np.einsum("ij,ij->i", diff, diff))

    @cached_property
    def _elementwise(self) -> sp.csr_matrix | None:
        return element_strains(self.ref.space)

    def _strains(self, fes: ngs.FESpace) -> sp.csr_matrix | None:
        """:func:`element_strains` of another space, kept for the last one asked (a study asks per mesh)."""
        if self._other[0] is not fes:
            self._other = (fes, element_strains(fes))
        return self._other[1]


def element_strains(fes: ngs.FESpace) -> sp.csr_matrix | None:
    """D with (D u)[e d² + d i + j] = ε_ij(u) on element e, for P1 ``VectorH1`` on straight simplices (else None).

    ε is constant on each simplex: with its vertices x_0 … x_d, E = [x_1 − x_0, …, x_d − x_0], the barycentric
    gradients ∇λ_a (a ≥ 1) are the rows of E⁻¹, ∇λ_0 = −Σ_a ∇λ_a, and ε_ij = ½ Σ_a (u_i,a ∂_j λ_a + u_j,a ∂_i λ_a),
    u_i,a the i-th component's DOF at vertex a (component i's DOFs are the i-th block, one per vertex).
    """
    mesh, d = fes.mesh, fes.mesh.dim
    if not vertex_p1(fes):
        return None
    nodes = simplices(mesh)[0]
    grads = gradients(coordinates(mesh), nodes)                                    # ne × (d+1) × d
    ne = len(nodes)
    rows, cols, vals = [], [], []
    for i in range(d):
        for j in range(d):
            row = np.repeat(np.arange(ne) * d * d + d * i + j, d + 1)
            rows += [row, row]
            cols += [(i * mesh.nv + nodes).ravel(), (j * mesh.nv + nodes).ravel()]
            vals += [0.5 * grads[:, :, j].ravel(), 0.5 * grads[:, :, i].ravel()]
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(ne * d * d, fes.ndof))


class ContactTrace:
    """The nodal values of Γ_C (the contact points') as a function on Γ_C, evaluated at points on or near it."""

    def __init__(self, mesh: ngs.Mesh, points, order: int, reach: float):
        facets = [el for el in mesh.Elements(ngs.BND) if el.mat == "contact"]
        self.vertices = np.array([[v.nr for v in el.vertices] for el in facets])
        self.simplices = Simplices(_corners(mesh, facets))
        self.at_vertices, self.reach, self.mid = points.at_vertices, reach, None
        if order == 2:
            ends = {e.nr: {v.nr for v in mesh[e].vertices} for el in facets for e in el.edges}
            point_of = {int(e): i for i, e in enumerate(points.edges) if e >= 0}
            corners = self.vertices
            pairs = [(a, b) for a in range(corners.shape[1]) for b in range(a + 1, corners.shape[1])]
            self.pairs = pairs
            self.mid = np.array([[point_of[next(e.nr for e in el.edges if ends[e.nr] == {row[a], row[b]})]
                                  for a, b in pairs] for el, row in zip(facets, corners)])

    def __call__(self, values: np.ndarray, x: np.ndarray) -> np.ndarray:
        """The function with nodal ``values`` (one per contact point) at the points x (m × d)."""
        index, lam, dist = self.simplices.nearest(np.asarray(x, dtype=float))
        if dist.max(initial=0.0) > self.reach:
            raise ValueError(f"points: {x[int(dist.argmax())].tolist()} is not on Γ_C ({dist.max():.3g} from it)")
        corner = (self.at_vertices @ values)[self.vertices[index]]                   # m × (k+1)
        if self.mid is None:
            return np.einsum("mi,mi->m", lam, corner)
        mid = values[self.mid[index]]                                                 # m × pairs
        quadratic = np.einsum("mi,mi->m", corner, lam * (2 * lam - 1))
        return quadratic + sum(4 * mid[:, p] * lam[:, a] * lam[:, b] for p, (a, b) in enumerate(self.pairs))
