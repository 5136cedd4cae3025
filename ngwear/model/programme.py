"""Braking programmes: blocks of identical stops, compiled into what a run needs.

A programme (``[programme]``, :class:`Programme`) is a list of blocks, each ``count``
identical stops of ``duration`` followed by a ``dwell``.  Stop i of the whole programme starts at

    t_i = T_b + k (d_b + D_b),     T_b = Σ_{c < b} n_c (d_c + D_c),

for the k-th stop of block b (n_b stops of duration d_b and dwell D_b), so the stops of a block are the same
problem shifted in time (their grids agree to the last bit relative to their start) and the programme ends at
T = Σ_b n_b (d_b + D_b).  During a stop the foundation's velocity and the loads are scaled by

    s_v(t) = v₀ + (v₁ − v₀) τ/d,   s_F(t) = f₀ + (f₁ − f₀) τ/d,    τ = t − t_i ∈ [0, d],

([v₀, v₁] = ``speed``, [f₀, f₁] = ``load``; a number is [v, v]); in a dwell s_v = s_F = 0.  These factors
replace ``foundation.speed_table`` and ``loads.time_table`` (a scene gives either the tables or a programme):
their product with a table over [0, T] would scale the stops by where they fall in the programme, which a block
of identical stops cannot be.

**The time grid.**  A stop takes ``steps_per_stop`` = m uniform steps, t_i + d j/m (j = 0 … m), and begins with
a solve at t_i, as step 0 of a run does: its first wear step then starts from the loaded rate α p at t_i.  A
dwell needs no solve at all: without load and sliding the quasistatic state is the unloaded one (u = 0, p = 0, no
wear, w unchanged; a body held by a plate alone is not even located), so the time loop steps over it as one
interval whose end state is known, not m steps: one, not none, so that the record and a heat solver's cooling see
it.  The factors by time alone are right-continuous at the jumps (the stop's end into its dwell, the next stop's
start), exactly as :func:`~ngwear.model.keys.piecewise_linear` through :meth:`Schedule.table` gives them; a stop's
own grid, its end included, takes its factors from :meth:`Schedule.factors`.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property, lru_cache

import numpy as np
from pydantic import PrivateAttr, TypeAdapter, ValidationError, field_validator, model_validator

from .keys import Flag, Level, Number, SceneError, Section, Whole, key
from .messages import message
from .programme_csv import read_rows

MAX_STEPS = 1_000_000
"""Most time steps of a programme's stops, one after the other (as ``time.steps``): the bound of its grid."""
STEPS_PER_STOP = 10_000
"""Most time steps of one stop (``programme.steps_per_stop``)."""


def read_blocks(path) -> tuple[Stop, ...]:
    """The blocks of a programme's CSV file (:func:`~ngwear.model.programme_csv.read_rows`), each checked.

    Read once while the file is unchanged (its size and modification time).
    """
    try:
        info = os.stat(path)
    except OSError as err:
        raise SceneError(f"programme.file: cannot read {path} ({err})") from None
    return _read_blocks(str(path), info.st_size, info.st_mtime_ns)


@lru_cache(maxsize=4)
def _read_blocks(path: str, _size: int, _mtime: int) -> tuple[Stop, ...]:
    rows = read_rows(path)
    try:                                    # all rows at once; the first bad one named by checking them one by one
        return tuple(_BLOCKS.validate_python([row for _, row in rows]))
    except ValidationError:
        return tuple(block(row, f"programme.file: {where}") for where, row in rows)


def exact_prefix_sums(values: list[float]) -> np.ndarray:
    """T_b = Σ_{c < b} values_c, each correctly rounded (as ``math.fsum`` of the prefix), in one pass.

    The running sum is kept exactly (a :class:`~fractions.Fraction` of the floats) and rounded once per prefix.
    """
    total, out = Fraction(0), np.empty(len(values))
    for i, value in enumerate(values):
        out[i] = float(total)
        total += Fraction(value)
    return out


