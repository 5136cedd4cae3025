"""A generalised Archard law: w' = κ ‖v*‖^a p^b, with the exponents ``contact.wear_exponents = [a, b]``.

b ≥ 1 keeps the rate Lipschitz in the wear (its stability slope κ ‖v*‖^a b p(g)^(b−1) L_p is finite); a = b = 1 is
Archard's law.  κ has the unit m^(1−a) s^(a−1) Pa^(−b) in an SI scene (w' in m/s).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..keys import Constant, Level, SceneError, Vector
from .law import WEAR_LAWS, WearLaw, register

EXPONENTS = Constant("wear_exponents", Vector, "`wear_law = \"power\"`: [a, b] of w' = κ ‖v*‖^a p^b",
                     default=(1.0, 1.0), reuse=Level.NOTHING, shown="[1, 1]", allowed="a in [0, 4], b in [1, 4]")
BOUNDS = {"a": (0.0, 4.0), "b": (1.0, 4.0)}
"""The exponents' ranges (b ≥ 1: the rate stays Lipschitz in the wear)."""


@register
@dataclass(frozen=True)
class Power(WearLaw):
    """w' = κ ‖v*‖^a p^b:  α = κ ‖v*‖^a, g(p) = p^b."""

    name: ClassVar[str] = "power"
    doc: ClassVar[str] = "w' = κ ‖v*‖^a p^b (`contact.wear_exponents`)"
    constants: ClassVar[tuple] = (EXPONENTS,)
    linear: ClassVar[bool] = False
    speed_exponent: float = 1.0
    pressure_exponent: float = 1.0

    @classmethod
    def of(cls, contact):
        """The law of ``contact.wear_exponents``; [1, 1] is Archard's law itself."""
        a, b = contact.wear_exponents
        return WEAR_LAWS["archard"]() if (a, b) == (1.0, 1.0) else cls(a, b)

    @classmethod
    def check(cls, contact) -> None:
        """Two exponents, each within :data:`BOUNDS` (b ≥ 1: the rate stays Lipschitz in the wear)."""
        if len(contact.wear_exponents) != 2:
            raise SceneError(f"contact.wear_exponents: must be [a, b], two numbers (got {list(contact.wear_exponents)})")
        for name, value in zip("ab", contact.wear_exponents):
            low, high = BOUNDS[name]
            if not low <= value <= high:
                raise SceneError(f"contact.wear_exponents: {name} must be in [{low:g}, {high:g}] (got "
                                 f"{list(contact.wear_exponents)})")

    def alpha(self, kappa, friction, speed):
        """κ ‖v*‖^a where the foundation slides (0 elsewhere, also for a = 0)."""
        speed = np.asarray(speed, dtype=float)
        return np.where(speed > 0, kappa * np.maximum(speed, 0.0) ** self.speed_exponent, 0.0)

    def g(self, p):
        return np.maximum(p, 0.0) ** self.pressure_exponent

    def dg(self, p):
        b = self.pressure_exponent
        return b * np.maximum(p, 0.0) ** (b - 1) if b != 1 else np.ones_like(np.asarray(p, dtype=float))

    @classmethod
    def kappa_unit(cls, contact) -> str:
        a, b = contact.wear_exponents
        return f"m^{1 - a:g} s^{a - 1:g} Pa^{-b:g}"
