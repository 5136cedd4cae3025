"""A programme's CSV file: its rows read with a bound, as spreadsheets write them, each a raw block.

The header names the columns (:data:`COLUMNS`), a row is a block; a cell is a number or ``[start, end]``.  The
file is read only if it is a regular file, opened without blocking and read up to :data:`MAX_BYTES`; what is
wrong with it is one line naming ``programme.file``, the line and the column.  The blocks are checked by
:mod:`ngwear.model.programme`.
"""
from __future__ import annotations

import csv
import os
import re
import stat
import tomllib
from pathlib import Path

from .keys import SceneError

COLUMNS = ("count", "duration", "speed", "load", "dwell")
REQUIRED = ("count", "duration")
MAX_BYTES = 10_000_000
"""The largest programme file read (a million blocks of short rows)."""
_DECIMAL = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_NUMBER, _INTEGER = re.compile(_DECIMAL), re.compile(r"[+-]?\d+")
_PAIR = re.compile(rf"\[\s*({_DECIMAL})\s*,\s*({_DECIMAL})\s*\]")
"""A decimal number, and [start, end] of two (``inf``, ``nan``, ``1_000`` and the rest go to TOML, which refuses or
reads them)."""


def read_rows(path) -> list[tuple[str, dict]]:
    """(Where, raw block) of each row of a programme's CSV file; SceneError lines name ``programme.file``.

    The header names the columns (:data:`COLUMNS`; ``count`` and ``duration`` required), with a unit as ngwear's own
    CSV files write it if it is the column's (``duration [s]``, :data:`UNITS`); columns without a name and without
    values (a spreadsheet's trailing separators) are left out.  A cell is read as a TOML value (a number, or
    ``[start, end]`` quoted); an empty cell takes the key's default.
    """
    path = Path(path)
    lines = csv.reader(_text(path).splitlines(), strict=True, skipinitialspace=True)
    try:
        columns = [_column(name, path) for name in next(lines, [])]
        header = [name for name in columns if name]
        missing = [name for name in REQUIRED if name not in header]
        unknown = [name for name in header if name not in COLUMNS]
        if missing or unknown or len(set(header)) < len(header):
            problem = f"has no column {missing[0]!r}" if missing else f"has an unknown or repeated column " \
                f"{(unknown or [n for n in header if header.count(n) > 1])[0]!r}"
            separated = next((f"; separated by {name}? the columns are separated by commas" for sep, name in
                              ((";", "semicolons"), ("\t", "tabs")) if any(sep in n for n in header)), "")
            raise SceneError(f"programme.file: {path.name} {problem} (its header: {', '.join(header) or 'none'}; "
                             f"the columns: {', '.join(COLUMNS)}, of them {' and '.join(REQUIRED)} required"
                             f"{separated})")
        rows = []
        for number, cells in enumerate(lines, start=2):
            if not any(cell.strip() for cell in cells):
                continue
            where = f"{path.name} line {number}"
            if len(cells) != len(columns):
                raise SceneError(f"programme.file: {where}: has {len(cells)} cells, the header {len(columns)}")
            if any(cell.strip() for name, cell in zip(columns, cells) if not name):
                raise SceneError(f"programme.file: {where}: has a value in a column without a name")
            cells = [cell for name, cell in zip(columns, cells) if name]
            rows.append((where, {name: _cell(cell, f"{where}: {name}") for name, cell in zip(header, cells)
                                 if cell.strip()}))
    except csv.Error as err:
        raise SceneError(f"programme.file: {path.name} line {lines.line_num}: {err}") from None
    if not rows:
        raise SceneError(f"programme.file: {path.name} has no blocks (one row a block below the header)")
    return rows


UNITS = {"duration": "s", "dwell": "s"}
"""The unit a column's header may carry (``duration [s]``); the factors (count, speed, load) carry none."""
_HEADED = re.compile(r"(\w+)\s*\[\s*([^\]]*?)\s*\]")


def _column(text: str, path: Path) -> str:
    """A header cell's column name: ``name`` or ``name [unit]`` with the column's own unit."""
    text = text.strip()
    headed = _HEADED.fullmatch(text)
    if headed is None:
        return text
    name, unit = headed.groups()
    if UNITS.get(name) != unit:
        wanted = f"[{UNITS[name]}]" if name in UNITS else "no unit (a factor)"
        raise SceneError(f"programme.file: {path.name} column {text!r}: its unit must be {wanted}")
    return name


def _text(path: Path) -> str:
    """The text of a regular file of at most :data:`MAX_BYTES` (UTF-8, a spreadsheet's byte-order mark dropped).

    Opened without blocking and checked on the open file (a FIFO, a device or a link swapped in is refused), then read
    with the bound: ``/dev/zero`` is never read at all.
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
        with os.fdopen(fd, "rb") as file:
            if not stat.S_ISREG(os.fstat(file.fileno()).st_mode):
                raise SceneError(f"programme.file: {path} is not a regular file (a CSV file of the blocks)")
            data = file.read(MAX_BYTES + 1)
        if len(data) > MAX_BYTES:
            raise SceneError(f"programme.file: {path.name} is larger than {MAX_BYTES // 1_000_000} MB")
        return data.decode("utf-8-sig")
    except (OSError, UnicodeDecodeError) as err:
        raise SceneError(f"programme.file: cannot read {path} ({err})") from None


def _cell(text: str, where: str):
    """A cell's value: a number or ``[start, end]`` of numbers (read as such, the common cases), else a TOML value."""
    text = text.strip()
    try:
        if _NUMBER.fullmatch(text):
            return int(text) if _INTEGER.fullmatch(text) else float(text)
        pair = _PAIR.fullmatch(text)
        return [float(pair[1]), float(pair[2])] if pair else tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        raise SceneError(f"programme.file: {where}: must be a number or [start, end] (got {text!r})") from None
