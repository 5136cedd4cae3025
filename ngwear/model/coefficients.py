"""Contact coefficients that vary over Γ_C (paper H(p), (H_0)): μ(x), κ(x) and the compliance's L(x).

``contact.friction``, ``contact.wear`` and ``contact.stiffness`` each take a number, an expression in x, y, z
(:mod:`ngwear.model.expressions`), or in Python an array with one value per contact point or a function
``f(points) -> values`` (kept by token, :mod:`ngwear.model.functions`).  :func:`normalised` checks what it can
before the mesh exists (a number's range, an expression's syntax, an array's values); :func:`at_points`
evaluates a coefficient at the contact points and checks every value against the key's range, naming the key
and the first point that is off.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import expressions, functions
from .keys import SceneError, range_text

RANGES = {"friction": {"lo": 0}, "wear": {"lo": 0}, "stiffness": {"lo": 0, "lo_open": True}}
"""The range of each coefficient, at every contact point."""


def normalised(value, name: str):
    """A float, a checked expression (or function token) string, or a tuple of floats; a SceneError otherwise."""
    key, bounds = f"contact.{name}", RANGES[name]
    if isinstance(value, bool):
        raise SceneError(f"{key}: must be a number, an expression in x, y, z or a list of numbers (got {value!r})")
    if isinstance(value, (int, float)):
        rule = range_text(bounds["lo"], lo_open=bounds.get("lo_open", False))
        if not np.isfinite(value):
            raise SceneError(f"{key}: must be a finite number {rule} (got {value!r})")
        if value < bounds["lo"] or (bounds.get("lo_open") and value == bounds["lo"]):
            raise SceneError(f"{key}: must be {rule} (got {value!r})")
        return float(value)
    if isinstance(value, str):
        if not functions.is_token(value):
            expressions.Expression.parse(value, key)
        return value
    try:
        values = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        values = None
    if values is None or values.ndim != 1 or not len(values):
        raise SceneError(f"{key}: must be a number, an expression in x, y, z or a list of numbers (got {value!r})")
    return tuple(float(v) for v in check(key, values, None))


def check(key: str, values: np.ndarray, points: np.ndarray | None) -> np.ndarray:
    """``values`` checked against the range of ``key`` (``points``: where they are, for the message)."""
    at = points if points is not None else np.zeros((len(values), 3))
    return expressions.check_values(key, values, at, **RANGES[key.split(".")[-1]])


def at_points(value, name: str, points: np.ndarray) -> np.ndarray:
    """The coefficient ``contact.<name>`` at the contact points (n × d): one value per point, checked."""
    key = f"contact.{name}"
    if isinstance(value, str) and functions.is_token(value):
        value = functions.resolve(value, key)
    return expressions.values_at(value, key, points, **RANGES[name])


def bound(value) -> float | None:
    """The largest value of a coefficient, where it is known without the mesh (a number or an array), else None."""
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, tuple):
        return max(value)
    return None


def describe(value) -> str:
    """A short text of a coefficient for summaries and titles."""
    if isinstance(value, (int, float)):
        return f"{value:g}"
    if isinstance(value, tuple):
        return f"{len(value)} values in [{min(value):g}, {max(value):g}]"
    return value


@dataclass(frozen=True)
class Coefficients:
    """μ_i, κ_i and L_i at the contact points, each of shape (n,)."""

    friction: np.ndarray
    wear: np.ndarray
    stiffness: np.ndarray

    @classmethod
    def of(cls, contact, points: np.ndarray) -> Coefficients:
        return cls(*(at_points(getattr(contact, name), name, points) for name in ("friction", "wear", "stiffness")))
