"""A run: scheme P^hk of the paper (eqs. 14–15) and its implicit / second-order variants, from set-up to its record.

:func:`simulate` sets a run up (a new one: the discretization, its refusals and warnings; a resumed one: the
checkpoint), runs the time loop (:mod:`ngwear.runs.loop`) and ends it: times, warnings, the last checkpoint.  The
steps are uniform or chosen by an error estimate (:mod:`ngwear.runs.clock`), a programme's stops
(:mod:`ngwear.runs.stop_clock`); bulk displacement fields are recovered (one back-substitution each) only for the
steps that are written or looked at.

Nothing is lost on an interrupt: a set ``stop`` event (the CLI's SIGINT/SIGTERM) or Ctrl-C ends the run at a step
boundary with status ``interrupted`` and every completed step; with an output folder the run writes checkpoints there
(:mod:`ngwear.results.checkpoint`) from which ``resume`` goes on, after removing the files of an earlier run there
(:func:`~ngwear.results.folder.clear`).  The run holds its folders (:func:`ngwear.results.folder.hold`); when the disk
fills it stops at a step boundary, writes what fits and raises :class:`~ngwear.results.folder.NoSpace` saying which
steps are kept.
"""
from __future__ import annotations

import logging
import time
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..model import plausibility
from ..model.netgen_meshing import Stopped
from ..model.scene import Scene, SceneError
from ..model.scene_mesh import build_mesh
from ..numerics.contact import Instant
from ..numerics.discrete import Discretization
from ..numerics.systems import unknowns
from ..numerics.thickness import thickness
from ..numerics.wear import WearIntegrator, diverging, explicit_stability
from ..results.checkpoint import Checkpoint
from ..results.folder import NoSpace, clear, hold, no_space
from ..results.recording import Recording
from ..results.result import Result
from .checks import WORN_OUT
from .heating import Heating
from .loop import Run, Saver, likeliest, run
from .progress import RunProgress, bar
from .step import State

log = logging.getLogger(__name__)


class RunError(RuntimeError):
    """A run that stopped part-way (a Newton failure), for callers that need a completed one (the explorer).

    ``result`` holds the steps it completed.
    """

    def __init__(self, message: str, result):
        super().__init__(message)
        self.result = result


def simulate(scene: Scene, *, discretization: Discretization | None = None, progress: bool = True,
             checkpoint=None, resume=None, stop=None) -> Result:
    """Run the scene's time loop; a run that fails or is interrupted part-way returns the steps it completed.

    Parameters
    ----------
    scene : Scene or None
        What to run (None with ``resume``: the checkpoint's scene).
    discretization : Discretization, optional
        Of an earlier run: its mesh, factorisation and contact compliance are reused wherever the
        scene change allows (see :meth:`Discretization.with_scene`).
    checkpoint : path, optional
        An output folder: a checkpoint is written there every ``output.checkpoint_seconds`` of wall
        time (0: never), when the run is interrupted and when it ends.
    resume : path, optional
        The output folder of an earlier run: go on from its checkpoint, on its mesh.  ``scene`` may
        extend ``time.T``; ``None`` takes the checkpoint's scene.  Checkpoints go on in that folder.
    stop : threading.Event, optional
        When set, the run stops at the next step boundary with status ``interrupted``; during the set-up, after
        the stage it is in (a large mesh at once), with :class:`~ngwear.model.netgen_meshing.Stopped`.
    progress : bool
        Show the set-up's stages and the steps: a bar in a terminal or notebook, else log lines
        (``ngwear.progress`` at INFO, see :mod:`ngwear.runs.progress`).

    Returns
    -------
    Result
        Every completed step; ``status`` says whether the run completed.

    Raises
    ------
    FolderError
        ``checkpoint`` or ``resume`` is in use by another run, or a file of ``resume`` is missing or damaged.
    NoSpace
        The disk filled: the run stopped, its checkpoint keeps the steps that fit (see the message).
    Stopped
        ``stop`` was set before the first step (nothing was computed).
    """
    with ExitStack() as held:
        for folder, key in ((checkpoint, "checkpoint"), (resume, "resume")):
            if folder is not None:
                new = key == "checkpoint" and (resume is None or Path(folder).resolve() != Path(resume).resolve())
                held.enter_context(hold(folder, key, create=new))
        return _simulate(scene, discretization, progress, checkpoint, resume, stop)


