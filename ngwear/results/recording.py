"""A run recording itself: each step's row into its :class:`~ngwear.results.result.Result`.

:meth:`Recording.start` makes a run's empty result with room for its rows, in memory or (an output folder) in mapped
files there (:mod:`ngwear.results.history`); :meth:`Recording.append` records the row of a step's state; the
recording keeps the bookkeeping of a run that stops: a failed step (:meth:`~Recording.fail`), an interrupt (even one
inside :meth:`~Recording.append`: :meth:`~Recording.settle`), rows moved to another folder
(:meth:`~Recording.keep_in`), and a geometry update that moves the last row's wear into the body
(:meth:`~Recording.moved`).
"""
from __future__ import annotations

import numpy as np

from ..numerics.solver import NewtonRecord
from ..numerics.topology import coordinates
from .folder import NoSpace, no_space
from .history import History
from .provenance import provenance
from .result import Result, output_times, row_shapes


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
