"""Elasticity laws σ = F(ε) (paper H(F)): strongly monotone with m_F, Lipschitz with L_F.

    (F(ε₁) − F(ε₂)) : (ε₁ − ε₂) ≥ m_F |ε₁ − ε₂|²,      |F(ε₁) − F(ε₂)| ≤ L_F |ε₁ − ε₂|.

Every law here is hyperelastic, σ = ∂ψ/∂ε, with a symmetric tangent D(ε) = ∂σ/∂ε; in Mandel notation
(:mod:`ngwear.model.mandel`) m_F = inf_ε λ_min(D(ε)) and L_F = sup_ε max |λ(D(ε))|.  A law is a frozen dataclass
whose methods return NGSolve CoefficientFunctions of a d × d strain ε:

- ``stress(ε)`` σ,  ``energy(ε)`` ψ,  ``tangent(ε)`` D in Mandel notation (m × m);
- ``elastic_integrand(u, v)`` = σ(ε(u)) : ε(v): with u a TrialFunction, the bilinear form of a linear law, or the
  residual of a nonlinear one (NGSolve's ``Apply`` and ``AssembleLinearization`` evaluate and linearise it);
- ``tangent_integrand(ε, u, v)`` = D(ε) ε(u) : ε(v), the bilinear form of the tangent at the strain ε;
- ``tangent_at_zero()`` the linear law a fixed stiffness K₀ is built from; ``is_linear``;
- ``monotonicity`` m_F and ``lipschitz`` L_F in closed form (:mod:`ngwear.model.moduli` samples any law, e.g.
  :class:`Energy`, at the integration points of a strain field or at given strains).

Laws: :class:`Isotropic` (Hooke), :class:`Anisotropic` (any Mandel stiffness), :class:`TransverselyIsotropic`,
:class:`Compaction` (stiffer in compression) and :class:`Energy` (a user's ψ, differentiated by NGSolve).
2D is plane strain (ε₃₃ = ε₁₃ = ε₂₃ = 0).  A law that is not positive definite is refused with a
:class:`SceneError` naming the scene key (``key`` is the table, ``material`` or ``material.regions.NAME``).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import ClassVar

import ngsolve as ngs
import numpy as np

from . import mandel
from .keys import SceneError
from .moduli import tangent_at


def strain(u) -> ngs.CoefficientFunction:
    """ε(u) = (∇u + ∇uᵀ)/2."""
    return ngs.Sym(ngs.Grad(u))


def _iso_stiffness(lam: float, eta: float, dim: int) -> np.ndarray:
    """Mandel stiffness of σ = 2η ε + λ tr(ε) I: 2η 1 + λ i iᵀ (i = I_M); eigenvalues 2η and 2η + dλ."""
    i = mandel.to_mandel(np.eye(dim))
    return 2 * eta * np.eye(mandel.size(dim)) + lam * np.outer(i, i)


def _positive(key: str, value: float) -> None:
    if not value > 0:
        raise SceneError(f"{key}: must be > 0 (got {value!r})")


def _check_lame(key: str, lam: float, eta: float, dim: int) -> None:
    _positive(f"{key}.lame_mu", eta)
    if not 2 * eta + dim * lam > 0:
        raise SceneError(f"{key}.lame_lambda: the stiffness is not positive definite: need λ > −2η/{dim} = "
                         f"{-2 * eta / dim:.6g} (got λ = {lam!r})")


class _Linear:
    """What every linear law shares, given its Mandel ``matrix`` and ``dim``."""

    is_linear: ClassVar[bool] = True
    matrix: np.ndarray
    dim: int

    def stress(self, eps: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
        return mandel.tensor_cf(mandel.matrix_cf(self.matrix) * mandel.vector_cf(eps), self.dim)

    def energy(self, eps: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
        e = mandel.vector_cf(eps)
        return 0.5 * ngs.InnerProduct(mandel.matrix_cf(self.matrix) * e, e)

    def tangent(self, eps: ngs.CoefficientFunction | None = None) -> ngs.CoefficientFunction:
        return mandel.matrix_cf(self.matrix)

    def elastic_integrand(self, u, v) -> ngs.CoefficientFunction:
        """C_ijkl ∂_l u_k ∂_j v_i (= C ε(u) : ε(v)): on the gradients, twice as fast to assemble as in Mandel form."""
        flat = self.dim ** 2
        tensor = mandel.fourth_order(self.matrix).reshape(flat, flat)
        return ngs.InnerProduct(mandel.matrix_cf(tensor) * ngs.Grad(u).Reshape((flat,)), ngs.Grad(v).Reshape((flat,)))

    def tangent_integrand(self, eps, u, v) -> ngs.CoefficientFunction:
        return self.elastic_integrand(u, v)

    def tangent_at_zero(self):
        return self

    @property
    def monotonicity(self) -> float:
        return float(np.linalg.eigvalsh(self.matrix)[0])

    @property
    def lipschitz(self) -> float:
        return float(np.abs(np.linalg.eigvalsh(self.matrix)).max())


@dataclass(frozen=True)
class Isotropic(_Linear):
    """Hooke: σ = 2η ε + λ tr(ε) I,  ψ = η |ε|² + λ/2 tr(ε)²;  m_F = min(2η, 2η + dλ), L_F = max(2η, 2η + dλ).

    Positive definite iff η > 0 and 2η + dλ > 0.
    """

    lam: float
    eta: float
    dim: int
    key: str = field(default="material", repr=False, compare=False)

    def __post_init__(self):
        _check_lame(self.key, self.lam, self.eta, self.dim)

    @cached_property
    def matrix(self) -> np.ndarray:
        return _iso_stiffness(self.lam, self.eta, self.dim)

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
    Positive definite iff E_p, E_a, G_a > 0, |ν_p| < 1 and ν_ap² < (1 − ν_p) E_a / (2 E_p).
    """

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
            _positive(f"{k}.{name}", getattr(self, name))
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

    @cached_property
    def matrix(self) -> np.ndarray:
        C = mandel.rotated(np.linalg.inv(self.compliance_local), mandel.frame(self.axis))
        C = 0.5 * (C + C.T)
        return mandel.plane_strain(C) if self.dim == 2 else C


