"""The stiffness of constant linear laws from the space's gradient blocks, assembled once per mesh.

The displacement space is d copies of a scalar H1 space (NGSolve's ``VectorH1``: the DOFs of component i are its
i-th block), so for laws C^r constant on the regions r

    a(u, v) = Σ_r ∫_r C^r_ijkl ∂_l u_k ∂_j v_i dx,      K_(i,k) = Σ_r Σ_jl C^r_ijkl S^r_jl,   S^r_jl = ∫_r ∂_j ψ ∂_l φ dx,

with φ, ψ the scalar basis functions.  The d(d+1)/2 scalar matrices S^r_jl (S_lj = S_jlᵀ) are the only assembly:
any law's K is a sparse sum of them, so a material change assembles nothing.  NGSolve's symbolic form of a general
C_ijkl costs more than its isotropic form; the blocks cost about the isotropic form, whatever C (``tests/test_stiffness.py``
checks them against the symbolic forms).  For P1 on straight simplices the gradients are constant on each element,

    S^r_jl = Σ_{e ⊂ r} |e| ∂_j λ_a ∂_l λ_b   at the entry (vertex a, vertex b) of e,

summed in NumPy from the element arrays (:func:`simplex_blocks`), which is faster than NGSolve's assembly for a
geometry update's K (``benchmarks/stiffness_blocks.py`` measures both).
"""
from __future__ import annotations

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from ..model import mandel
from .topology import coordinates, gradients, signed_volumes, simplices, vertex_p1


class GradientBlocks:
    """S^r_jl of every region r of the space's mesh (built on first use of each region).

    ``kept``: the blocks of regions whose elements are those of another mesh's, unmoved (a geometry update leaves
    the regions that do not carry Γ_C), by region.  ``patterns``: :func:`simplex_pattern` of a mesh with the same
    elements (a geometry update moves vertices only), by region; shared, and filled as regions are summed.
    """

    def __init__(self, fes: ngs.FESpace, kept: dict[str, dict] | None = None, patterns: dict | None = None):
        self.mesh, self.dim = fes.mesh, fes.mesh.dim
        self.scalar = ngs.H1(fes.mesh, order=fes.globalorder)
        if fes.ndof != self.dim * self.scalar.ndof:
            raise ValueError("GradientBlocks: the space is not d copies of H1 of its order")
        self._regions: dict[str, dict] = dict(kept or {})
        self.patterns = {} if patterns is None else patterns
        self.vertex_p1 = vertex_p1(fes)

    @property
    def built(self) -> dict[str, dict]:
        """The blocks built so far, by region."""
        return dict(self._regions)

    def of(self, region: str) -> dict:
        """{(a, b): S_ab} of ``region`` (CSR, both triangles): summed in NumPy for P1 on straight simplices."""
        if region not in self._regions:
            if self.vertex_p1:
                nodes = region_simplices(self.mesh, region)
                if region not in self.patterns:
                    self.patterns[region] = simplex_pattern(nodes, self.mesh.nv)
                self._regions[region] = simplex_blocks(coordinates(self.mesh), nodes, self.patterns[region])
            else:
                self._regions[region] = self._assembled(region)
        return self._regions[region]

    def _assembled(self, region: str) -> dict:
        """{(a, b): S_ab} of ``region`` by NGSolve's forms (S_ab for a ≤ b, their transposes below)."""
        p, q = self.scalar.TnT()
        blocks, dx = {}, ngs.dx(definedon=self.mesh.Materials(region))
        for a in range(self.dim):
            for b in range(a, self.dim):
                blocks[a, b] = assembled(ngs.BilinearForm(ngs.grad(p)[b] * ngs.grad(q)[a] * dx, symmetric=a == b))
        for a in range(self.dim):
            for b in range(a):
                blocks[a, b] = blocks[b, a].T.tocsr()
        return blocks

    def stiffness(self, laws: dict) -> sp.csr_matrix:
        """K of the linear laws ``{region: law}`` (each with a Mandel ``matrix``)."""
        block = [[None] * self.dim for _ in range(self.dim)]
        for region, law in laws.items():
            C, S = mandel.fourth_order(law.matrix), self.of(region)
            for i, a, k, b in zip(*np.nonzero(C)):
                term = C[i, a, k, b] * S[a, b]
                block[i][k] = term if block[i][k] is None else block[i][k] + term
        return sp.bmat(block, format="csr")


def region_simplices(mesh: ngs.Mesh, region: str) -> np.ndarray:
    """The vertices (from 0) of the volume elements of ``region``."""
    nodes, index = simplices(mesh)
    return nodes[index == list(mesh.GetMaterials()).index(region)]


def simplex_pattern(nodes: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(entry, indptr, indices): each element entry's place among the vertex pairs of ``nodes``, their CSR pattern.

    It depends on the elements only: one index map for every block (n × n) and every geometry update.
    """
    pairs, entry = np.unique((np.repeat(nodes, nodes.shape[1], axis=1) * n + np.tile(nodes, nodes.shape[1])).ravel(),
                             return_inverse=True)
    return entry, np.searchsorted(pairs, np.arange(n + 1) * n), pairs % n


def simplex_blocks(coords: np.ndarray, nodes: np.ndarray, pattern: tuple) -> dict:
    """{(a, b): S_ab} of P1 on the straight simplices ``nodes`` (CSR on their vertex pairs, :func:`simplex_pattern`).

    The scalar P1 space's DOF of a vertex is its number (module docstring).
    """
    (entry, indptr, indices), (n, d) = pattern, coords.shape
    grads, volumes = gradients(coords, nodes), np.abs(signed_volumes(coords, nodes))
    return {(a, b): sp.csr_matrix((np.bincount(entry, (volumes[:, None, None] * grads[:, :, None, a]
                                                      * grads[:, None, :, b]).ravel(), len(indices)),
                                   indices, indptr), shape=(n, n))
            for a in range(d) for b in range(d)}


PARALLEL = 50_000
"""The DOFs of a form's space from which NGSolve's TaskManager assembles it (see :func:`assembled`)."""


def assembled(form: ngs.BilinearForm) -> sp.csr_matrix:
    """The form's matrix as a scipy CSR matrix (of a symmetric form: both triangles, whichever NGSolve kept).

    A form on :data:`PARALLEL` DOFs or more is assembled by NGSolve's TaskManager, its threads on element colours:
    the same matrix to the bit as one thread's (``tests/test_stiffness.py``), faster on quiet cores.  Smaller ones on
    one thread: the TaskManager's threads wait actively, and on cores another process keeps busy (a test worker, a
    sweep's) they cost more than they save on a small form.
    """
    if form.space.ndof >= PARALLEL:
        with ngs.TaskManager():
            form.Assemble()
    else:
        form.Assemble()
    vals, cols, ptr = form.mat.CSR()
    K = sp.csr_matrix((np.array(vals), np.array(cols), np.array(ptr)), shape=(form.mat.height, form.mat.width))
    upper, lower = sp.triu(K, 1), sp.tril(K, -1)
    if upper.nnz == 0 and lower.nnz:
        return (K + lower.T).tocsr()
    if lower.nnz == 0 and upper.nnz:
        return (K + upper.T).tocsr()
    return K
