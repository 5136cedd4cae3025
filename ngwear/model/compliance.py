"""The normal compliance p (paper H(p)): the contact laws of ``contact.law``, each declared once.

p Lipschitz, non-decreasing, p(r) = 0 for r ≤ 0: ``linear`` p(r) = L r₊ (paper: L = 10), ``power``
p(r) = L r₊^e, e ≥ 1; L a number or one value per contact point (p(x, r), :mod:`ngwear.model.coefficients`).
A law is a :class:`Compliance` registered with :func:`register`: it declares its ``contact.law`` name, its line of
documentation and the keys of ``[contact]`` it takes besides L (:class:`~ngwear.model.keys.Constant`; the scene's
``[contact]`` table, its schema and the rule that other laws' keys keep their defaults follow from them), and it
gives the numerics p, p' and its NGSolve form.  The elasticity laws are in :mod:`ngwear.model.materials`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import ngsolve as ngs
import numpy as np

from .keys import Constant, Level, Number

COMPLIANCES: dict[str, type[Compliance]] = {}
"""The laws a scene names (``contact.law``), in the order of the documentation; the first is the default."""


class Compliance:
    """A compliance law p: its declaration (class attributes) and what the numerics need of it (the protocol).

    Declaration: ``name`` (``contact.law``), ``doc``, ``constants`` (its keys of ``[contact]`` besides L) and
    :meth:`of`.  Protocol: ``stiffness`` L (a number or one value per contact point); ``p(r)`` (calling the law) and
    :meth:`derivative` on arrays; :meth:`cf`, its NGSolve CoefficientFunction; :meth:`slope`, its largest slope on
    [0, g]; :meth:`energy_cf`, its primitive; ``is_linear``: piecewise linear (the wear update has a closed form,
    and the semismooth Newton method ends in finitely many steps).
    """

    name: ClassVar[str]
    doc: ClassVar[str]
    constants: ClassVar[tuple[Constant, ...]] = ()
    is_linear: ClassVar[bool] = False
    stiffness: float | np.ndarray

    @classmethod
    def of(cls, contact, stiffness) -> Compliance:
        """The law of a scene's ``[contact]`` table with L = ``stiffness`` (a number or per point)."""
        raise NotImplementedError


def register(law: type[Compliance]) -> type[Compliance]:
    """Add a law to :data:`COMPLIANCES` under its ``name`` (a class decorator)."""
    COMPLIANCES[law.name] = law
    return law


@register
@dataclass(frozen=True, eq=False)
class Linear(Compliance):
    """p(r) = L r₊ (the paper's law)."""

    name: ClassVar[str] = "linear"
    doc: ClassVar[str] = "L r₊"
    is_linear: ClassVar[bool] = True
    stiffness: float | np.ndarray

    @classmethod
    def of(cls, contact, stiffness):
        return cls(stiffness)

    def __call__(self, r: np.ndarray) -> np.ndarray:
        return self.stiffness * np.maximum(r, 0.0)

    def derivative(self, r: np.ndarray) -> np.ndarray:
        """Generalised derivative p'(r): Heaviside · L, taking L at the kink r = 0.

        Any value in [0, L] is a valid (Clarke) derivative at the kink; L keeps the Newton matrix regular
        for a body that starts touching the foundation and is held by a plate alone.
        """
        return np.where(r >= 0, self.stiffness, 0.0)

    def cf(self, r: ngs.CoefficientFunction, stiffness=None) -> ngs.CoefficientFunction:
        """The law as an NGSolve CoefficientFunction of r (its derivative at r = 0 is that of :meth:`derivative`).

        ``stiffness``: L as a CoefficientFunction (a field: its nodal GridFunction), else the number.
        """
        return (self.stiffness if stiffness is None else stiffness) * ngs.IfPos(-r, 0, r)

    def slope(self, gap: float):
        """L_p = L, the largest slope of p over [0, g] (per point for a field)."""
        return self.stiffness * 1.0

    def energy_cf(self, r: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
        """Its primitive P(r) = L r₊² / 2, so P' = :meth:`cf`; P'' = L at r = 0 too (as :meth:`derivative`)."""
        return 0.5 * self.stiffness * ngs.IfPos(-r, 0, r * r)


EXPONENT = Constant("exponent", Number, "e (power law only)", default=1.0, reuse=Level.NOTHING,
                    limits={"ge": 1, "le": 10})


@register
@dataclass(frozen=True, eq=False)
class Power(Compliance):
    """p(r) = L r₊^e, e > 1 (e = 1 is :class:`Linear`)."""

    name: ClassVar[str] = "power"
    doc: ClassVar[str] = "L r₊^e"
    constants: ClassVar[tuple] = (EXPONENT,)
    stiffness: float | np.ndarray
    exponent: float

    @classmethod
    def of(cls, contact, stiffness):
        return Linear(stiffness) if contact.exponent == 1.0 else cls(stiffness, contact.exponent)

    def __call__(self, r: np.ndarray) -> np.ndarray:
        return self.stiffness * np.maximum(r, 0.0) ** self.exponent

    def derivative(self, r: np.ndarray) -> np.ndarray:
        """p'(r) = L e r₊^(e−1) (0 at r = 0)."""
        return np.where(r > 0, self.stiffness * self.exponent * np.maximum(r, 0.0) ** (self.exponent - 1), 0.0)

    def cf(self, r: ngs.CoefficientFunction, stiffness=None) -> ngs.CoefficientFunction:
        """As :meth:`Linear.cf`."""
        L = self.stiffness if stiffness is None else stiffness
        return L * ngs.IfPos(r, r ** self.exponent, 0)   # pow inside: its derivative at 0 is 0, not NaN

    def slope(self, gap: float):
        """L_p = L e g^(e−1), the largest slope of p over [0, g] (per point for a field; inf where it overflows)."""
        try:
            factor = self.exponent * gap ** (self.exponent - 1)
        except OverflowError:
            return math.inf
        with np.errstate(over="ignore"):
            return self.stiffness * factor

    def energy_cf(self, r: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
        """Its primitive P(r) = L r₊^(e+1) / (e + 1), so P' = :meth:`cf`."""
        return self.stiffness / (self.exponent + 1) * ngs.IfPos(r, r ** (self.exponent + 1), 0)


def compliance_from(contact, stiffness=None) -> Compliance:
    """The compliance law of a scene's ``[contact]`` table; ``stiffness``: L at the contact points (a field)."""
    return COMPLIANCES[contact.law].of(contact, contact.stiffness if stiffness is None else stiffness)


def largest_slope(contact) -> float | None:
    """L_p, the largest slope of p over [0, g], from ``contact.stiffness`` (None for a field: see the points')."""
    from .coefficients import bound
    top = bound(contact.stiffness)
    return None if top is None else float(compliance_from(contact, top).slope(contact.gap))
