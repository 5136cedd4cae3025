"""How a scene key is declared: type, range, one line of documentation and what a change of it invalidates.

Every key of a scene is declared once, with :func:`key`, next to its field in :mod:`ngwear.model.sections`.
Besides the type and range that pydantic validates, the declaration names the :class:`Level` of the cached
work that a change of the key invalidates: the mesh, the finite element space and contact points, the
stiffness and its factorisation, the contact direction's pieces, the loads, or nothing.  The levels are
ordered as the pieces are built, each from the ones before it, so a change invalidates its level and every
later one.  The mesh cache key, :meth:`~ngwear.numerics.discrete.Discretization.with_scene`, the study's
grouping of cases and the explorer all read this one declaration (:func:`ngwear.model.scene.signature`).
"""
from __future__ import annotations

from enum import IntEnum
from typing import Annotated, Any

from pydantic import AllowInfNan, BaseModel, BeforeValidator, ConfigDict, Field, Strict


class SceneError(ValueError):
    """A scene field is missing, of the wrong type or out of range (the message names the field)."""


class Level(IntEnum):
    """What a change of a scene key invalidates, in the order the cached pieces are built."""

    MESH = 0          # the mesh (Netgen), and everything built on it
    SPACE = 1         # the finite element space, its clamping and the contact points
    STIFFNESS = 2     # the stiffness matrix and its factorisation
    DIRECTION = 3     # the contact direction's pieces: ν·G (the contact compliance), the plate's modes
    LOADS = 4         # the load vectors and their responses K⁻¹f
    NOTHING = 5       # read at solve time (friction, wear, gap, motion, time, ...)

    @property
    def label(self) -> str:
        return LABELS[self]


LABELS = {Level.MESH: "mesh", Level.SPACE: "space", Level.STIFFNESS: "factorisation",
          Level.DIRECTION: "contact compliance", Level.LOADS: "loads", Level.NOTHING: "nothing"}


def _integral(value: Any) -> Any:
    """A whole float (``10.0``) is taken as the integer it is; anything else is left to the int check."""
    return int(value) if isinstance(value, float) and value.is_integer() else value


Number = Annotated[float, Strict(), AllowInfNan(False)]
Whole = Annotated[int, BeforeValidator(_integral), Strict()]
Flag = Annotated[bool, Strict()]
Vector = tuple[Number, ...]
MAX_ROWS = 10_000
"""Most rows of a table (``loads.time_table``, ``foundation.speed_table``): each is looked up at every step."""
Rows = tuple[tuple[Number, Number], ...]
Table = Annotated[Rows, Field(max_length=MAX_ROWS)]


def range_text(lo=None, hi=None, lo_open=False, hi_open=False) -> str:
    """``> 0``, ``>= 1``, ``<= 2`` or ``in (0, 3.0]``."""
    if lo is not None and hi is not None:
        return f"in {'(' if lo_open else '['}{lo}, {hi}{')' if hi_open else ']'}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {lo}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {hi}"
    return ""


def key(default: Any, doc: str, *, reuse: Level, shown: str | None = None, allowed: str | None = None,
        **limits) -> Any:
    """A declared scene key: default, one line of documentation, what a change invalidates, limits.

    ``shown`` and ``allowed`` replace the default and the range in the reference table.
    """
    extra = {k: v for k, v in (("shown", shown), ("allowed", allowed)) if v is not None}
    return Field(default, description=doc, json_schema_extra={**extra, "invalidates": reuse.name.lower()}, **limits)


def level_of(info) -> Level:
    """The declared :class:`Level` of a field (its ``invalidates``)."""
    extra = info.json_schema_extra or {}
    if "invalidates" not in extra:
        raise KeyError("a scene key without a declared level (declare it with ngwear.model.keys.key)")
    return Level[extra["invalidates"].upper()]


class Section(BaseModel):
    """A table of a scene file (``[contact]``, ...): frozen, unknown keys refused."""

    model_config = ConfigDict(frozen=True, extra="forbid")
