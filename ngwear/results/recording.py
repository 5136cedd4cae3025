"""A run recording itself: each step's row into its :class:`~ngwear.results.result.Result`, and where the rows live.

:meth:`Recording.start` makes a run's empty result with room for its rows, in memory or (an output folder) in mapped
files there (:class:`History`); :meth:`Recording.append` records the row of a step's state; the
recording keeps the bookkeeping of a run that stops: a failed step (:meth:`~Recording.fail`), an interrupt (even one
inside :meth:`~Recording.append`: :meth:`~Recording.settle`), rows moved to another folder
(:meth:`~Recording.keep_in`), and a geometry update that moves the last row's wear into the body
(:meth:`~Recording.moved`).

The rows' storage, :class:`History`: the per-step arrays of a run in rows with room to grow, in memory or in mapped
files of its output folder.  A run records (4 + d) n_c numbers a step at its n_c contact points: 18 260 points in 3D
make 1 MB a step and 10 GB in 10 000 steps, which would sit in the process's memory beside K's factor and be written
whole by every checkpoint.  With an output folder the rows live in files ``steps-<id>/<name>.f64`` (float64, C order,
no header) mapped into memory: the kernel writes them out and drops them from memory as they fill, and a checkpoint
flushes the mapping and records how many rows count, so that it writes only what is new.  Rows past that count belong
to steps after the checkpoint and are written again when the run resumes.

The room for the rows is reserved on disk (``posix_fallocate``) before it is mapped: a full disk is an ``OSError``
(ENOSPC) when the run starts or its rows grow, never a SIGBUS when a page of the mapping is first written.  A
checkpoint also records the CRC-32 of each file's counted rows, carried on from the last checkpoint over the rows
added since, and a resume maps the files only once their sizes and checksums say that they hold those rows.
"""
from __future__ import annotations

import os
import shutil
import uuid
import zlib
from pathlib import Path

import numpy as np

from ..numerics.systems.newton import NewtonRecord
from ..numerics.topology import coordinates
from .folder import FolderError, NoSpace, no_space
from .provenance import provenance
from .result import Result, output_times, row_shapes

PREFIX = "steps-"


