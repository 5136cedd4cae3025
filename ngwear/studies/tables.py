"""A study file's tables read as dotted scene keys and values, and the one-line error that names a field."""
from __future__ import annotations

import json
import re
from typing import Any

BARE = re.compile(r"[A-Za-z0-9_-]+")                 # a TOML bare key; other keys are written quoted


class StudyError(ValueError):
    """A study field is missing, malformed or gives no valid case (the message names the field)."""


def first_repeat(items: list) -> tuple[int, int] | None:
    """The first (i, j), i < j, of two items equal as written (``1`` and ``1.0`` differ), or None."""
    seen: dict[str, int] = {}
    for j, item in enumerate(items):
        i = seen.setdefault(as_text(item), j)
        if i != j:
            return i, j
    return None


def as_text(value: Any) -> str:
    return json.dumps(value, sort_keys=True, default=str)


def shown(params: dict, keys=None) -> str:
    return ", ".join(f"{k} = {as_text(params[k])}" for k in (keys or params) if k in params) or "as the base scene"


def whole_number(value: Any, name: str, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise StudyError(f"{name}: must be a whole number >= {low} (got {value!r})")
    return value


def table_of(data: dict, key: str, prefix: str = "") -> dict:
    value = data.get(key, {})
    if not isinstance(value, dict):
        name = f"{prefix}.{key}" if prefix else key
        raise StudyError(f"{name}: must be a table of dotted scene keys (got {value!r})")
    return value


def flat(table: dict, where: str) -> dict[str, Any]:
    """``{"contact": {"friction": x}}`` and ``{"contact.friction": x}`` → ``{"contact.friction": x}``.

    Two spellings of one key in ``table`` (``"contact.friction"`` beside ``contact = {friction = ...}``)
    are refused naming both.
    """
    out, spelled = {}, {}
    for path, value in leaves(table, ()):
        key, spelling = ".".join(path), ".".join(p if BARE.fullmatch(p) else json.dumps(p) for p in path)
        if key in out:
            raise StudyError(f"{where}.{key}: given twice, as {where}.{spelled[key]} and {where}.{spelling} "
                             "(give it once)")
        out[key], spelled[key] = value, spelling
    return out


def leaves(table: dict, path: tuple[str, ...]):
    for key, value in table.items():
        if isinstance(value, dict):
            yield from leaves(value, (*path, key))
        else:
            yield (*path, key), value
