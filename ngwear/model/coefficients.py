"""Contact coefficients that vary over Γ_C (paper H(p), (H_0)): μ(x), κ(x) and the compliance's L(x).

``contact.friction``, ``contact.wear`` and ``contact.stiffness`` each take a number, an expression in x, y, z
(:mod:`ngwear.model.expressions`), or in Python an array with one value per contact point or a function
``f(points) -> values`` (kept by token, :mod:`ngwear.model.function_tokens`).  :func:`normalised` checks what it can
before the mesh exists (a number's range, an expression's syntax, an array's values); :func:`at_points`
evaluates a coefficient at the contact points and checks every value against the key's range, naming the key
and the first point that is off.

Coefficients of state: an expression may also name T, p, v (the surface temperature, the pressure and the sliding
speed at the point), and a table ``[[T, value], …]`` is piecewise linear in T (constant beyond its ends).  They are
evaluated from the last step's state (explicit: within a step each is a fixed field, the paper's L∞ coefficient),
:meth:`Coefficients.updated`; :func:`state_of` tells which state a coefficient depends on, so constant ones keep
their arrays and cost nothing.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import expressions, function_tokens
from .keys import SceneError, range_text

RANGES = {"contact.friction": {"lo": 0}, "contact.wear": {"lo": 0}, "contact.stiffness": {"lo": 0, "lo_open": True},
          "heat.contact_conductance": {"lo": 0}}
"""The range of each coefficient, at every contact point (by its dotted key)."""


def _key(name: str) -> str:
    """The dotted key of a coefficient: ``contact.<name>`` for a contact coefficient's name, else ``name`` itself."""
    return name if "." in name else f"contact.{name}"


def normalised(value, name: str):
    """A float, a checked expression (or function token) string, a tuple of floats or a table of T; else a SceneError."""
    key = _key(name)
    bounds = RANGES[key]
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
        if not function_tokens.is_token(value):
            expressions.Expression.parse(value, key)
        return value
    try:
        values = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        values = None
    if values is not None and values.ndim == 2 and values.shape[1:] == (2,) and len(values):
        return _table(key, values)
    if values is None or values.ndim != 1 or not len(values):
        raise SceneError(f"{key}: must be a number, an expression in x, y, z or a list of numbers (got {value!r})")
    return tuple(float(v) for v in check(key, values, None))


def _table(key: str, rows: np.ndarray) -> tuple[tuple[float, float], ...]:
    """A table [[T, value], …] with finite, increasing T and values in the key's range."""
    temperatures, values = rows.T
    if not np.isfinite(temperatures).all() or (np.diff(temperatures) <= 0).any():
        raise SceneError(f"{key}: the temperatures of a table [[T, value], …] must be finite and increasing (got "
                         f"{temperatures.tolist()})")
    bounds = RANGES[key]
    bad = ~np.isfinite(values) | (values <= bounds["lo"] if bounds.get("lo_open") else values < bounds["lo"])
    if bad.any():
        i = int(np.argmax(bad))
        raise SceneError(f"{key}: the values of a table [[T, value], …] must be finite and "
                         f"{range_text(bounds['lo'], lo_open=bounds.get('lo_open', False))} (got {values[i]:g} at "
                         f"T = {temperatures[i]:g})")
    return tuple((float(a), float(b)) for a, b in rows)


def is_table(value) -> bool:
    """Whether a normalised coefficient is a table of the temperature."""
    return isinstance(value, tuple) and bool(value) and isinstance(value[0], tuple)


def state_of(value, name: str) -> frozenset[str]:
    """The names of the state (T, p, v) the coefficient ``name`` (see :func:`_key`) depends on (empty: of x alone)."""
    if is_table(value):
        return frozenset({"T"})
    if isinstance(value, str) and not function_tokens.is_token(value):
        return expressions.Expression.parse(value, _key(name)).state
    return frozenset()


def check(key: str, values: np.ndarray, points: np.ndarray | None) -> np.ndarray:
    """``values`` checked against the range of ``key`` (``points``: where they are, for the message)."""
    at = points if points is not None else np.zeros((len(values), 3))
    return expressions.check_values(key, values, at, **RANGES[key])


def at_points(value, name: str, points: np.ndarray, state: dict | None = None, t: float | None = None) -> np.ndarray:
    """The coefficient ``name`` (``contact.<name>``, or a dotted key) at the contact points (n × d), checked.

    ``state``: {"T", "p", "v": arrays (n,)} at the points, for a coefficient of state (:func:`state_of`); a
    refusal names the key, the point, the state there and the time ``t``.
    """
    key = _key(name)
    bounds, needed = RANGES[key], state_of(value, name)
    if needed and state is None:
        raise SceneError(f"{key}: depends on the state ({', '.join(sorted(needed))}): evaluated with the state at "
                         "the points (the time loop's, ngwear.numerics.contact.Contact.update)")
    if is_table(value):
        temperatures, values = np.array(value).T
        return expressions.check_values(key, np.interp(state["T"], temperatures, values), points, state=state, t=t,
                                        **bounds)
    if isinstance(value, str) and function_tokens.is_token(value):
        value = function_tokens.resolve(value, key)
    return expressions.values_at(value, key, points, state if needed else None, t, **bounds)


def bound(value) -> float | None:
    """The largest value of a coefficient, where it is known without the mesh (a number, an array, a table)."""
    if isinstance(value, (int, float)):
        return float(value)
    if is_table(value):
        return max(v for _, v in value)
    if isinstance(value, tuple):
        return max(value)
    return None


def describe(value) -> str:
    """A short text of a coefficient for summaries and titles."""
    if isinstance(value, (int, float)):
        return f"{value:g}"
    if is_table(value):
        values = [v for _, v in value]
        return f"a table of T, values in [{min(values):g}, {max(values):g}]"
    if isinstance(value, tuple):
        return f"{len(value)} values in [{min(value):g}, {max(value):g}]"
    return value


NAMES = ("friction", "wear", "stiffness")
"""The coefficients of ``[contact]``, in the order of :class:`Coefficients`."""


def stateful(contact) -> tuple[str, ...]:
    """The names of the coefficients of ``contact`` that depend on the state (empty: all fixed for the run)."""
    return tuple(name for name in NAMES if state_of(getattr(contact, name), name))


@dataclass(frozen=True)
class Coefficients:
    """μ_i, κ_i and L_i at the contact points, each of shape (n,)."""

    friction: np.ndarray
    wear: np.ndarray
    stiffness: np.ndarray

    @classmethod
    def of(cls, contact, points: np.ndarray, state: dict | None = None, t: float | None = None) -> Coefficients:
        """The coefficients at the points; those of state at ``state`` (see :func:`at_points`)."""
        return cls(*(at_points(getattr(contact, name), name, points, state, t) for name in NAMES))

    def updated(self, contact, points: np.ndarray, state: dict, t: float | None = None) -> Coefficients:
        """These coefficients with those of state evaluated at ``state``; the fixed ones' arrays are kept as they are.

        ``state``: {"T": T_j, "p": p_j, "v": ‖v*(x_i, t_j)‖} at the contact points, the last step's (explicit).
        """
        changed = {name: at_points(getattr(contact, name), name, points, state, t) for name in stateful(contact)}
        return replace(self, **changed) if changed else self
