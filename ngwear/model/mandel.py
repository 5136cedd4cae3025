"""Mandel notation for symmetric tensors and the stiffness, in numpy and as NGSolve CoefficientFunctions.

A symmetric d × d tensor ε is the vector ε_M of its m = d(d+1)/2 components, off-diagonal ones scaled by √2:

    d = 3:  ε_M = (ε₁₁, ε₂₂, ε₃₃, √2 ε₂₃, √2 ε₁₃, √2 ε₁₂),      d = 2:  ε_M = (ε₁₁, ε₂₂, √2 ε₁₂),

so that σ : ε = σ_M · ε_M and |ε| = |ε_M|.  A linear law σ = C ε is then a symmetric m × m matrix C_M whose
eigenvalues are the law's monotonicity and Lipschitz constants (its smallest and largest).  A rotation x' = R x maps
ε to R ε Rᵀ, i.e. ε_M to Q(R) ε_M with Q orthogonal, and the stiffness to Q C_M Qᵀ (:func:`rotated`).  The 2D
(plane strain, ε₃₃ = ε₁₃ = ε₂₃ = 0) stiffness is the (11, 22, 12) block of the 3D one (:func:`plane_strain`).
"""
from __future__ import annotations

import ngsolve as ngs
import numpy as np

PAIRS = {2: ((0, 0), (1, 1), (0, 1)), 3: ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))}
"""Tensor indices (i, j) of each Mandel component."""
_PLANE = (0, 1, 5)   # the 3D Mandel components that remain in plane strain: 11, 22, 12


def size(dim: int) -> int:
    """The number of Mandel components, m = d(d+1)/2."""
    return len(PAIRS[dim])


def weights(dim: int) -> np.ndarray:
    """1 for a diagonal component, √2 for an off-diagonal one."""
    return np.array([1.0 if i == j else np.sqrt(2) for i, j in PAIRS[dim]])


def to_mandel(tensors: np.ndarray) -> np.ndarray:
    """(…, d, d) symmetric tensors → (…, m) Mandel vectors."""
    tensors = np.asarray(tensors, dtype=float)
    dim = tensors.shape[-1]
    return np.stack([tensors[..., i, j] for i, j in PAIRS[dim]], axis=-1) * weights(dim)


def from_mandel(vectors: np.ndarray) -> np.ndarray:
    """(…, m) Mandel vectors → (…, d, d) symmetric tensors."""
    vectors = np.asarray(vectors, dtype=float)
    dim = {3: 2, 6: 3}[vectors.shape[-1]]
    out = np.zeros(vectors.shape[:-1] + (dim, dim))
    for k, (i, j) in enumerate(PAIRS[dim]):
        out[..., i, j] = out[..., j, i] = vectors[..., k] / weights(dim)[k]
    return out


def fourth_order(stiffness: np.ndarray) -> np.ndarray:
    """C_ijkl (d, d, d, d) of a Mandel stiffness: Σ_ab B_a,ij C_ab B_b,kl with B_a the tensor of the a-th unit vector."""
    basis = from_mandel(np.eye(len(stiffness)))
    return np.einsum("aij,ab,bkl->ijkl", basis, stiffness, basis)


def rotation(R: np.ndarray) -> np.ndarray:
    """Q(R), the orthogonal m × m matrix with (R ε Rᵀ)_M = Q(R) ε_M."""
    basis = from_mandel(np.eye(size(len(R))))
    return to_mandel(R @ basis @ R.T).T


def rotated(stiffness: np.ndarray, R: np.ndarray) -> np.ndarray:
    """The Mandel stiffness of the material turned by R: Q C Qᵀ, i.e. C'_ijkl = R_ia R_jb R_kc R_ld C_abcd."""
    Q = rotation(R)
    return Q @ stiffness @ Q.T


def plane_strain(stiffness: np.ndarray) -> np.ndarray:
    """The 2D stiffness of a 3D one under plane strain (ε₃₃ = ε₁₃ = ε₂₃ = 0): its (11, 22, 12) block."""
    return stiffness[np.ix_(_PLANE, _PLANE)]


def out_of_plane_row(stiffness: np.ndarray) -> np.ndarray:
    """The row r of a 3D stiffness with σ₃₃ = r · ε_M under plane strain (ε_M the 2D Mandel vector)."""
    return stiffness[2, list(_PLANE)]


def frame(axis) -> np.ndarray:
    """A rotation R (3 × 3) with R e₃ = axis / |axis|; a 2D axis is taken in the x–y plane."""
    a = np.zeros(3)
    a[:len(axis)] = axis
    a /= np.linalg.norm(a)
    helper = np.eye(3)[np.argmin(np.abs(a))]
    e1 = np.cross(helper, a)
    e1 /= np.linalg.norm(e1)
    return np.column_stack([e1, np.cross(a, e1), a])


def vector_cf(tensor: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
    """ε_M of a d × d matrix CoefficientFunction (its symmetric part is taken: ε_ij and ε_ji are averaged)."""
    dim = tensor.dims[0]
    return ngs.CF(tuple(w * (tensor[i, j] if i == j else 0.5 * (tensor[i, j] + tensor[j, i]))
                        for w, (i, j) in zip(weights(dim), PAIRS[dim])))


def tensor_cf(vector: ngs.CoefficientFunction, dim: int) -> ngs.CoefficientFunction:
    """The d × d symmetric matrix CoefficientFunction of a Mandel vector CoefficientFunction."""
    index = {}
    for k, (i, j) in enumerate(PAIRS[dim]):
        index[i, j] = index[j, i] = k
    w = weights(dim)
    return ngs.CF(tuple(vector[index[i, j]] / w[index[i, j]] for i in range(dim) for j in range(dim)),
                  dims=(dim, dim))


def matrix_cf(matrix: np.ndarray) -> ngs.CoefficientFunction:
    """A constant m × m matrix as a CoefficientFunction."""
    return ngs.CF(tuple(float(v) for v in np.asarray(matrix).ravel()), dims=np.shape(matrix))


def tangent_cf(derivative: ngs.CoefficientFunction, dim: int) -> ngs.CoefficientFunction:
    """The Mandel tangent (m × m) of dσ/dε given as a (d, d, d, d) CoefficientFunction T_ijkl = ∂σ_ij/∂ε_kl.

    The strain entries ε_kl and ε_lk are independent variables of T, so the Mandel entry is
    C_IJ = w_I w_J (T_ijkl + T_ijlk) / 2 for I = (i, j), J = (k, l).
    """
    flat = derivative.Reshape((dim * dim, dim * dim))
    w = weights(dim)
    return ngs.CF(tuple(w[a] * w[b] * 0.5 * (flat[i * dim + j, k * dim + m] + flat[i * dim + j, m * dim + k])
                        for a, (i, j) in enumerate(PAIRS[dim]) for b, (k, m) in enumerate(PAIRS[dim])),
                  dims=(size(dim), size(dim)))
