"""What the declarations say to people: one-line errors and the JSON Schema (the reference table: :mod:`.reference`).

:func:`message` turns the first pydantic error into one line naming the dotted key, what it must be (from its
declaration) and what it got; :func:`json_schema` is the schema editors use to complete and check scene files; the
helpers that read a declaration (:func:`plain`, :func:`allowed`, :func:`base_type`) serve the reference too.
"""
from __future__ import annotations

from typing import Annotated, Any, Literal, get_args, get_origin

from pydantic import BaseModel
from pydantic.fields import FieldInfo

from .keys import Rows, SceneError, Vector, range_text
from .kinds import KINDS

NAME_RULE = "a plain name of at most 100 letters, digits, '.', '_', '-' or spaces, not a path"


def message(err: dict, data: Any, scene_model: type[BaseModel]) -> str:
    """One line for the first pydantic error: the dotted key, what it must be, what it got."""
    cause = (err.get("ctx") or {}).get("error")
    if isinstance(cause, SceneError):
        return str(cause)
    name, info, owner = _field(err["loc"], scene_model)
    kind = err["type"]
    if kind == "extra_forbidden":
        table = _field(err["loc"][:-1], scene_model)[2] or scene_model
        what = "section" if table is scene_model else "key"
        return f"{name}: unknown {what} (allowed: {', '.join(table.model_fields)})"
    if kind == "missing":
        return f"{name}: missing ({info.description if info else 'a table'})"
    got = raw(data, name)
    if info is None or owner is not None:
        return f"{name}: must be a table (got {got!r})"
    what, rng = _what(info, name, data)
    if kind == "too_long" and not isinstance(err["loc"][-1], int):      # a table's rows (not a row's numbers)
        return f"{name}: at most {err['ctx']['max_length']} rows (got {err['ctx']['actual_length']})"
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        return f"{name}: must be {rng} (got {got!r})"
    if kind == "finite_number":
        return f"{name}: must be {'finite' if what.startswith('a list') else f'a finite {what[2:]} {rng}'.strip()}" \
               f" (got {got!r})"
    return f"{name}: must be {f'{what} {rng}'.strip()} (got {got!r})"


def raw(data: Any, dotted: str) -> Any:
    """The value at a dotted key of a nested dict (None where there is none)."""
    node = data
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def json_schema(scene_model: type[BaseModel]) -> dict[str, Any]:
    """The scene schema as JSON Schema (for editors that complete and check scene files).

    A key whose default depends on other keys (declared with ``shown`` and no default of its own) has no ``default``
    in the schema, which would say none: its ``shown`` says what it is.
    """
    schema = scene_model.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "ngwear scene"
    for table in schema.get("$defs", {}).values():
        for entry in table.get("properties", {}).values():
            if "shown" in entry and entry.get("default", 0) is None:
                del entry["default"]
    return schema


# ---------------------------------------------------------------- reading declarations


def plain(value: Any) -> str:
    if value is None or value == () or value == {}:
        return "—"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, str):
        return value
    return f"{value:g}" if isinstance(value, float) else str(value)


def limits(info: FieldInfo) -> tuple:
    """(lo, hi, lo_open, hi_open) of a declared field."""
    lo = hi = None
    lo_open = hi_open = False
    for m in info.metadata:
        for attr, is_lo, is_open in (("gt", True, True), ("ge", True, False), ("lt", False, True),
                                     ("le", False, False)):
            value = getattr(m, attr, None)
            if value is not None:
                if is_lo:
                    lo, lo_open = value, is_open
                else:
                    hi, hi_open = value, is_open
    return lo, hi, lo_open, hi_open


def allowed(info: FieldInfo) -> str:
    """The allowed values of a declared field, as the reference table states them."""
    base = base_type(info.annotation)
    if get_origin(base) is Literal:
        return ", ".join(get_args(base))
    if base is bool:
        return "bool"
    return range_text(*limits(info)) or "—"


def base_type(annotation):
    """The annotation without ``| None`` and without ``Annotated`` metadata."""
    args = [a for a in get_args(annotation) if a is not type(None)]
    if args and get_origin(annotation) is not Literal and get_origin(annotation) not in (tuple, dict):
        annotation = args[0] if len(args) == 1 else annotation
    while get_origin(annotation) is Annotated:
        annotation = get_args(annotation)[0]
    return annotation


def _field(loc: tuple, scene_model) -> tuple[str, FieldInfo | None, type[BaseModel] | None]:
    """Dotted name, declaration and owning table of an error location (list indices dropped).

    The location is followed through nested tables (``loads.plate.force``) and into the entries of
    a table of vectors (``loads.traction.top``); a location that ends on a table has no declaration.
    """
    names = [p for p in loc if isinstance(p, str)]
    model, info, used = scene_model, None, []
    for part in names:
        used.append(part)
        if isinstance(model, _DictOf):         # the name of an entry of a table of tables (a region)
            model, info = model.value, None
            continue
        if model is None:                      # an entry of a dict-valued key: declared by the key
            break
        info = model.model_fields.get(part)
        if info is None:
            break
        base = base_type(info.annotation)
        if isinstance(base, type) and issubclass(base, BaseModel):
            model, info = base, None
        elif get_origin(base) is dict:
            value = get_args(base)[1]
            model = _DictOf(value) if isinstance(value, type) and issubclass(value, BaseModel) else None
        else:
            break
    owner = model if info is None else None
    return ".".join(used) or "scene", info, owner


class _DictOf:
    """The entries of a table of tables (``material.regions``): each a table of the model ``value``."""

    def __init__(self, value: type[BaseModel]):
        self.value = value


def _what(info: FieldInfo, name: str, data: Any) -> tuple[str, str]:
    """(What the value must be, its range), e.g. ("a number", "> 0") or ("a list of 2 numbers", "")."""
    base = base_type(info.annotation)
    rng = _maxh_range(data) if name == "mesh.maxh" else range_text(*limits(info))
    if name.startswith("loads.traction."):
        base = Vector
    if get_origin(base) is Literal:
        return "one of " + ", ".join(get_args(base)), ""
    if base is bool:
        return "true or false", ""
    if name == "name":
        return NAME_RULE, ""
    if base is str:
        return "a non-empty string", ""
    if name == "loads.traction":
        return "a table of boundary = [vector]", ""
    if base == Rows:                                   # a Table: its max_length is the field's metadata
        return "a list of [t, factor] pairs", ""
    if get_origin(base) is tuple:
        if get_args(base)[0] is str:
            return "a list of boundary names", ""
        kind = KINDS.get(raw(data, "geometry.kind") or "strip")
        sizes = {"geometry.size": len(kind.size) if kind and kind.size else None, "geometry.position": 2}
        count = sizes.get(name, _dim_of(data))
        return (f"a list of {count} numbers" if count else "a list of numbers"), ""
    return ("a whole number" if base is int else "a number"), rng


def _dim_of(data: Any) -> int | None:
    kind = KINDS.get(raw(data, "geometry.kind") or "strip")
    return kind.dim if kind and kind.dim else None


def _maxh_range(data: Any) -> str:
    kind, size = KINDS.get(raw(data, "geometry.kind") or "strip"), raw(data, "geometry.size")
    if kind and kind.size and isinstance(size, list) and size and all(isinstance(v, (int, float)) for v in size):
        return range_text(0, kind.extent(size), lo_open=True)
    return "> 0"

