"""Constitutive laws: normal compliance p and Hooke's elasticity.

Compliance (paper H(p)): p Lipschitz, non-decreasing, p(r) = 0 for r ≤ 0.
``linear``: p(r) = L r₊ (paper: L = 10);  ``power``: p(r) = c r₊^e, e ≥ 1.
Elasticity (paper §5): F(ε) = 2η ε + λ tr(ε) I.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import ngsolve as ngs
import numpy as np


@dataclass(frozen=True)
class Compliance:
    """p(r) = stiffness · r₊^exponent (exponent 1: the paper's linear law)."""

    stiffness: float
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

    def cf(self, r: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
        """The same law as an NGSolve CoefficientFunction of r (its derivative at r = 0 is that of :meth:`derivative`)."""
        if self.exponent == 1.0:
            return self.stiffness * ngs.IfPos(-r, 0, r)
        return self.stiffness * ngs.IfPos(r, r ** self.exponent, 0)   # pow inside: its derivative at 0 is 0, not NaN


    def energy_cf(self, r: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
        """Its primitive P(r) = ∫₀^r p = stiffness · r₊^(exponent+1) / (exponent + 1), so P' = :meth:`cf`.

        For the linear law P'' = L at r = 0 too (the r ≥ 0 branch is taken there, as in :meth:`derivative`).
        """
        if self.exponent == 1.0:
            return 0.5 * self.stiffness * ngs.IfPos(-r, 0, r * r)
        return self.stiffness / (self.exponent + 1) * ngs.IfPos(r, r ** (self.exponent + 1), 0)


def compliance_from(contact) -> Compliance:
    """The compliance law a scene's ``[contact]`` table describes."""
    return Compliance(contact.stiffness, contact.exponent if contact.law == "power" else 1.0)


def largest_slope(contact) -> float:
    """L_p, the largest slope of the compliance p over [0, g]: L e g^(e−1) (inf where it overflows)."""
    e = contact.exponent if contact.law == "power" else 1.0
    try:
        return contact.stiffness * e * contact.gap ** (e - 1)
    except OverflowError:
        return math.inf


def piecewise_linear(table, t: float) -> float:
    """Value at t of the piecewise-linear function through ``[(t, f), ...]`` (1 for an empty table)."""
    if not table:
        return 1.0
    ts, fs = zip(*table)
    return float(np.interp(t, ts, fs))
