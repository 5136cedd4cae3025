"""The contact points of Γ_C: the nodes of its nodal rule, their weights and evaluation maps, and d₀.

The contact terms are integrated with the *nodal* rule of the element (trapezoidal / Simpson on segments, the vertex
rule / the edge-midpoint rule on triangles): an integral over Γ_C is Σ_i m_i f(x_i) over the contact points x_i with
weights m_i.  This makes the constraint u_ν ≤ g + d₀, the wear update and ∫_ΓC w all nodal, so the discrete Archard
identity holds to round-off.  For P2 the points are the vertices and edge midpoints of Γ_C in 2D, its edge midpoints
in 3D (:data:`NODAL_WEIGHTS`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp
from ngsolve.fem import NODE_TYPE

from .topology import facets

NODAL_WEIGHTS = {
    # (dimension, order): the weights of a contact facet's vertices and edge midpoints, per unit measure
    (2, 1): (1 / 2, None),       # trapezoidal
    (2, 2): (1 / 6, 2 / 3),      # Simpson
    (3, 1): (1 / 3, None),       # vertex rule
    (3, 2): (0.0, 1 / 3),        # edge-midpoint rule
}
"""Nodal rules of the contact facets: each integrates the element's shape functions exactly, so a
uniform pressure gives the consistent nodal forces.  On P2 triangles that is the edge-midpoint rule
(exact for quadratics): the vertices get zero weight, so the contact points are the edge midpoints
alone (a positive rule on all six nodes, e.g. the vertex rule on the four halved triangles, gives
inconsistent forces: 10 % error in the closed-form column at h = 1/4, first order, measured)."""


def initial_distance(coords: np.ndarray, nu) -> np.ndarray:
    """d₀ ≥ 0 at points x_i: distance along ν to the foundation plane through the lowest point, max ν·x − ν·x_i."""
    heights = coords @ np.asarray(nu, dtype=float)
    return heights.max(initial=0.0) - heights


@dataclass(frozen=True)
class ContactPoints:
    """The nodal points x_i of Γ_C with weights m_i and evaluation maps.

    ``P`` (d·n × ndof): (P u)[d i + k] = u_k(x_i).  ``at_vertices`` (nv × n): values at the mesh
    vertices of Γ_C from values at the points: the vertex's own point, or, where the vertices are no
    points (P2 in 3D), the mean over its Γ_C triangles (v, a, b) of w_va + w_vb − w_ab (the linear
    function through the triangle's midpoint values, exact for linear w); 0 off Γ_C.  ``Q`` (ndof_scalar × n):
    coefficients of the scalar H1 function with these vertex values and the given values at the points
    (for the NGSolve form's w and d₀, and VTU output).  ``vertices[i]``: the mesh vertex at x_i, −1 for
    an edge midpoint (P2); ``edges[i]``: the mesh edge whose midpoint is x_i, −1 for a vertex.
    """

    coords: np.ndarray
    weights: np.ndarray
    P: sp.csr_matrix
    Q: sp.csr_matrix
    at_vertices: sp.csr_matrix
    vertices: np.ndarray
    edges: np.ndarray
    n: int = field(init=False)          # the number of points

    def __post_init__(self):
        object.__setattr__(self, "n", len(self.weights))


def contact_points(fes: ngs.FESpace, dim: int, order: int) -> ContactPoints:
    """Collect the contact points (the nodes of Γ_C with a positive weight in :data:`NODAL_WEIGHTS`) and their weights."""
    mesh = fes.mesh
    vertex_weight, midpoint_weight = NODAL_WEIGHTS[dim, order]
    index: dict[tuple, int] = {}
    coords, weights = [], []
    edge_ends: dict[int, tuple[int, int]] = {}
    triangles: list[tuple] = []

    def point(key, x, weight):
        if key not in index:
            index[key] = len(coords)
            coords.append(x)
            weights.append(0.0)
        weights[index[key]] += weight

    def dofs(node_type, nr):
        return [d for d in fes.GetDofNrs(ngs.NodeId(node_type, nr)) if d >= 0]

    faces, names = facets(mesh)
    faces = faces[names == "contact"]                                # Γ_C's facets, in NGSolve's order
    X = np.array(mesh.ngmesh.Coordinates())
    sides = X[faces[:, 1:]] - X[faces[:, :1]]
    sizes = [np.linalg.norm(side[0]) for side in sides] if dim == 2 else \
        [0.5 * np.linalg.norm(normal) for normal in np.cross(sides[:, 0], sides[:, 1])]
    if order == 1:
        for corners, size in zip(faces.tolist(), sizes):
            for v in corners:
                point(("v", v), X[v], size * vertex_weight)
    else:
        contact = (el for el in mesh.Elements(ngs.BND) if el.mat == "contact")
        for el, corners, size in zip(contact, faces.tolist(), sizes):
            for v in corners if vertex_weight else ():
                point(("v", v), X[v], size * vertex_weight)
            if dim == 3:
                triangles.append((tuple(corners), tuple(e.nr for e in el.edges)))
            for e in el.edges:
                a, b = mesh[e].vertices
                edge_ends[e.nr] = (a.nr, b.nr)
                point(("e", e.nr), 0.5 * (X[a.nr] + X[b.nr]), size * midpoint_weight)
    n = len(coords)
    vertices, edges = np.full(n, -1), np.full(n, -1)
    for (kind, nr), i in index.items():
        (vertices if kind == "v" else edges)[i] = nr
    at_vertices = _vertex_map(mesh.nv, vertices, {key[1]: i for key, i in index.items() if key[0] == "e"},
                              edge_ends, triangles)
    # P: a vertex point is its vertex DOFs; an edge midpoint (u_a + u_b)/2 + β_e c_e (the hierarchical P2 bubble)
    beta = _bubble_scale(mesh, dim, edge_ends) if order == 2 else None
    rows, cols, vals = [], [], []
    for (kind, nr), i in index.items():
        if kind == "v":
            terms = [(dofs(NODE_TYPE.VERTEX, nr), 1.0)]
        else:
            a, b = edge_ends[nr]
            edofs = dofs(NODE_TYPE.EDGE, nr)
            terms = [(dofs(NODE_TYPE.VERTEX, a), 0.5), (dofs(NODE_TYPE.VERTEX, b), 0.5), (edofs, beta[nr])]
        for ds, c in terms:
            for k, dof in enumerate(ds):
                rows.append(dim * i + k), cols.append(dof), vals.append(c)
    P = sp.csr_matrix((vals, (rows, cols)), shape=(dim * n, fes.ndof))
    Q = _scalar_coefficients(fes, dim, at_vertices, edges, edge_ends, beta)
    return ContactPoints(np.array(coords)[:, :dim], np.array(weights), P, Q, at_vertices, vertices, edges)


def _vertex_map(nv: int, vertices: np.ndarray, midpoint: dict, edge_ends: dict, triangles: list) -> sp.csr_matrix:
    """at_vertices of :class:`ContactPoints`: identity rows for vertex points, else the triangles' reconstruction."""
    n = len(vertices)
    if (vertices >= 0).any():
        own = np.flatnonzero(vertices >= 0)
        return sp.csr_matrix((np.ones(len(own)), (vertices[own], own)), shape=(nv, n))
    rows, cols, vals = [], [], []
    for corners, sides in triangles:
        at = {frozenset(edge_ends[e]): midpoint[e] for e in sides}
        for v in corners:
            a, b = (u for u in corners if u != v)
            rows += [v, v, v]
            cols += [at[frozenset((v, a))], at[frozenset((v, b))], at[frozenset((a, b))]]
            vals += [1.0, 1.0, -1.0]
    rows = np.array(rows, dtype=int)
    count = np.bincount(rows, minlength=nv) / 3
    return sp.csr_matrix((np.array(vals) / count[rows], (rows, cols)), shape=(nv, n))


def _scalar_coefficients(fes, dim, at_vertices, edges, edge_ends, beta) -> sp.csr_matrix:
    """Q of :class:`ContactPoints`: vertex DOFs = at_vertices; edge DOFs c_e = (w_e − (w_a + w_b)/2)/β_e.

    The scalar space's DOFs are numbered as the first component's of the vector space ``fes``.
    """
    ndof = fes.ndof // dim
    nv, n = at_vertices.shape
    touched = np.flatnonzero(at_vertices.getnnz(axis=1))            # the vertices of Γ_C
    vertex_dof = np.array([fes.GetDofNrs(ngs.NodeId(NODE_TYPE.VERTEX, int(v)))[0] for v in touched], dtype=int)
    Q = sp.csr_matrix((np.ones(len(touched)), (vertex_dof, touched)), shape=(ndof, nv)) @ at_vertices
    if beta is None:
        return Q.tocsr()
    mid = np.flatnonzero(edges >= 0)
    dof = np.array([fes.GetDofNrs(ngs.NodeId(NODE_TYPE.EDGE, int(e)))[0] for e in edges[mid]], dtype=int)
    ends = np.array([edge_ends[e] for e in edges[mid]], dtype=int).reshape(-1, 2)
    rows = np.arange(len(mid))
    halves = sp.csr_matrix((np.full(2 * len(mid), 0.5), (np.repeat(rows, 2), ends.ravel())), shape=(len(mid), nv))
    own = sp.csr_matrix((np.ones(len(mid)), (rows, mid)), shape=(len(mid), n))
    bubble = sp.diags([1.0 / beta[e] for e in edges[mid]]) @ (own - halves @ at_vertices)
    place = sp.csr_matrix((np.ones(len(mid)), (dof, rows)), shape=(ndof, len(mid)))
    return (Q + place @ bubble).tocsr()


def _bubble_scale(mesh: ngs.Mesh, dim: int, edge_ends: dict) -> dict:
    """β_e of the edges e of ``edge_ends`` ({e: (a, b)}): the P2 edge shape function's value at the midpoint.

    From f = |x|²: f(mid) − (f(a)+f(b))/2 = −|b−a|²/4 = β_e c_e, with c_e the interpolant's edge DOF.
    """
    scal = ngs.H1(mesh, order=2)
    gf = ngs.GridFunction(scal)
    gf.Set(sum(c * c for c in (ngs.x, ngs.y, ngs.z)[:dim]))
    coef = gf.vec.FV().NumPy()
    points = mesh.ngmesh.Coordinates()
    beta = {}
    for e, (a, b) in edge_ends.items():
        length2 = float(np.sum((points[b] - points[a]) ** 2))
        beta[e] = -length2 / 4 / coef[scal.GetDofNrs(ngs.NodeId(NODE_TYPE.EDGE, e))[0]]
    return beta
