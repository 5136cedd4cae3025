"""The linear laws σ = C ε: Hooke's (``linear``), ``transversely_isotropic`` and :class:`Anisotropic` (any C).

Their Mandel stiffness C is constant, so m_F and L_F are its smallest and largest eigenvalues (in magnitude), and
their stiffness K is summed from the body's gradient blocks (:mod:`ngwear.numerics.stiffness`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import ClassVar

import ngsolve as ngs
import numpy as np

from .. import mandel
from ..keys import Constant, Number, SceneError, Vector
from .law import Law, register, strain

LAME_LAMBDA = Constant("lame_lambda", Number, "Lamé λ (Hooke: σ = 2η ε + λ tr ε I)", symbol="λ", modulus=True,
                       shown="1", limits={"ge": 0})
LAME_MU = Constant("lame_mu", Number, "Lamé η", symbol="η", modulus=True, shown="1", limits={"gt": 0})
YOUNG = Constant("young", Number, "Young's modulus E (instead of Lamé, with `material.poisson`)", symbol="E",
                 modulus=True, limits={"gt": 0})
POISSON = Constant("poisson", Number, "Poisson's ratio ν", symbol="ν", limits={"gt": -1, "le": 0.499})
HOOKE = ((LAME_LAMBDA, LAME_MU), (YOUNG, POISSON))
"""The two ways to give Hooke's constants."""


def lame(table) -> tuple[float, float]:
    """(λ, η) of a table that gives Hooke's constants; converts (E, ν) when those are given."""
    if table.young is not None:
        e, nu = table.young, table.poisson
        return e * nu / ((1 + nu) * (1 - 2 * nu)), e / (2 * (1 + nu))
    return table.lame_lambda, table.lame_mu


def iso_stiffness(lam: float, eta: float, dim: int) -> np.ndarray:
    """Mandel stiffness of σ = 2η ε + λ tr(ε) I: 2η 1 + λ i iᵀ (i = I_M); eigenvalues 2η and 2η + dλ."""
    i = mandel.to_mandel(np.eye(dim))
    return 2 * eta * np.eye(mandel.size(dim)) + lam * np.outer(i, i)


def positive(key: str, value: float) -> None:
    if not value > 0:
        raise SceneError(f"{key}: must be > 0 (got {value!r})")


def check_lame(key: str, lam: float, eta: float, dim: int) -> None:
    positive(f"{key}.lame_mu", eta)
    if not 2 * eta + dim * lam > 0:
        raise SceneError(f"{key}.lame_lambda: the stiffness is not positive definite: need λ > −2η/{dim} = "
                         f"{-2 * eta / dim:.6g} (got λ = {lam!r})")