@dataclass(frozen=True)
class Compaction:
    """Stiffer in compression: σ = 2η ε + λ tr(ε) I + β min(tr ε, 0) I,  ψ = η|ε|² + λ/2 tr(ε)² + β/2 min(tr ε, 0)².

    The tangent is Hooke's with λ for tr ε > 0 and λ + β for tr ε ≤ 0 (the compressed side at the kink), so
    m_F = 2η + d min(0, λ, λ + β) and L_F = max(2η, |2η + dλ|, |2η + d(λ + β)|); for λ, β ≥ 0: m_F = 2η,
    L_F = 2η + d(λ + β).  ``tangent_at_zero`` is the compressed tangent Isotropic(λ + β, η), the stiffest.
    """

    is_linear: ClassVar[bool] = False
    lam: float
    eta: float
    beta: float
    dim: int
    key: str = field(default="material", repr=False, compare=False)

    def __post_init__(self):
        _check_lame(self.key, self.lam, self.eta, self.dim)
        if not self.beta >= 0:
            raise SceneError(f"{self.key}.compaction_modulus: must be >= 0 (got {self.beta!r})")

    def stress(self, eps):
        tr = ngs.Trace(eps)
        return 2 * self.eta * eps + (self.lam * tr + self.beta * ngs.IfPos(tr, 0, tr)) * ngs.Id(self.dim)

    def energy(self, eps):
        tr = ngs.Trace(eps)
        return self.eta * ngs.InnerProduct(eps, eps) + 0.5 * self.lam * tr ** 2 + 0.5 * self.beta * ngs.IfPos(
            tr, 0, tr ** 2)

    def tangent(self, eps):
        return ngs.IfPos(ngs.Trace(eps), mandel.matrix_cf(_iso_stiffness(self.lam, self.eta, self.dim)),
                         mandel.matrix_cf(_iso_stiffness(self.lam + self.beta, self.eta, self.dim)))

    def elastic_integrand(self, u, v):
        return ngs.InnerProduct(self.stress(strain(u)), strain(v))

    def tangent_integrand(self, eps, u, v):
        """2η ε(u) : ε(v) + (λ + β [tr ε ≤ 0]) tr ε(u) tr ε(v): :meth:`tangent` without its m × m matrices."""
        stiffened = self.lam + self.beta * ngs.IfPos(ngs.Trace(eps), 0.0, 1.0)
        return (2 * self.eta * ngs.InnerProduct(strain(u), strain(v))
                + stiffened * ngs.Trace(strain(u)) * ngs.Trace(strain(v)))

    def tangent_at_zero(self) -> Isotropic:
        return Isotropic(self.lam + self.beta, self.eta, self.dim, key=self.key)

    def linear_part(self) -> Isotropic:
        """Hooke's law without the kink: Isotropic(λ, η)."""
        return Isotropic(self.lam, self.eta, self.dim, key=self.key)

    @property
    def monotonicity(self) -> float:
        return 2 * self.eta + self.dim * min(0.0, self.lam, self.lam + self.beta)

    @property
    def lipschitz(self) -> float:
        return max(2 * self.eta, abs(2 * self.eta + self.dim * self.lam),
                   abs(2 * self.eta + self.dim * (self.lam + self.beta)))


