"""Archard's law (the paper's): w' = κ ‖v*‖ p, the worn volume κ × normal force × sliding distance."""
from __future__ import annotations

from typing import ClassVar

from . import WearLaw, register


@register
class Archard(WearLaw):
    """w' = κ ‖v*‖ p:  α = κ ‖v*‖, g(p) = p."""

    name: ClassVar[str] = "archard"
    doc: ClassVar[str] = "w' = κ ‖v*‖ p (the paper's)"

    def alpha(self, kappa, friction, speed):
        return kappa * speed
