"""The wear law's protocol, the registry of ``contact.wear_law`` and the default law, Archard's (:class:`Archard`).

The other laws are the package's modules (:mod:`ngwear.model.wear_laws`), each registering its own.
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np

from ..keys import Constant

WEAR_LAWS: dict[str, type[WearLaw]] = {}
"""The laws a scene names (``contact.wear_law``), in the order of the documentation; the first is the default."""


class WearLaw:
    """A wear law w' = α g(p): its declaration (class attributes) and what the numerics need of it (the protocol).

    Declaration: ``name`` (``contact.wear_law``), ``doc``, ``constants`` (its keys of ``[contact]`` besides κ),
    ``speed_exponent`` a (α is homogeneous of degree a in ‖v*‖: a stop's ∫α dt is α at the stop's effective
    sliding, :meth:`sliding`), :meth:`of` and :meth:`kappa_unit`.  Protocol, on arrays over the contact points:
    :meth:`alpha`, :meth:`g`, :meth:`dg`, :meth:`rate` and :meth:`slope`; ``linear``: g(p) = p (the integrators'
    closed forms for a linear compliance apply).
    """

    name: ClassVar[str]
    doc: ClassVar[str]
    constants: ClassVar[tuple[Constant, ...]] = ()
    linear: ClassVar[bool] = True
    speed_exponent: float = 1.0

    @classmethod
    def of(cls, contact) -> WearLaw:
        """The law of a scene's ``[contact]`` table."""
        return cls()

    @classmethod
    def check(cls, contact) -> None:
        """Refuse constants of a ``[contact]`` table that make no law: a SceneError naming the key (none here)."""

    def alpha(self, kappa: np.ndarray, friction: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """α_i of κ_i, μ_i and ‖v*_i‖."""
        raise NotImplementedError

    def g(self, p: np.ndarray) -> np.ndarray:
        """g(p); the pressure itself for a linear law."""
        return p

    def dg(self, p: np.ndarray) -> np.ndarray | float:
        """g'(p)."""
        return 1.0

    def rate(self, alpha: np.ndarray, p: np.ndarray) -> np.ndarray:
        """W' = α g(p)."""
        return alpha * self.g(p)

    def slope(self, alpha: np.ndarray, compliance, gap: float) -> np.ndarray:
        """α g'(p(g)) L_p: the largest ∂w'/∂r over the layer r ∈ [0, g] (g convex: its slope is largest at p(g))."""
        slope = alpha * compliance.slope(gap)
        return slope if self.linear else slope * self.dg(compliance(np.asarray(gap, dtype=float)))

    def sliding(self, factors: np.ndarray, local: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """The effective sliding of a stop, (∫|s_v|^a dt)^(1/a) ‖v*_i‖: α of it is ∫ α dt over the stop's grid.

        ``factors`` s_v and ``local`` the times of the stop's grid (trapezoidal rule), ``speed`` ‖v*_i‖ at s_v = 1.
        """
        a, magnitude = self.speed_exponent, np.abs(factors)
        weighted = magnitude if a == 1 else magnitude ** a
        integral = float(np.trapezoid(weighted, local))
        return (integral if a == 1 else integral ** (1 / a)) * speed

    def factor_power(self, factor: float) -> float:
        """|s|^a: how α scales with the speed factor (the largest α of a run is α at s_v = 1 times this)."""
        return factor if self.speed_exponent == 1 else factor ** self.speed_exponent

    @classmethod
    def kappa_unit(cls, contact) -> str:
        """The unit of κ in an SI scene (w' in m/s)."""
        return "1/Pa"


def register(law: type[WearLaw]) -> type[WearLaw]:
    """Add a law to :data:`WEAR_LAWS` under its ``name`` (a class decorator)."""
    WEAR_LAWS[law.name] = law
    return law


@register
class Archard(WearLaw):
    """Archard's law (the paper's, the default): w' = κ ‖v*‖ p, α = κ ‖v*‖, g(p) = p; the worn volume κ F s."""

    name: ClassVar[str] = "archard"
    doc: ClassVar[str] = "w' = κ ‖v*‖ p (the paper's)"

    def alpha(self, kappa, friction, speed):
        return kappa * speed


def wear_law(contact) -> WearLaw:
    """The wear law of a scene's ``[contact]`` table."""
    return WEAR_LAWS[contact.wear_law].of(contact)


def constants() -> tuple[Constant, ...]:
    """Every key of ``[contact]`` the laws declare, each once, in the order of registration."""
    return tuple(dict.fromkeys(c for law in WEAR_LAWS.values() for c in law.constants))