class History:
    """Named arrays of shape (capacity, *shape) whose first rows are a run's completed steps."""

    def __init__(self, buffers: dict[str, np.ndarray], folder: Path | None = None):
        self.buffers, self.folder = buffers, folder
        self._sums: dict[str, int] = {}             # CRC-32 of the first ``_summed`` rows of each array
        self._summed = 0

    @classmethod
    def empty(cls, shapes: dict[str, tuple], capacity: int, folder=None) -> History:
        """Zeros in memory, or (``folder`` given) in new files of a new ``steps-<id>`` folder in it."""
        if folder is None:
            return cls({name: np.zeros((capacity, *shape)) for name, shape in shapes.items()})
        home = Path(folder) / f"{PREFIX}{uuid.uuid4().hex[:12]}"
        home.mkdir(parents=True)
        history = cls({}, home)
        try:
            for name, shape in shapes.items():
                history.buffers[name] = history._mapped(name, shape, capacity)
        except OSError:                             # no room for the rows: nothing of them left behind
            shutil.rmtree(home, ignore_errors=True)
            raise
        return history

    @classmethod
    def reopen(cls, home, shapes: dict[str, tuple], rows: int, sums: dict[str, int] | None = None) -> History:
        """The files of ``home`` (a ``steps-<id>`` folder) mapped again, to be appended to.

        Only once they hold the ``rows`` rows a checkpoint counts: every file is there, of whole rows, at
        least ``rows`` of them, and (``sums`` given) with the checkpoint's CRC-32; else a FolderError naming
        the file.
        """
        home = Path(home)
        if home.is_symlink():
            raise FolderError("resume", f"{home} is a link, not a folder of the run's own (refused: it would be written)")
        if not home.is_dir():
            raise FolderError("resume", f"{home} is missing (it holds the steps its checkpoint counts)")
        history = cls({}, home)
        for name, shape in shapes.items():
            row, path = 8 * int(np.prod(shape, dtype=int)), home / f"{name}.f64"
            if not row:
                history.buffers[name] = np.zeros((rows, *shape))
                continue
            if path.is_symlink():
                raise FolderError("resume", f"{path} is a link, not a file of the run's own (refused: it would be "
                                            "written)")
            if not path.is_file():
                raise FolderError("resume", f"{path} is missing (its checkpoint counts {rows} rows)")
            size = path.stat().st_size
            if size % row or size // row < rows:
                raise FolderError("resume", f"{path} holds {size / row:.6g} rows of {row} bytes, its checkpoint "
                                            f"counts {rows}: the file was cut short or changed")
            history.buffers[name] = (np.memmap(path, dtype=np.float64, mode="r+", shape=(size // row, *shape))
                                     if size else history._mapped(name, shape, 1))
        for name, found in history.checksums(rows).items():
            if sums is not None and name in sums and found != sums[name]:
                raise FolderError("resume", f"{home / name}.f64: its first {rows} rows are not those of its "
                                            "checkpoint (their CRC-32 differs): the file was changed")
        return history

    def _mapped(self, name: str, shape: tuple, capacity: int) -> np.ndarray:
        """The rows of ``name`` in its file, with room for ``capacity`` rows reserved on disk first."""
        if not np.prod(shape, dtype=int):          # no columns (δ of a run without a plate): nothing to keep
            return np.zeros((capacity, *shape))
        path = self.folder / f"{name}.f64"
        _reserve(path, capacity * 8 * int(np.prod(shape, dtype=int)))
        return np.memmap(path, dtype=np.float64, mode="r+", shape=(capacity, *shape))

    def reserve(self, row: int) -> None:
        """Room for ``row`` in every array (doubling their capacity when full): OSError on a full disk, else room."""
        if any(len(buffer) <= row for buffer in self.buffers.values()):
            self._grow(2 * (row + 1))

    def put(self, name: str, row: int, value) -> np.ndarray:
        """Write ``value`` into ``row`` (doubling the capacity of every array when full); the rows up to it."""
        if len(self.buffers[name]) <= row:
            self._grow(2 * (row + 1))
        buffer = self.buffers[name]
        buffer[row] = value
        return buffer[:row + 1]

    def _grow(self, capacity: int) -> None:
        """Room for ``capacity`` rows in every array: on disk for all files first, or (a full disk) for none."""
        short = {name: buffer for name, buffer in self.buffers.items() if len(buffer) < capacity}
        files = {name: self.folder / f"{name}.f64" for name, buffer in short.items() if isinstance(buffer, np.memmap)}
        sizes = {name: path.stat().st_size for name, path in files.items()}
        try:
            for name, path in files.items():
                _reserve(path, capacity * 8 * int(np.prod(short[name].shape[1:], dtype=int)))
        except OSError:                             # give back what was reserved: the checkpoint still fits
            for name, path in files.items():
                os.truncate(path, sizes[name])
            raise
        for name, old in short.items():
            if name in files:
                old.flush()
                new = np.memmap(files[name], dtype=np.float64, mode="r+", shape=(capacity, *old.shape[1:]))
            else:
                new = np.zeros((capacity, *old.shape[1:]))
                new[:len(old)] = old
            self.buffers[name] = new

    def flush(self) -> None:
        """Write the mapped rows to their files."""
        for buffer in self.buffers.values():
            if isinstance(buffer, np.memmap):
                buffer.flush()

    def checksums(self, rows: int) -> dict[str, int]:
        """The CRC-32 of the bytes of each array's first ``rows`` rows; reads only the rows not summed before."""
        if rows < self._summed:
            self._sums, self._summed = {}, 0
        for name, buffer in self.buffers.items():
            self._sums[name] = zlib.crc32(buffer[self._summed:rows], self._sums.get(name, 0))
        self._summed = rows
        return dict(self._sums)

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


def _reserve(path: Path, size: int) -> None:
    """Allocate the first ``size`` bytes of ``path`` on disk (created or extended, never cut): ENOSPC or room.

    A link at ``path`` is refused (ELOOP), not extended.
    """
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND | os.O_NOFOLLOW | os.O_CLOEXEC, 0o666)
    try:
        os.posix_fallocate(fd, 0, size)
    finally:
        os.close(fd)


def remove_others(folder, keep: Path) -> None:
    """Delete the history folders in ``folder`` other than ``keep`` (those of runs a checkpoint no longer names)."""
    for home in Path(folder).glob(f"{PREFIX}*"):
        if home.is_dir() and home.resolve() != Path(keep).resolve():
            shutil.rmtree(home, ignore_errors=True)


def step_rows(state) -> dict[str, np.ndarray]:
    """The rows every run records of a step's state (:data:`~ngwear.results.step_fields.RECORDED`)."""
    instant = state.instant
    return {"times": instant.t, "speed_factor": instant.speed, "load_factor": instant.load, "wear": state.wear,
            "normal_displacement": state.normal, "pressure": state.pressure, "reaction": state.lam,
            "forces": state.forces, "plate_displacement": state.plate}


class Recording:
    """The recording of a run into ``result``: its rows in ``history``.

    Attributes
    ----------
    result : Result
        What the run produced so far; its arrays are views of the recorded rows.
    history : History
        The rows' storage, in memory or in mapped files of an output folder.
    """

    def __init__(self, result: Result, history: History):
        self.result, self.history = result, history

    @classmethod
    def start(cls, scene, disc, folder=None) -> Recording:
        """An empty result with room for the scene's steps, in memory or (``folder``) in mapped files there.

        NoSpace when the folder has no room for them.
        """
        shapes, coefficients = row_shapes(scene, disc), disc.contact.coefficients
        try:
            history = History.empty(shapes, scene.time.steps + 1, folder)
        except OSError as err:
            if not no_space(err):
                raise
            size = (scene.time.steps + 1) * sum(8 * int(np.prod(shape, dtype=int)) for shape in shapes.values())
            raise NoSpace(f"no space left on device in {folder} for the rows of {scene.time.steps + 1} steps "
                          f"({size / 1e6:.4g} MB); nothing was computed") from None
        result = Result(scene, disc.points.coords, disc.points.weights,
                        {name: np.zeros((0, *shape)) for name, shape in shapes.items()}, coefficients.friction,
                        coefficients.wear, coefficients.stiffness, discretization=disc, provenance=provenance(scene))
        return cls(result, history)

    def reserve(self) -> None:
        """Room for the next step's row: an OSError (a full disk) before anything of the step is kept, else none later."""
        self.history.reserve(len(self.result.times))

    def append(self, state, heated: dict | None = None) -> None:
        """Record the state's step as step j = the number of steps so far (the rows double when full: adaptive runs).

        ``heated``: the rows of the heat and of the coefficients of state (:meth:`~ngwear.runs.heating.Heating.after`).
        """
        result, j = self.result, len(self.result.times)
        rows = {**step_rows(state), **(heated or {})}
        if set(rows) != set(result.rows):
            raise KeyError(f"a step records {', '.join(result.rows)} (got {', '.join(rows)})")
        for name in result.rows:
            result.rows[name] = self.history.put(name, j, rows[name])
        result.newton.append(state.record)

    def revise(self, name: str, value: np.ndarray) -> None:
        """Rewrite the last step's row of ``name``."""
        result = self.result
        result.rows[name] = self.history.put(name, len(result.times) - 1, value)

    def moved(self, realised: np.ndarray, disc, before: np.ndarray) -> None:
        """A geometry update after the last step: its wear W at the points leaves the layer for the body (on ``disc``).

        The mesh in force until now (its vertices ``before``) is kept if a frame since the last update shows it (and
        ``disc``'s, in force from this step, until the next update tells), and the displacement of those frames and
        of this step (a frame, or not: the next steps tell) is recovered on the discretization it was solved on,
        before ``disc`` replaces it.  The last row's wear becomes w − W (≥ 0).
        """
        result = self.result
        start, k = (result.removed_rows[-1] if len(result.removed_rows) else 0), len(result.removed_rows)
        frames = [j for j in result.stored_steps if start <= j < result.steps]    # exact: no later step is nearer
        if frames:
            result.meshes[k] = before
        else:
            result.meshes.pop(k, None)
        result.meshes[k + 1] = coordinates(disc.mesh)
        for j in [j for j in result.fields if start <= j < result.steps and j not in frames]:
            del result.fields[j]                        # the last update's step, no frame after all
        for j in [*frames, result.steps]:
            result.displacement(j)
        w = np.maximum(result.wear[-1] - realised, 0.0)
        result.removed = np.vstack([result.removed, realised]) if len(result.removed_rows) else realised[None, :].copy()
        result.removed_rows = np.append(result.removed_rows, result.steps)
        result.moved_weights = np.vstack([result.moved_weights, disc.points.weights]) \
            if result.moved_weights is not None else disc.points.weights[None, :].copy()
        self.revise("wear", w)
        result.discretization, result.mesh_digest = disc, None

    def keep_field(self, u: np.ndarray) -> None:
        """Keep the displacement u of the step just recorded (a nonlinear body's: recovering it needs an iteration).

        The previous step's goes unless it may be a frame (an output time within half a step of it).
        """
        self._keep(self.result.fields, u)

    def keep_temperature(self, temperature: np.ndarray) -> None:
        """Keep the nodal temperature of the step just recorded, for the frames (the previous one as a field's)."""
        self._keep(self.result.temperatures, temperature)

    def _keep(self, kept: dict, value: np.ndarray) -> None:
        j = self.result.steps
        previous = j - 1
        if previous in kept and not self._frame_candidate(previous):
            del kept[previous]
        kept[j] = value.copy()

    def _frame_candidate(self, j: int) -> bool:
        scene, times = self.result.scene, self.result.times
        out, t = scene.output, times[j]
        half = 0.5 * max(t - times[j - 1] if j else 0.0, times[j + 1] - t if j + 1 < len(times) else 0.0)
        wanted = output_times(out, np.array([t]), scene.time.T)
        return bool(np.any(np.abs(wanted - t) <= half * (1 + 1e-9)))

    def keep_in(self, folder) -> None:
        """Move the rows into mapped files of a new history folder in ``folder`` (to checkpoint there)."""
        rows = len(self.result.times)
        self.history = self.history.moved(folder, rows)
        self.result.rows = {name: self.history.buffers[name][:rows] for name in self.result.rows}

    def fail(self, message: str, newton: NewtonRecord) -> None:
        """Stop the run at a step that failed: its status says why, its Newton record is kept."""
        self.result.status = message
        self.result.newton.append(newton)

    def settle(self) -> None:
        """After an interrupt inside :meth:`append`: the arrays and records cut to the steps all of them hold."""
        result = self.result
        rows = min(len(values) for values in result.rows.values())
        result.rows = {name: values[:rows] for name, values in result.rows.items()}
        del result.newton[rows:]

    def interrupt(self) -> None:
        """Mark the run as stopped on request (Ctrl-C, SIGTERM): every completed step is kept."""
        self.result.status = "interrupted"