def _simulate(scene, discretization, progress, checkpoint, resume, stop) -> Result:
    began = time.perf_counter()
    stages = Stages(scene.name if scene is not None else "resume", progress, stop)
    start = (_start(scene, discretization, checkpoint, stages, stop) if resume is None
             else _resume(scene, resume, checkpoint, stages))
    scene, disc, recording, result = start.scene, start.disc, start.recording, start.recording.result
    stages.prepare(disc)
    integrator = WearIntegrator(scene.wear.integrator, disc.contact.law, disc.contact.wear_law)
    loop = Run(scene, disc, recording, start.state, integrator, start.saved,
               Saver(start.checkpoint, scene.output.checkpoint_seconds, rows=start.kept),
               RunProgress(scene, result) if progress else None, stop)
    before, solving = result.wall_time, time.perf_counter()
    try:
        run(loop)
    except KeyboardInterrupt:
        recording.settle()
        recording.interrupt()
    except OSError as err:                      # the rows found no room to grow
        if not no_space(err):
            raise
        recording.settle()
        loop.saver.full = err
    result.wall_time, result.rejected = before + time.perf_counter() - began, loop.clock.rejected
    result.solve_time += time.perf_counter() - solving
    loop.validity.report(result)
    if loop.heating is not None:
        loop.heating.report(result)
    if loop.clock.unmet:
        result.warnings.append(f"time.tolerance: steps at time.min_step = {scene.time.min_step:g} missed the "
                               "tolerance; lower time.min_step")
    if len(result.times):
        result.continuation = loop.continuation()
    loop.saver.write(recording, lambda: result.continuation)
    if loop.progress is not None:
        loop.progress.close()
    if loop.saver.full is not None:
        raise NoSpace(loop.saver.kept(result), result, resumable=loop.saver.rows > 0)
    if result.status not in ("completed", WORN_OUT):
        log.warning("%s: %s", scene.name, result.status)
    return result


@dataclass
class _Start:
    """Where a run starts, new or resumed: its scene, discretization, recording and state.

    ``checkpoint``: the output folder it checkpoints into; ``saved``: a resumed run's heat, surface and adaptive
    step (:class:`~ngwear.results.checkpoint.Checkpoint`); ``kept``: the rows the checkpoint read keeps (0 when the
    run goes on in another folder).
    """

    scene: Scene
    disc: Discretization
    recording: Recording
    state: State
    checkpoint: object
    saved: dict
    kept: int = 0


def _start(scene, discretization, checkpoint, stages, stop) -> _Start:
    """A new run: its discretization (of ``discretization`` where the scene allows), empty rows, the unloaded state."""
    cautions = plausibility.warnings(scene)         # an SI scene's unlikely moduli, stiffness, wear: said first
    for caution in cautions:
        log.warning("%s", caution)
    if discretization is None:
        disc = stages.run("mesh (Netgen, or the cache)", lambda: Discretization(scene, build_mesh(scene, stop=stop)))
    else:
        disc = discretization if discretization.scene == scene else discretization.with_scene(scene)
    loads = plausibility.load_warnings(scene, float(disc.points.weights.sum()))     # said here, or in the refusal
    cautions += loads
    refusal = diverging(scene, disc.contact.largest_rate())
    if refusal:
        stages.close()
        raise SceneError(refusal + (f"; {likeliest(cautions)}" if cautions else ""))
    for caution in loads:
        log.warning("%s", caution)
    measured = _checked_limit(scene, disc)
    if checkpoint is not None:
        clear(checkpoint)                           # an earlier run's files go: a folder never mixes two runs
    recording = Recording.start(scene, disc, checkpoint)
    recording.result.measured = measured
    recording.result.warnings.extend(cautions)
    warning = None if scene.time.adaptive else explicit_stability(scene, disc.contact.largest_rate())
    if warning:
        log.warning("%s", warning)
        recording.result.warnings.append(warning)
    contact, n = disc.contact, disc.points.n
    state = State(unknowns(disc), np.zeros(n), contact.coefficients, np.zeros(n),
                  reference=Heating.reference(scene, contact))
    return _Start(scene, disc, recording, state, checkpoint, {})


