"""A straight-sided mesh as arrays: its simplices, boundary facets and vertices, read from Netgen's element tables.

Vertex numbers count from 0 (Netgen's from 1); the arrays follow NGSolve's order of the elements.  Reading them is a
copy of Netgen's tables, not a loop over NGSolve's element objects (a Python call per element).
"""
from __future__ import annotations

import math
from itertools import combinations

import ngsolve as ngs
import numpy as np

TRIG, TET = 10, 20
"""Netgen's codes of the first-order triangle and tetrahedron (its element tables' ``type``)."""


def straight_simplices(mesh: ngs.Mesh) -> bool:
    """Whether every volume element is a straight simplex: a first-order triangle (2D) or tetrahedron (3D).

    Not when the mesh has a quadrilateral, prism or hexahedron, a second-order node, or a curved geometry.
    """
    kind = (mesh.ngmesh.Elements3D() if mesh.dim == 3 else mesh.ngmesh.Elements2D()).NumPy()["type"]
    return mesh.GetCurveOrder() == 1 and bool((kind == (TET if mesh.dim == 3 else TRIG)).all())


def vertex_p1(fes: ngs.FESpace) -> bool:
    """Whether ``fes`` is P1 ``VectorH1`` on straight simplices with component i's DOFs its i-th block, one a vertex."""
    mesh, flags = fes.mesh, fes.flags.ToDict()
    return (isinstance(fes, ngs.VectorH1) and fes.globalorder == 1 and fes.ndof == mesh.dim * mesh.nv
            and "interleaved" not in flags and "definedon" not in flags and straight_simplices(mesh))


def gradients(coords: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """The barycentric gradients of straight simplices, ne × (d+1) × d: ∇λ_0, …, ∇λ_d of each.

    With E = [x_1 − x_0, …, x_d − x_0] the rows of E⁻¹ are ∇λ_a (a ≥ 1), and ∇λ_0 = −Σ_a ∇λ_a.
    """
    edges = np.swapaxes(coords[nodes[:, 1:]] - coords[nodes[:, :1]], 1, 2)          # ne × d × d, columns x_a − x_0
    inner = np.linalg.inv(edges)
    return np.concatenate([-inner.sum(axis=1, keepdims=True), inner], axis=1)


def simplices(mesh: ngs.Mesh) -> tuple[np.ndarray, np.ndarray]:
    """(Vertices of each volume element (from 0), its region's index into ``mesh.GetMaterials()``)."""
    elements = (mesh.ngmesh.Elements3D() if mesh.dim == 3 else mesh.ngmesh.Elements2D()).NumPy()
    return elements["nodes"][:, :mesh.dim + 1].astype(np.int64) - 1, elements["index"] - 1


def facets(mesh: ngs.Mesh) -> tuple[np.ndarray, np.ndarray]:
    """(Vertices of each boundary element (from 0), its boundary's name), in NGSolve's order of the elements."""
    ngmesh = mesh.ngmesh
    if mesh.dim == 3:
        elements, name = ngmesh.Elements2D().NumPy(), lambda index: ngmesh.FaceDescriptor(index).bcname
    else:
        elements, name = ngmesh.Elements1D().NumPy(), lambda index: ngmesh.GetBCName(index - 1)
    indices = np.unique(elements["index"])
    names = np.array([name(int(index)) for index in indices])
    return elements["nodes"][:, :mesh.dim].astype(np.int64) - 1, names[np.searchsorted(indices, elements["index"])]


def lone_facets(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The boundary of the region the simplices ``nodes`` fill: (its facets, for each its simplex's other vertex).

    A facet of one simplex only is on the boundary; the facets are sorted rows, in lexicographic order.
    """
    d = nodes.shape[1] - 1
    local = list(combinations(range(d + 1), d))
    faces = np.sort(np.concatenate([nodes[:, list(f)] for f in local]), axis=1)
    opposite = np.concatenate([nodes[:, ({*range(d + 1)} - {*f}).pop()] for f in local])
    order = np.lexsort(faces.T[::-1])
    faces, opposite = faces[order], opposite[order]
    twin = (faces[1:] == faces[:-1]).all(axis=1)                     # a facet shared with the next one
    lone = ~(np.r_[twin, False] | np.r_[False, twin])
    return faces[lone], opposite[lone]


def keys(rows: np.ndarray) -> np.ndarray:
    """One comparable key per row of vertex numbers, whatever their order (the sorted row's bytes)."""
    rows = np.ascontiguousarray(np.sort(rows, axis=1), dtype=np.int64)
    return rows.view(np.dtype((np.void, rows.dtype.itemsize * rows.shape[1]))).ravel()


def coordinates(mesh: ngs.Mesh) -> np.ndarray:
    """The vertices' coordinates, nv × d (a copy)."""
    return np.array(mesh.ngmesh.Coordinates()[:, :mesh.dim])


def place(mesh: ngs.Mesh, coords: np.ndarray) -> None:
    """Move the mesh's vertices to ``coords`` (nv × d); Netgen's and NGSolve's point searches follow."""
    mesh.ngmesh.Coordinates()[:, :mesh.dim] = coords
    mesh.ngmesh.Update()


def signed_volumes(coords: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Signed volumes (areas in 2D) of simplices."""
    edges = coords[nodes[:, 1:]] - coords[nodes[:, :1]]
    return np.linalg.det(edges) / math.factorial(coords.shape[1])
