"""A user's strain energy ψ(ε) (Python only): σ = ∂ψ/∂ε and D = ∂σ/∂ε by NGSolve's symbolic differentiation."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ClassVar

import ngsolve as ngs
import numpy as np

from .. import mandel
from ..keys import Constant
from ..moduli import tangent_at
from .law import Law, register, strain
from .linear import Anisotropic

ENERGY = Constant("energy", str, "`energy` (Python only): a function ψ(ε) of the strain tensor returning an NGSolve "
                  "expression", shown="—", allowed="a Python function", function=True)


@register
@dataclass(frozen=True)
class Energy(Law):
    """A user's strain energy ψ(ε) (a callable returning an NGSolve expression of the d × d strain).

    σ = sym ∂ψ/∂ε and D = ∂σ/∂ε come from NGSolve's symbolic differentiation (``MakeVariable``, ``Diff``); the
    entries ε_ij and ε_ji are independent variables there, and the symmetric part of ∂ψ/∂ε is the stress of ψ on
    symmetric tensors.  Both are compiled (``Compile``): the differentiated expression trees, evaluated as they are,
    made assembling D many times slower, with the same numbers.  m_F and L_F have no closed
    form (``estimated``): :func:`~ngwear.model.moduli.estimate_moduli` samples them.
    """

    name: ClassVar[str] = "energy"
    doc: ClassVar[str] = "σ = ∂ψ/∂ε of a Python function ψ(ε) (`material.energy`)"
    ways: ClassVar[tuple] = ((ENERGY,),)
    estimated: ClassVar[bool] = True
    psi: Callable[[ngs.CoefficientFunction], ngs.CoefficientFunction]
    dim: int
    key: str = field(default="material", repr=False, compare=False)

    @classmethod
    def of(cls, table, dim, direction, key):
        from ..function_tokens import resolve
        return cls(resolve(table.energy, f"{key}.energy"), dim, key=key)

    @classmethod
    def check(cls, table, dim, direction, key):
        """Nothing to check before the run: ψ is a function of the session that runs the scene."""

    def energy(self, eps):
        return self.psi(eps)

    def stress(self, eps):
        variable = eps.MakeVariable()
        return self._stress_of(variable)

    def _stress_of(self, variable):
        return ngs.Sym(self.psi(variable).Diff(variable)).Compile()

    def tangent(self, eps):
        variable = eps.MakeVariable()
        return mandel.tangent_cf(self._stress_of(variable).Diff(variable), self.dim).Compile()

    def elastic_integrand(self, u, v):
        return ngs.InnerProduct(self.stress(strain(u)), strain(v))

    def tangent_integrand(self, eps, u, v):
        return ngs.InnerProduct(self.tangent(eps) * mandel.vector_cf(strain(u)), mandel.vector_cf(strain(v)))

    def tangent_at_zero(self) -> Anisotropic:
        """The linear law of D(0)."""
        C = tangent_at(self, np.zeros((1, self.dim, self.dim)))[0]
        return Anisotropic(tuple(map(tuple, 0.5 * (C + C.T))), key=self.key)