@dataclass(frozen=True, eq=False)
class Schedule:
    """A programme compiled: its stops one after the other, their grids and their factors s_v, s_F.

    Attributes
    ----------
    block, start, duration, dwell : ndarray, shape (S,)
        Of each stop i of the programme: its block (from 0), t_i, d and the dwell after it.
    speed, load : ndarray, shape (S, 2)
        The factors' values at the stop's start and end.
    steps : int
        m, the steps of one stop.
    first : ndarray, shape (B + 1,)
        The first stop of each block, then S: block b's stops are ``first[b]:first[b + 1]``.
    """

    block: np.ndarray
    start: np.ndarray
    duration: np.ndarray
    dwell: np.ndarray
    speed: np.ndarray
    load: np.ndarray
    steps: int
    first: np.ndarray

    @classmethod
    def of(cls, programme) -> Schedule:
        """The schedule of a ``[programme]`` table (:class:`Programme`), compiled once per programme."""
        if programme._schedule is None:
            programme._schedule = cls._compiled(programme)
        return programme._schedule

    @classmethod
    def _compiled(cls, programme) -> Schedule:
        blocks = programme.blocks
        counts = np.array([b.count for b in blocks])
        block = np.repeat(np.arange(len(blocks)), counts)
        first = np.concatenate([[0], np.cumsum(counts)])
        begins = exact_prefix_sums([b.count * b.period for b in blocks])
        within = np.arange(first[-1]) - first[block]
        field = lambda name: np.array([getattr(b, name) for b in blocks], dtype=float)[block]  # noqa: E731
        period = np.array([b.period for b in blocks])
        return cls(block, np.array(begins)[block] + within * period[block], field("duration"), field("dwell"),
                   field("speed"), field("load"), programme.steps_per_stop, first)

    @property
    def count(self) -> int:
        """S, the number of stops."""
        return len(self.block)

    @property
    def end(self) -> float:
        """T, the end of the last stop's dwell."""
        return float(self.start[-1] + self.duration[-1] + self.dwell[-1])

    def last_of_block(self, i: int) -> int:
        """The last stop of stop i's block."""
        return int(self.first[self.block[i] + 1]) - 1

    def local(self, i: int) -> np.ndarray:
        """Stop i's grid from its start, d j/m (j = 0 … m): the same bits for every stop of a block.

        Steps k taken as its differences, not as those of :meth:`times`, keep a block's stops one problem.
        """
        return self.duration[i] * np.arange(self.steps + 1) / self.steps

    def times(self, i: int) -> np.ndarray:
        """Stop i's grid t_i + d j/m, j = 0 … m (its start, a solve without a wear step, included)."""
        return self.start[i] + self.local(i)

    def factors(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """(s_v, s_F) at stop i's grid :meth:`times`, its end included (the stop's values, not the dwell's)."""
        phase = np.arange(self.steps + 1) / self.steps
        return tuple(ends[i, 0] + (ends[i, 1] - ends[i, 0]) * phase for ends in (self.speed, self.load))

    def speed_at(self, t) -> np.ndarray:
        """s_v(t) by time: the stop's ramp, 0 in a dwell (right-continuous at the jumps)."""
        table = self.table("speed")
        return np.interp(t, table[:, 0], table[:, 1])

    def load_at(self, t) -> np.ndarray:
        """s_F(t) by time: the stop's ramp, 0 in a dwell (right-continuous at the jumps)."""
        table = self.table("load")
        return np.interp(t, table[:, 0], table[:, 1])

    def table(self, which: str) -> np.ndarray:
        """[[t, s], …] of s_v (``"speed"``) or s_F (``"load"``): the piecewise-linear table of the factor.

        Non-decreasing times, repeated at the jumps (a stop's end into its dwell, the next stop's start), so that
        :func:`~ngwear.model.keys.piecewise_linear` through it is right-continuous there, as :meth:`speed_at` is: it
        stands where ``foundation.speed_table`` (``loads.time_table``) did.
        """
        return self._tables[which]

    @cached_property
    def _tables(self) -> dict[str, np.ndarray]:
        following = np.append(self.start[1:], self.end)
        stop_end = np.minimum(self.start + self.duration, following)     # no later than the next start, by an ulp
        rest = np.zeros(self.count)
        keep = np.ones((self.count, 4), bool)
        keep[:, 2:] = (self.dwell > 0)[:, None]
        tables = {}
        for which, ends in (("speed", self.speed), ("load", self.load)):
            rows = np.stack([np.column_stack(pair) for pair in ((self.start, ends[:, 0]), (stop_end, ends[:, 1]),
                                                                 (stop_end, rest), (following, rest))], axis=1)
            tables[which] = rows[keep]
        return tables

    @property
    def cools(self) -> bool:
        """Whether the programme ends with a dwell (the last stop's), which a run steps over to the end T."""
        return bool(self.dwell[-1] > 0)

    def rows(self, jumped: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(Stop, step j) of each recorded row of a run of this programme with the stops ``jumped`` not simulated.

        A simulated stop records m + 1 rows: its start (j = 0) and its m steps; a jumped stop records none.  The
        last dwell, if any, is one more row, j = m + 1 of the last stop, at T (:attr:`cools`).
        """
        simulated = np.setdiff1d(np.arange(self.count), jumped)
        stops, steps = np.repeat(simulated, self.steps + 1), np.tile(np.arange(self.steps + 1), len(simulated))
        if self.cools:
            stops, steps = np.append(stops, self.count - 1), np.append(steps, self.steps + 1)
        return stops, steps

    def ends(self, rows: int) -> np.ndarray:
        """The rows, among the first ``rows`` recorded, that end a simulated stop: m, 2m + 1, … (see :meth:`rows`)."""
        return np.arange(self.steps, rows, self.steps + 1)

    def row_factors(self, jumped: np.ndarray, rows: int) -> tuple[np.ndarray, np.ndarray]:
        """(s_v, s_F) of the first ``rows`` recorded rows (see :meth:`rows`)."""
        stop, j = (a[:rows] for a in self.rows(jumped))
        phase = j / self.steps
        return tuple(np.where(j > self.steps, 0.0, ends[stop, 0] + (ends[stop, 1] - ends[stop, 0]) * phase)
                     for ends in (self.speed, self.load))


# ---------------------------------------------------------------- the scene's [programme] table


Ramp = Number | tuple[Number, Number]


class Stop(Section):
    """One block of a programme: ``count`` identical stops, each ``duration`` long and followed by its ``dwell``."""

    count: Whole = key(1, "the number of identical stops of the block", reuse=Level.NOTHING, ge=1, le=MAX_STEPS)
    duration: Number = key(..., "the time of one stop (sliding, loaded)", reuse=Level.NOTHING, shown="— (required)",
                           gt=0)
    speed: Ramp = key((1.0, 1.0), "the factor of the foundation's velocity: a number, or [start, end] linear over "
                      "the stop (a stop to rest: [1, 0])", reuse=Level.NOTHING, shown="1",
                      allowed="a number or [start, end]")
    load: Ramp = key((1.0, 1.0), "the factor of the loads (plate force, tractions, body force): a number or "
                     "[start, end]", reuse=Level.NOTHING, shown="1", allowed="numbers >= 0 when only a plate holds "
                     "the body")
    dwell: Number = key(0.0, "the time after each stop with no load and no wear", reuse=Level.NOTHING, ge=0)

    @field_validator("speed", "load")
    @classmethod
    def _ramp(cls, value: Ramp) -> tuple[float, float]:
        """A number v is the constant factor [v, v]."""
        return (value, value) if isinstance(value, float) else value

    @property
    def period(self) -> float:
        """The time of one stop and its dwell."""
        return self.duration + self.dwell


_BLOCKS = TypeAdapter(list[Stop])


def block(entry, where: str) -> Stop:
    """One block from a table (or a file's row), or one SceneError line starting with ``where``."""
    if not isinstance(entry, (dict, Stop)):
        raise SceneError(f"{where}: must be a table {{count, duration, speed, load, dwell}} (got {entry!r})")
    try:
        return Stop.model_validate(entry)
    except ValidationError as err:
        first = sorted(err.errors(), key=lambda e: e["type"] != "extra_forbidden")[0]
        name = first["loc"][0] if first["loc"] else "block"
        if first["type"] == "extra_forbidden":
            text = f"{name}: unknown (allowed: {', '.join(Stop.model_fields)})"
        elif name in ("speed", "load"):
            text = f"{name}: must be a number or [start, end] (got {entry.get(name)!r})"
        else:
            text = message(first, entry, Stop)
        raise SceneError(f"{where}: {text}") from None


class Programme(Section):
    """A braking programme: blocks of identical stops, run one after the other (see :mod:`ngwear.model.programme`)."""

    stops: tuple[Stop, ...] = key((), "the blocks, one after the other, each `{ count, duration, speed, load, "
                                  "dwell }` (the keys `programme.stops[].…`)", reuse=Level.NOTHING, shown="—",
                                  allowed="one block or more")
    file: str | None = key(None, "a CSV file of the blocks (instead of `stops`; relative to the scene file): a header "
                           "naming the columns `count`, `duration` and any of `speed`, `load`, `dwell`, then one row "
                           "a block (a [start, end] factor quoted: `\"[1.0, 0.0]\"`); comma-separated UTF-8, a "
                           "byte-order mark and `duration [s]`, `dwell [s]` headers accepted", reuse=Level.NOTHING,
                           shown="—", allowed="a regular CSV file of at most 10 MB")
    steps_per_stop: Whole = key(20, "uniform time steps of one stop (`time.adaptive` is refused with a programme)",
                                reuse=Level.NOTHING, ge=1, le=STEPS_PER_STOP)
    jump: Flag = key(False, "apply stops of a block at once (cycle jumps) once their wear increments settle",
                     reuse=Level.NOTHING)
    jump_tolerance: Number = key(1e-3, "`jump`: the change of the wear increment between consecutive simulated "
                                 "stops, relative to the increment (max over Γ_C), below which stops are jumped",
                                 reuse=Level.NOTHING, gt=0, lt=1)

    @field_validator("stops", mode="before")
    @classmethod
    def _blocks(cls, value):
        """Each block checked on its own: one line naming the block and its key."""
        if not isinstance(value, (list, tuple)):
            raise SceneError(f"programme.stops: must be a list of blocks {{count, duration, speed, load, dwell}} "
                             f"(got {value!r})")
        return tuple(block(entry, f"programme.stops: block {i}") for i, entry in enumerate(value, start=1))

    _read: tuple[Stop, ...] = PrivateAttr(default=())    # the rows of ``file``, read once with the scene
    _schedule: Schedule | None = PrivateAttr(default=None)     # compiled once (Schedule.of)

    def __eq__(self, other) -> bool:
        """The same keys and blocks (the compiled schedule is a cache of them)."""
        return isinstance(other, Programme) and self.__dict__ == other.__dict__ and self._read == other._read

    __hash__ = Section.__hash__

    @model_validator(mode="after")
    def _one_source(self) -> Programme:
        if (not self.stops) == (self.file is None):
            raise SceneError("programme.stops: give the blocks either as programme.stops or in programme.file "
                             f"(got {'both' if self.stops else 'neither'})")
        if self.file is not None:           # a file is read (and its rows checked) with the scene
            self._read = read_blocks(self.file)
        return self

    @property
    def blocks(self) -> tuple[Stop, ...]:
        """The blocks: ``stops``, or the rows of ``file``."""
        return self.stops if self.file is None else self._read

    @property
    def end(self) -> float:
        """T: the time of every stop and dwell."""
        return math.fsum(b.count * b.period for b in self.blocks)

    @property
    def count(self) -> int:
        """S, the number of stops."""
        return sum(b.count for b in self.blocks)

    @property
    def steps(self) -> int:
        """The time steps of the programme's stops, one after the other (its dwells take none)."""
        return self.count * self.steps_per_stop
