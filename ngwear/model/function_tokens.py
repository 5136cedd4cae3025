"""Python functions in scenes (Python only): kept in this process under a name, so that a scene stays plain data.

A callable given for a scene key that takes one (``material.energy``, ``contact.friction``, ``contact.wear``,
``contact.stiffness``) is replaced by its *token* ``"python:<module>.<name>#<n>"`` before validation; the scene
holds the token (TOML, JSON, ``scene.json`` of a result) and :func:`resolve` gives the callable back in the
process that registered it.  In another process the token names a function that is gone, and using it is one
line naming the key: results keep the values the function gave (the per-point coefficients), not the function.
"""
from __future__ import annotations

import re
from collections.abc import Callable

from .keys import SceneError

_FUNCTIONS: dict[str, Callable] = {}
_TOKENS: dict[int, str] = {}
TOKEN = re.compile(r"^python:[\w.<>]+#\d+$")


def token(function: Callable) -> str:
    """The token of ``function`` (the same function keeps its token; the registry keeps it alive)."""
    if id(function) not in _TOKENS:
        name = f"{getattr(function, '__module__', None) or 'python'}.{getattr(function, '__qualname__', 'function')}"
        _TOKENS[id(function)] = text = f"python:{name}#{len(_FUNCTIONS)}"
        _FUNCTIONS[text] = function
    return _TOKENS[id(function)]


def is_token(value) -> bool:
    return isinstance(value, str) and bool(TOKEN.match(value))


def resolve(text: str, key: str) -> Callable:
    """The function behind a token, or a SceneError naming ``key`` when it is not of this process."""
    if text not in _FUNCTIONS:
        raise SceneError(f"{key}: {text} is a Python function of another session; give a number or an expression "
                         "(a result keeps the values it gave)")
    return _FUNCTIONS[text]


FUNCTION_KEYS = (("contact", "friction"), ("contact", "wear"), ("contact", "stiffness"))
"""The contact keys (table, key) that take a Python function; so do the material constants declared ``function``
(``material.energy``, ``material.regions.<region>.energy``)."""


def tokenised(data: dict) -> None:
    """Replace the functions given for :data:`FUNCTION_KEYS` in raw scene tables by their tokens (in place)."""
    from .materials import constants

    tables = [(data.get(table), name) for table, name in FUNCTION_KEYS]
    material = data.get("material") if isinstance(data.get("material"), dict) else {}
    regions = material.get("regions") if isinstance(material.get("regions"), dict) else {}
    tables += [(table, c.name) for table in (material, *regions.values()) for c in constants() if c.function]
    for table, name in tables:
        if isinstance(table, dict) and callable(table.get(name)):
            table[name] = token(table[name])
