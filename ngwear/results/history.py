"""The per-step arrays of a run, in rows with room to grow: in memory, or in mapped files of its output folder.

A run records (4 + d) n_c numbers a step at its n_c contact points: 18 260 points in 3D make 1 MB a step and
10 GB in 10 000 steps, which would sit in the process's memory beside K's factor and be written whole by
every checkpoint.  With an output folder the rows live in files ``steps-<id>/<name>.f64`` (float64, C
order, no header) mapped into memory: the kernel writes them out and drops them from memory as they fill,
and a checkpoint flushes the mapping and records how many rows count, so that it writes only what is new.
Rows past that count belong to steps after the checkpoint and are written again when the run resumes.
"""
from __future__ import annotations

import shutil
import uuid
from pathlib import Path

import numpy as np

PREFIX = "steps-"


class History:
    """Named arrays of shape (capacity, *shape) whose first rows are a run's completed steps."""

    def __init__(self, buffers: dict[str, np.ndarray], folder: Path | None = None):
        self.buffers, self.folder = buffers, folder

    @classmethod
    def empty(cls, shapes: dict[str, tuple], capacity: int, folder=None) -> History:
        """Zeros in memory, or (``folder`` given) in new files of a new ``steps-<id>`` folder in it."""
        if folder is None:
            return cls({name: np.zeros((capacity, *shape)) for name, shape in shapes.items()})
        home = Path(folder) / f"{PREFIX}{uuid.uuid4().hex[:12]}"
        home.mkdir(parents=True)
        history = cls({}, home)
        for name, shape in shapes.items():
            history.buffers[name] = history._mapped(name, shape, capacity, "w+")
        return history

    @classmethod
    def reopen(cls, home, shapes: dict[str, tuple]) -> History:
        """The files of ``home`` (a ``steps-<id>`` folder) mapped again, to be appended to."""
        home = Path(home)
        history = cls({}, home)
        capacity = (home / "times.f64").stat().st_size // 8          # the rows all grow together
        for name, shape in shapes.items():
            history.buffers[name] = history._mapped(name, shape, capacity, "r+")
        return history

    def _mapped(self, name: str, shape: tuple, capacity: int, mode: str) -> np.ndarray:
        if not np.prod(shape, dtype=int):          # no columns (δ of a run without a plate): nothing to keep
            return np.zeros((capacity, *shape))
        return np.memmap(self.folder / f"{name}.f64", dtype=np.float64, mode=mode, shape=(capacity, *shape))

    def put(self, name: str, row: int, value) -> np.ndarray:
        """Write ``value`` into ``row`` (doubling the capacity when full); the rows up to it."""
        buffer = self.buffers[name]
        if len(buffer) <= row:
            buffer = self._grown(name, 2 * (row + 1))
        buffer[row] = value
        return buffer[:row + 1]

    def _grown(self, name: str, capacity: int) -> np.ndarray:
        old = self.buffers[name]
        if not isinstance(old, np.memmap):
            new = np.zeros((capacity, *old.shape[1:]))
            new[:len(old)] = old
        else:
            old.flush()
            with open(self.folder / f"{name}.f64", "r+b") as file:
                file.truncate(capacity * old[0].nbytes)
            new = self._mapped(name, old.shape[1:], capacity, "r+")
        self.buffers[name] = new
        return new

    def flush(self) -> None:
        """Write the mapped rows to their files."""
        for buffer in self.buffers.values():
            if isinstance(buffer, np.memmap):
                buffer.flush()

    def is_in(self, folder) -> bool:
        """Whether the rows live in files of ``folder`` (not in memory, not in another folder)."""
        return self.folder is not None and self.folder.parent.resolve() == Path(folder).resolve()

    def moved(self, folder, rows: int) -> History:
        """A copy of the first ``rows`` rows in a new history folder in ``folder``."""
        shapes = {name: buffer.shape[1:] for name, buffer in self.buffers.items()}
        copy = History.empty(shapes, max(rows, 1), folder)
        for name, buffer in self.buffers.items():
            copy.buffers[name][:rows] = buffer[:rows]
        return copy


def remove_others(folder, keep: Path) -> None:
    """Delete the history folders in ``folder`` other than ``keep`` (those of runs a checkpoint no longer names)."""
    for home in Path(folder).glob(f"{PREFIX}*"):
        if home.is_dir() and home.resolve() != Path(keep).resolve():
            shutil.rmtree(home, ignore_errors=True)
