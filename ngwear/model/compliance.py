"""The normal compliance p (paper H(p)) and the piecewise-linear time tables.

p Lipschitz, non-decreasing, p(r) = 0 for r ≤ 0: ``linear`` p(r) = L r₊ (paper: L = 10), ``power``
p(r) = L r₊^e, e ≥ 1; L a number or one value per contact point (p(x, r), :mod:`ngwear.model.coefficients`).
The elasticity laws are in :mod:`ngwear.model.materials`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import ngsolve as ngs
import numpy as np


@dataclass(frozen=True, eq=False)
class Compliance:
    """p(r) = stiffness · r₊^exponent (exponent 1: the paper's linear law); stiffness a number or per point."""

    stiffness: float | np.ndarray
    exponent: float = 1.0

    def __call__(self, r: np.ndarray) -> np.ndarray:
        return self.stiffness * np.maximum(r, 0.0) ** self.exponent

    def derivative(self, r: np.ndarray) -> np.ndarray:
        """Generalised derivative p'(r): Heaviside · L for the linear law, taking L at the kink r = 0.

        Any value in [0, L] is a valid (Clarke) derivative at the kink; L keeps the Newton matrix regular
        for a body that starts touching the foundation and is held by a plate alone.
        """
        rp = np.maximum(r, 0.0)
        if self.exponent == 1.0:
            return np.where(r >= 0, self.stiffness, 0.0)
        return np.where(r > 0, self.stiffness * self.exponent * rp ** (self.exponent - 1), 0.0)

    def cf(self, r: ngs.CoefficientFunction, stiffness=None) -> ngs.CoefficientFunction:
        """The law as an NGSolve CoefficientFunction of r (its derivative at r = 0 is that of :meth:`derivative`).

        ``stiffness``: L as a CoefficientFunction (a field: its nodal GridFunction), else the number.
        """
        L = self.stiffness if stiffness is None else stiffness
        if self.exponent == 1.0:
            return L * ngs.IfPos(-r, 0, r)
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
        """Its primitive P(r) = ∫₀^r p = stiffness · r₊^(exponent+1) / (exponent + 1), so P' = :meth:`cf`.

        For the linear law P'' = L at r = 0 too (the r ≥ 0 branch is taken there, as in :meth:`derivative`).
        """
        if self.exponent == 1.0:
            return 0.5 * self.stiffness * ngs.IfPos(-r, 0, r * r)
        return self.stiffness / (self.exponent + 1) * ngs.IfPos(r, r ** (self.exponent + 1), 0)


def compliance_from(contact, stiffness=None) -> Compliance:
    """The compliance law of a scene's ``[contact]`` table; ``stiffness``: L at the contact points (a field)."""
    return Compliance(contact.stiffness if stiffness is None else stiffness,
                      contact.exponent if contact.law == "power" else 1.0)


def largest_slope(contact) -> float | None:
    """L_p, the largest slope of p over [0, g], from ``contact.stiffness`` (None for a field: see the points')."""
    from .coefficients import bound
    top = bound(contact.stiffness)
    return None if top is None else float(compliance_from(contact, top).slope(contact.gap))


def piecewise_linear(table, t: float) -> float:
    """Value at t of the piecewise-linear function through ``[(t, f), ...]`` (1 for an empty table)."""
    if not table:
        return 1.0
    ts, fs = zip(*table)
    return float(np.interp(t, ts, fs))