class _Linear(Law):
    """What every linear law shares, given its Mandel ``matrix`` and ``dim``."""

    is_linear: ClassVar[bool] = True
    matrix: np.ndarray
    dim: int

    def stress(self, eps: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
        """σ_ij = C_ijkl ε_kl: one product of a constant d² × d² matrix (no conversion to and from Mandel vectors)."""
        flat = self.dim ** 2
        tensor = mandel.fourth_order(self.matrix).reshape(flat, flat)
        return (mandel.matrix_cf(tensor) * eps.Reshape((flat,))).Reshape((self.dim, self.dim))

    def energy(self, eps: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
        e = mandel.vector_cf(eps)
        return 0.5 * ngs.InnerProduct(mandel.matrix_cf(self.matrix) * e, e)

    def tangent(self, eps: ngs.CoefficientFunction | None = None) -> ngs.CoefficientFunction:
        return mandel.matrix_cf(self.matrix)

    def out_of_plane(self, eps: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
        """σ₃₃ = C₃₃ₖ ε_k over the in-plane Mandel components of the 3D stiffness (:attr:`stiffness_3d`)."""
        return ngs.InnerProduct(ngs.CF(tuple(mandel.out_of_plane_row(self.stiffness_3d))), mandel.vector_cf(eps))

    def elastic_integrand(self, u, v) -> ngs.CoefficientFunction:
        """C_ijkl ∂_l u_k ∂_j v_i (= C ε(u) : ε(v)): on the gradients, cheaper to assemble than in Mandel form."""
        flat = self.dim ** 2
        tensor = mandel.fourth_order(self.matrix).reshape(flat, flat)
        return ngs.InnerProduct(mandel.matrix_cf(tensor) * ngs.Grad(u).Reshape((flat,)), ngs.Grad(v).Reshape((flat,)))

    def tangent_integrand(self, eps, u, v) -> ngs.CoefficientFunction:
        return self.elastic_integrand(u, v)

    def tangent_at_zero(self):
        return self

    @property
    def stiffness_3d(self) -> np.ndarray:
        """The 3D Mandel stiffness (in 2D the one whose plane-strain block the law is): a thermal strain's stress."""
        if self.dim == 3:
            return self.matrix
        raise SceneError(f"{self.key}.expansion: a 2D law given by its in-plane stiffness alone has no plane-strain "
                         "thermal stress")

    @property
    def monotonicity(self) -> float:
        return float(np.linalg.eigvalsh(self.matrix)[0])

    @property
    def lipschitz(self) -> float:
        return float(np.abs(np.linalg.eigvalsh(self.matrix)).max())


@register
@dataclass(frozen=True)
class Isotropic(_Linear):
    """Hooke: σ = 2η ε + λ tr(ε) I,  ψ = η |ε|² + λ/2 tr(ε)²;  m_F = min(2η, 2η + dλ), L_F = max(2η, 2η + dλ).

    Positive definite iff η > 0 and 2η + dλ > 0.  The default law, with the paper's dimensionless λ = η = 1.
    """

    name: ClassVar[str] = "linear"
    doc: ClassVar[str] = "Hooke σ = 2η ε + λ tr ε I"
    ways: ClassVar[tuple] = HOOKE
    defaults: ClassVar[dict] = {"lame_lambda": 1.0, "lame_mu": 1.0}
    lam: float
    eta: float
    dim: int
    key: str = field(default="material", repr=False, compare=False)

    def __post_init__(self):
        check_lame(self.key, self.lam, self.eta, self.dim)

    @classmethod
    def of(cls, table, dim, direction, key):
        return cls(*lame(table), dim, key=key)

    @cached_property
    def matrix(self) -> np.ndarray:
        return iso_stiffness(self.lam, self.eta, self.dim)

    @property
    def stiffness_3d(self) -> np.ndarray:
        return iso_stiffness(self.lam, self.eta, 3)

    def stress(self, eps):
        return 2 * self.eta * eps + self.lam * ngs.Trace(eps) * ngs.Id(self.dim)

    def energy(self, eps):
        return self.eta * ngs.InnerProduct(eps, eps) + 0.5 * self.lam * ngs.Trace(eps) ** 2

    def elastic_integrand(self, u, v):
        return ngs.InnerProduct(self.stress(strain(u)), strain(v))


@dataclass(frozen=True)
class Anisotropic(_Linear):
    """σ_M = C ε_M with a symmetric positive definite Mandel stiffness C (m × m, m = 3 in 2D, 6 in 3D)."""

    stiffness: tuple[tuple[float, ...], ...]
    key: str = field(default="material", repr=False, compare=False)

    def __post_init__(self):
        C = np.asarray(self.stiffness, dtype=float)
        if C.shape not in ((3, 3), (6, 6)) or not np.allclose(C, C.T, rtol=1e-12, atol=0):
            raise SceneError(f"{self.key}.stiffness: must be a symmetric 3 × 3 (2D) or 6 × 6 (3D) Mandel matrix "
                             f"(got shape {C.shape})")
        smallest = np.linalg.eigvalsh(C)[0]
        if not smallest > 0:
            raise SceneError(f"{self.key}.stiffness: not positive definite (smallest eigenvalue {smallest:.6g})")
        object.__setattr__(self, "stiffness", tuple(map(tuple, C.tolist())))

    @cached_property
    def matrix(self) -> np.ndarray:
        return np.array(self.stiffness)

    @property
    def dim(self) -> int:
        return {3: 2, 6: 3}[len(self.stiffness)]

    def out_of_plane(self, eps):
        """None: a 2D stiffness alone does not give σ₃₃."""
        return None


def _plane(name: str, doc: str, symbol: str, *, modulus: bool = False, allowed: str | None = None,
           **limits) -> Constant:
    """A constant of the transversely isotropic law."""
    return Constant(name, Number, f"`transversely_isotropic`: {doc}", symbol=symbol, modulus=modulus,
                    allowed=allowed, limits=limits)


YOUNG_PLANE = _plane("young_plane", "E_p, Young's modulus in the plane ⟂ axis", "E_plane", modulus=True, gt=0)
YOUNG_AXIS = _plane("young_axis", "E_a, Young's modulus along the axis", "E_axis", modulus=True, gt=0)
POISSON_PLANE = _plane("poisson_plane", "ν_p, of a strain in the plane under stress in the plane", "ν_plane",
                       allowed="|ν_p| < 1")
POISSON_AXIS = _plane("poisson_axis", "ν_ap, of a strain in the plane under stress along the axis", "ν_axis",
                      allowed="ν_ap² < (1 − ν_p) E_a / (2 E_p)")
SHEAR_AXIS = _plane("shear_axis", "G_a, the shear modulus of planes containing the axis", "G_axis", modulus=True,
                    gt=0)
AXIS = Constant("axis", Vector, "`transversely_isotropic`: the symmetry axis", symbol="axis",
                shown="`contact.direction`", allowed="non-zero vector of d numbers")


@register
@dataclass(frozen=True)
class TransverselyIsotropic(_Linear):
    """Transversely isotropic about the unit vector ``axis`` (3 components in 3D, 2 in 2D plane strain).

    Five constants: in the isotropic plane ⟂ axis E_p (``young_plane``), ν_p (``poisson_plane``) and
    G_p = E_p / (2(1 + ν_p)); along the axis E_a (``young_axis``); ν_ap (``poisson_axis``) and G_a
    (``shear_axis``, the shear modulus of the planes containing the axis).  Convention: a uniaxial stress σ along
    the axis strains the axis by σ/E_a and every direction of the plane by −ν_ap σ/E_a; a uniaxial stress σ along
    e ⟂ axis strains e by σ/E_p, the other plane direction by −ν_p σ/E_p and the axis by −ν_pa σ/E_p with
    ν_pa = ν_ap E_p / E_a (the compliance is symmetric).  With axis = e₃, in Mandel notation
    (11, 22, 33, √2·23, √2·13, √2·12) the compliance is

        S = [[1/E_p, −ν_p/E_p, −ν_ap/E_a], [−ν_p/E_p, 1/E_p, −ν_ap/E_a], [−ν_ap/E_a, −ν_ap/E_a, 1/E_a]]
            ⊕ diag(1/(2G_a), 1/(2G_a), 1/(2G_p)),

    C = S⁻¹, turned onto ``axis`` (:func:`mandel.rotated`); in 2D the plane-strain block of the 3D C.
    Positive definite iff E_p, E_a, G_a > 0, |ν_p| < 1 and ν_ap² < (1 − ν_p) E_a / (2 E_p).  The axis defaults to ν.
    """

    name: ClassVar[str] = "transversely_isotropic"
    doc: ClassVar[str] = "(the `*_plane`, `*_axis` keys)"
    ways: ClassVar[tuple] = ((YOUNG_PLANE, YOUNG_AXIS, POISSON_PLANE, POISSON_AXIS, SHEAR_AXIS),)
    optional: ClassVar[tuple] = (AXIS,)
    young_plane: float
    young_axis: float
    poisson_plane: float
    poisson_axis: float
    shear_axis: float
    axis: tuple[float, ...]
    key: str = field(default="material", repr=False, compare=False)

    def __post_init__(self):
        k = self.key
        norm = float(np.linalg.norm(self.axis)) if len(self.axis) in (2, 3) else 0.0
        if not norm > 0 or not np.isfinite(norm):
            raise SceneError(f"{k}.axis: must be a non-zero vector of 2 (2D) or 3 (3D) numbers (got {list(self.axis)})")
        object.__setattr__(self, "axis", tuple(float(a) / norm for a in self.axis))
        for name in ("young_plane", "young_axis", "shear_axis"):
            positive(f"{k}.{name}", getattr(self, name))
        nu_p, nu_ap = self.poisson_plane, self.poisson_axis
        if not -1 < nu_p < 1:
            raise SceneError(f"{k}.poisson_plane: the stiffness is not positive definite: need |ν_p| < 1 "
                             f"(got ν_p = {nu_p!r})")
        bound = np.sqrt((1 - nu_p) * self.young_axis / (2 * self.young_plane))
        if not abs(nu_ap) < bound:
            raise SceneError(f"{k}.poisson_axis: the stiffness is not positive definite: need |ν_ap| < "
                             f"sqrt((1 − ν_p) E_a / (2 E_p)) = {bound:.6g} (got ν_ap = {nu_ap!r})")
        smallest = np.linalg.eigvalsh(self.matrix)[0]
        if not smallest > 0:   # the closed-form conditions above are exact; this guards round-off
            raise SceneError(f"{k}: the stiffness is not positive definite (smallest eigenvalue {smallest:.6g})")

    @classmethod
    def of(cls, table, dim, direction, key):
        return cls(table.young_plane, table.young_axis, table.poisson_plane, table.poisson_axis, table.shear_axis,
                   tuple(table.axis or direction), key=key)

    @property
    def dim(self) -> int:
        return len(self.axis)

    @cached_property
    def compliance_local(self) -> np.ndarray:
        """S in the frame whose third axis is ``axis`` (3D Mandel)."""
        Ep, Ea, nu_p, nu_ap = self.young_plane, self.young_axis, self.poisson_plane, self.poisson_axis
        S = np.zeros((6, 6))
        S[:3, :3] = [[1 / Ep, -nu_p / Ep, -nu_ap / Ea], [-nu_p / Ep, 1 / Ep, -nu_ap / Ea],
                     [-nu_ap / Ea, -nu_ap / Ea, 1 / Ea]]
        S[3, 3] = S[4, 4] = 1 / (2 * self.shear_axis)
        S[5, 5] = (1 + nu_p) / Ep
        return S

    @property
    def stiffness_3d(self) -> np.ndarray:
        return mandel.rotated(np.linalg.inv(self.compliance_local), mandel.frame(self.axis))

    @cached_property
    def matrix(self) -> np.ndarray:
        C = self.stiffness_3d
        C = 0.5 * (C + C.T)
        return mandel.plane_strain(C) if self.dim == 2 else C