def _checked_limit(scene, disc) -> np.ndarray | None:
    """The worn region's thickness under the contact points, with ``wear.limit`` below its least (None: no limit).

    A limit at or above it would end the run as worn out before anything wore.
    """
    if scene.wear.limit is None:
        return None
    measured = thickness(disc.mesh, disc.points.coords, disc.condensation.nu)
    if scene.wear.limit >= (thinnest := float(measured.min())):
        raise SceneError(f"wear.limit: must be below the worn region's thickness along ν, {thinnest:.4g} at its "
                         f"thinnest (the remaining thickness that ends the run; got {scene.wear.limit:g})")
    return measured


def _resume(scene, resume, checkpoint, stages) -> _Start:
    """A run going on from the checkpoint in ``resume`` (into ``checkpoint``, else into ``resume``)."""
    saved = stages.run("reading the checkpoint and its mesh", lambda: Checkpoint(resume, scene))
    recording, folder = saved.recording, checkpoint if checkpoint is not None else resume
    if Path(folder).resolve() != Path(resume).resolve():
        clear(folder)                           # the run goes on in another folder: the first stays as it was
    if not recording.history.is_in(folder):
        recording.keep_in(folder)
    kept = len(saved.result.times) if recording.history.is_in(resume) else 0
    result, disc = saved.result, saved.result.discretization
    contact = disc.contact
    state = State(saved.x, saved.lam, contact.coefficients, result.wear[-1],
                  instant=Instant(float(result.times[-1]), float(result.speed_factor[-1]),
                                  float(result.load_factor[-1])),
                  normal=result.normal_displacement[-1], pressure=result.pressure[-1],
                  plate=result.plate_displacement[-1], forces=result.forces[-1],
                  reference=Heating.reference(saved.scene, contact, saved.heat), record=result.newton[-1],
                  steps=result.steps)
    return _Start(saved.scene, disc, recording, state, folder,
                  {"heat": saved.heat, "surface": saved.surface, "step": saved.step}, kept)


class Stages:
    """Work outside the time loop, stage by stage on a progress bar.

    The set-up before the first step (minutes on large 3D meshes), the CLI's uniqueness check after the last.

    Stages already done (a reused discretization) are skipped; without ``show`` nothing is drawn.  A set ``stop``
    ends the set-up after the stage it is in (meshing at once) with :class:`~ngwear.model.netgen_meshing.Stopped`.
    """

    def __init__(self, name: str, show: bool, stop=None):
        self.name, self.bar, self.stop = name, None, stop
        if show:
            self.bar = bar(total=None, desc=f"{name}: set-up", leave=False, bar_format="{desc} [{elapsed}]")

    def run(self, label: str, build):
        if self.bar is not None:
            self.bar.set_description_str(f"{self.name}: {label}")
        try:
            done = build()
        except Stopped:
            self.close()
            raise
        if self.stop is not None and self.stop.is_set():
            self.close()
            raise Stopped(label)
        return done

    def prepare(self, disc: Discretization) -> None:
        """Assemble, factorise and condense what the condensed path needs, then close the bar."""
        if disc.scene.solver.method == "condensed":
            for label, build in disc.stages():
                self.run(label, build)
        self.close()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
