"""The compaction law: Hooke's law stiffer in compression (a friction material's pores closing).

    σ = 2η ε + λ tr(ε) I + β min(tr ε, 0) I,      ψ = η|ε|² + λ/2 tr(ε)² + β/2 min(tr ε, 0)².

Its kink in tr ε makes it piecewise linear: :mod:`ngwear.numerics.kink` turns it into sparse algebra (``kinked``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import ngsolve as ngs

from .. import mandel
from ..keys import Constant, Number, SceneError
from .law import Law, register, strain
from .linear import HOOKE, Isotropic, check_lame, iso_stiffness, lame

COMPACTION_MODULUS = Constant("compaction_modulus", Number, "`compaction`: β, the extra bulk stiffness in compression "
                              "(σ = 2η ε + λ tr ε I + β min(tr ε, 0) I)", symbol="β", modulus=True, limits={"ge": 0})


@register
@dataclass(frozen=True)
class Compaction(Law):
    """Stiffer in compression: σ = 2η ε + λ tr(ε) I + β min(tr ε, 0) I,  ψ = η|ε|² + λ/2 tr(ε)² + β/2 min(tr ε, 0)².

    The tangent is Hooke's with λ for tr ε > 0 and λ + β for tr ε ≤ 0 (the compressed side at the kink), so
    m_F = 2η + d min(0, λ, λ + β) and L_F = max(2η, |2η + dλ|, |2η + d(λ + β)|); for λ, β ≥ 0: m_F = 2η,
    L_F = 2η + d(λ + β).  ``tangent_at_zero`` is the compressed tangent Isotropic(λ + β, η), the stiffest.
    """

    name: ClassVar[str] = "compaction"
    doc: ClassVar[str] = "Hooke stiffened in compression, σ += β min(tr ε, 0) I"
    ways: ClassVar[tuple] = tuple((*way, COMPACTION_MODULUS) for way in HOOKE)
    kinked: ClassVar[bool] = True
    lam: float
    eta: float
    beta: float
    dim: int
    key: str = field(default="material", repr=False, compare=False)

    def __post_init__(self):
        check_lame(self.key, self.lam, self.eta, self.dim)
        if not self.beta >= 0:
            raise SceneError(f"{self.key}.compaction_modulus: must be >= 0 (got {self.beta!r})")

    @classmethod
    def of(cls, table, dim, direction, key):
        return cls(*lame(table), table.compaction_modulus, dim, key=key)

    def stress(self, eps):
        tr = ngs.Trace(eps)
        return 2 * self.eta * eps + (self.lam * tr + self.beta * ngs.IfPos(tr, 0, tr)) * ngs.Id(self.dim)

    def out_of_plane(self, eps):
        tr = ngs.Trace(eps)
        return self.lam * tr + self.beta * ngs.IfPos(tr, 0, tr)

    def energy(self, eps):
        tr = ngs.Trace(eps)
        return self.eta * ngs.InnerProduct(eps, eps) + 0.5 * self.lam * tr ** 2 + 0.5 * self.beta * ngs.IfPos(
            tr, 0, tr ** 2)

    def tangent(self, eps):
        return ngs.IfPos(ngs.Trace(eps), mandel.matrix_cf(iso_stiffness(self.lam, self.eta, self.dim)),
                         mandel.matrix_cf(iso_stiffness(self.lam + self.beta, self.eta, self.dim)))

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
