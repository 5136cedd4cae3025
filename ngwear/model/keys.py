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

from dataclasses import dataclass, field
from enum import IntEnum
from typing import Annotated, Any

import numpy as np
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


def piecewise_linear(table: Table, t: float) -> float:
    """Value at t of the piecewise-linear function through a time table ``[(t, f), ...]`` (1 for an empty table)."""
    if not table:
        return 1.0
    ts, fs = zip(*table)
    return float(np.interp(t, ts, fs))


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


@dataclass(frozen=True, eq=False)
class Constant:
    """A constant of a law, declared with the law (:mod:`ngwear.model.materials`, :mod:`ngwear.model.compliance`).

    It is a scene key of the law's table (``material.young``, ``contact.exponent``): ``name``, ``type``, ``doc``,
    ``default`` (None: optional), the :class:`Level` a change invalidates and its limits (pydantic's ``ge``, ``gt``,
    ``le``; ``shown`` and ``allowed`` as for :func:`key`); ``function``: in Python a function, kept by its token
    (:mod:`ngwear.model.function_tokens`); and how a summary shows it: ``symbol`` (None: not a number it lists) and
    ``modulus`` (a stiffness: Pa in an SI scene).
    """

    name: str
    type: Any
    doc: str
    default: Any = None
    reuse: Level = Level.STIFFNESS
    symbol: str | None = None
    modulus: bool = False
    shown: str | None = None
    allowed: str | None = None
    function: bool = False
    limits: dict = field(default_factory=dict)

    def declaration(self) -> tuple[Any, Any]:
        """(annotation, :func:`key`) of the constant's field in its table."""
        annotation = self.type if self.default is not None else self.type | None
        return annotation, key(self.default, self.doc, reuse=self.reuse, shown=self.shown, allowed=self.allowed,
                               **self.limits)


def level_of(info) -> Level:
    """The declared :class:`Level` of a field (its ``invalidates``)."""
    extra = info.json_schema_extra or {}
    if "invalidates" not in extra:
        raise KeyError("a scene key without a declared level (declare it with ngwear.model.keys.key)")
    return Level[extra["invalidates"].upper()]


class Section(BaseModel):
    """A table of a scene file (``[contact]``, ...): frozen, unknown keys refused."""

    model_config = ConfigDict(frozen=True, extra="forbid")