@dataclass(frozen=True)
class Energy:
    """A user's strain energy ψ(ε) (a callable returning an NGSolve expression of the d × d strain).

    σ = sym ∂ψ/∂ε and D = ∂σ/∂ε come from NGSolve's symbolic differentiation (``MakeVariable``, ``Diff``); the
    entries ε_ij and ε_ji are independent variables there, and the symmetric part of ∂ψ/∂ε is the stress of ψ on
    symmetric tensors.  m_F and L_F have no closed form: :func:`~ngwear.model.moduli.estimate_moduli` samples them.
    """

    is_linear: ClassVar[bool] = False
    psi: Callable[[ngs.CoefficientFunction], ngs.CoefficientFunction]
    dim: int
    key: str = field(default="material", repr=False, compare=False)

    def energy(self, eps):
        return self.psi(eps)

    def stress(self, eps):
        variable = eps.MakeVariable()
        return self._stress_of(variable)

    def _stress_of(self, variable):
        return ngs.Sym(self.psi(variable).Diff(variable))

    def tangent(self, eps):
        variable = eps.MakeVariable()
        return mandel.tangent_cf(self._stress_of(variable).Diff(variable), self.dim)

    def elastic_integrand(self, u, v):
        return ngs.InnerProduct(self.stress(strain(u)), strain(v))

    def tangent_integrand(self, eps, u, v):
        return ngs.InnerProduct(self.tangent(eps) * mandel.vector_cf(strain(u)), mandel.vector_cf(strain(v)))

    def tangent_at_zero(self) -> Anisotropic:
        """The linear law of D(0)."""
        C = tangent_at(self, np.zeros((1, self.dim, self.dim)))[0]
        return Anisotropic(tuple(map(tuple, 0.5 * (C + C.T))), key=self.key)


LAW_KEYS = {
    # law: (the ways to give its constants (one of them, whole), keys it may also take)
    "linear": ((("lame_lambda", "lame_mu"), ("young", "poisson")), ()),
    "transversely_isotropic": ((("young_plane", "young_axis", "poisson_plane", "poisson_axis", "shear_axis"),),
                               ("axis",)),
    "compaction": ((("lame_lambda", "lame_mu", "compaction_modulus"), ("young", "poisson", "compaction_modulus")),
                   ()),
    "energy": ((("energy",),), ()),
}
"""What each ``material.law`` needs; any other constant is refused."""
_CONSTANTS = sorted({k for ways, optional in LAW_KEYS.values() for way in ways for k in (*way, *optional)})


def check_table(table, key: str) -> None:
    """Refuse a material table whose constants do not fit its law: one line naming the key (``key.young``)."""
    law = table.kind
    ways, optional = LAW_KEYS[law]
    given = {name for name in _CONSTANTS if getattr(table, name) is not None}
    allowed = {k for way in ways for k in way} | set(optional)
    choices = "either " + ", or ".join(_listing(way) for way in ways) if len(ways) > 1 else _listing(ways[0])
    stray = sorted(given - allowed)
    if stray:
        raise SceneError(f"{key}.{stray[0]}: not a constant of material.law = {law!r} (give {choices})")
    common = set.intersection(*(set(way) for way in ways))
    used = [way for way in ways if (set(way) - common) & given]
    if len(used) > 1:
        first, second = (next(k for k in way if k in given and k not in common) for way in used[:2])
        raise SceneError(f"{key}.{second}: cannot be combined with {key}.{first} (give {choices})")
    way = used[0] if used else ways[0]
    missing = [name for name in way if name not in given]
    if missing:
        raise SceneError(f"{key}.{missing[0]}: missing ({_listing(way)} go together)")


def _listing(names) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return " and ".join([", ".join(names[:-1]), names[-1]] if len(names) > 1 else names)


def law_of(table, dim: int, direction, key: str = "material"):
    """The law of a checked material table (``direction``: the default axis of a transversely isotropic one)."""
    law = table.kind
    if law == "linear":
        return Isotropic(*table.lame, dim, key=key)
    if law == "compaction":
        return Compaction(*table.lame, table.compaction_modulus, dim, key=key)
    if law == "transversely_isotropic":
        return TransverselyIsotropic(table.young_plane, table.young_axis, table.poisson_plane, table.poisson_axis,
                                     table.shear_axis, tuple(table.axis or direction), key=key)
    from .functions import resolve
    return Energy(resolve(table.energy, f"{key}.energy"), dim, key=key)


def region_laws(scene) -> dict:
    """{region: law} of a scene: each region's table over ``[material]``, the axis defaulting to ν."""
    material, direction = scene.material, scene.contact.direction
    return {name: law_of(table, scene.dim, direction, f"material.regions.{name}" if name in material.regions
                         else "material")
            for name, table in material.by_region(scene.geometry.regions).items()}


def young_along(law, direction) -> float:
    """E_n = 1 / (n⊗n : S : n⊗n), S = D(0)⁻¹: the modulus of a uniaxial stress along the unit vector n."""
    n = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    dyad = mandel.to_mandel(np.outer(n, n)[None])[0]
    return float(1.0 / (dyad @ np.linalg.solve(law.tangent_at_zero().matrix, dyad)))
