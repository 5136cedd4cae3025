"""A run recording itself: each step's row into its :class:`~ngwear.results.result.Result`, kept to go on from.

:meth:`Recording.start` makes a run's empty result with room for its rows, in memory or (an output folder) in mapped
files there (:mod:`ngwear.results.history`); :meth:`Recording.append` records one :class:`StepRecord`; the
recording keeps the solver's warm start to go on from the last step (``continuation``, what a checkpoint writes)
and the bookkeeping of a run that stops: a failed step (:meth:`~Recording.fail`), an interrupt (even one inside
:meth:`~Recording.append`: :meth:`~Recording.settle`), rows moved to another folder (:meth:`~Recording.keep_in`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..numerics.solver import NewtonRecord
from .folder import NoSpace, no_space
from .history import History
from .provenance import provenance
from .result import Result, output_times, row_shapes


@dataclass(frozen=True)
class StepRecord:
    """One completed step: its Newton record and its row of each recorded field, by name.

    The fields are those of :data:`~ngwear.results.step_fields.RECORDED` that the run records, each given once.
    """

    rows: dict
    newton: NewtonRecord


class Recording:
    """The recording of a run into ``result``: its rows in ``history``, its warm start ``continuation``.

    Attributes
    ----------
    result : Result
        What the run produced so far; its arrays are views of the recorded rows.
    history : History
        The rows' storage, in memory or in mapped files of an output folder.
    continuation : tuple or None
        (x, λ, next step): the solver's warm start and the adaptive clock's next step, to go on from the last step.
    """

    def __init__(self, result: Result, history: History, continuation: tuple | None = None):
        self.result, self.history, self.continuation = result, history, continuation
        result.recording = self

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

    def append(self, step: StepRecord) -> None:
        """Record step j = the number of steps so far (the rows double when full: adaptive runs)."""
        result, j = self.result, len(self.result.times)
        if set(step.rows) != set(result.rows):
            raise KeyError(f"a step records {', '.join(result.rows)} (got {', '.join(step.rows)})")
        for name in result.rows:
            result.rows[name] = self.history.put(name, j, step.rows[name])
        result.newton.append(step.newton)

    def revise(self, name: str, value: np.ndarray) -> None:
        """Rewrite the last step's row of ``name`` (a geometry update moves its wear into the body)."""
        result = self.result
        result.rows[name] = self.history.put(name, len(result.times) - 1, value)

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
