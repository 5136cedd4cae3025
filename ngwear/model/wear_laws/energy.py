"""Wear by frictional work (the energy law of fretting): w' = κ_E μ p ‖v*‖, the worn volume κ_E × dissipated energy."""
from __future__ import annotations

from typing import ClassVar

from .law import WearLaw, register


@register
class Energy(WearLaw):
    """w' = κ_E μ ‖v*‖ p:  α = κ_E μ ‖v*‖, g(p) = p, κ_E = ``contact.wear`` (1/Pa: volume per dissipated energy)."""

    name: ClassVar[str] = "energy"
    doc: ClassVar[str] = "w' = κ μ ‖v*‖ p (wear by frictional work)"

    def alpha(self, kappa, friction, speed):
        return kappa * friction * speed
