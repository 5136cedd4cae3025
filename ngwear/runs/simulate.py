"""The time loop: scheme P^hk of the paper (eqs. 14–15) and its implicit / second-order variants.

Step 0 solves the contact problem at t = 0 with no wear; then, step after step, the wear law of the
next step is prepared from w_j, p_j (:mod:`ngwear.numerics.wear`), the contact problem is solved at
t_{j+1} and s = ν·u, p, λ, w are recorded at the contact points.  The steps are uniform or chosen by
an error estimate (:mod:`ngwear.runs.clock`; a rejected step is redone smaller).  Bulk displacement
fields are recovered (one back-substitution each) only for the steps that are written or looked at.
With a temperature or a coefficient of the state (:mod:`ngwear.runs.heating`) the coefficients are read from the
last step's state before each step and the body heated after it.

Nothing is lost on an interrupt: a set ``stop`` event (the CLI's SIGINT/SIGTERM) or Ctrl-C ends the
run at a step boundary with status ``interrupted`` and every completed step; with an output folder
the run writes checkpoints there (:mod:`ngwear.results.checkpoint`) from which ``resume`` goes on, after removing
the files of an earlier run there (:func:`~ngwear.results.folder.clear`).
The run holds its folders (:func:`ngwear.results.folder.hold`); when the disk fills it stops at a step
boundary, writes what fits and raises :class:`~ngwear.results.folder.NoSpace` saying which steps are kept.

A part's life (:mod:`ngwear.runs.life`): a ``[programme]`` runs its stops through a
:class:`~ngwear.runs.life.StopClock` (cycle jumps included), ``wear.geometry = "surface"`` moves the worn face after
the steps that reach ``wear.update`` (:class:`~ngwear.runs.life.Surface`), and ``wear.limit`` ends the run as
``worn_out`` (:func:`~ngwear.runs.life.worn_out`).

Every step is checked against the invariants (:mod:`ngwear.results.invariants`) before it is recorded:
the first step that breaks one stops the run (status naming the step, the invariant and by how much),
keeping the steps before it.  After it is recorded, whether it stays where the model is valid
(:mod:`ngwear.results.validity`): strains beyond 10 % stop the run after it, beyond 1 % and a worn-through
layer are warnings.
"""
from __future__ import annotations

import logging
import time
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..model import plausibility
from ..model.coefficients import bound, describe
from ..model.geometry import build_mesh
from ..model.meshing import Stopped
from ..model.scene import Scene, SceneError
from ..numerics.discrete import Discretization
from ..numerics.problem import Problem
from ..numerics.solver import ConvergenceError
from ..numerics.wear import WearIntegrator, diverging, explicit_stability
from ..results.checkpoint import Checkpoint, Saver
from ..results.folder import NoSpace, clear, hold, no_space
from ..results.invariants import StepCheck
from ..results.recording import Recording, StepRecord
from ..results.result import Result
from ..results.validity import Validity
from .clock import Clock
from .heating import Heating
from .life import WORN_OUT, StopClock, Surface, worn_out
from .progress import bar
from .stepper import Step, Stepper

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
        the stage it is in (a large mesh at once), with :class:`~ngwear.model.meshing.Stopped`.
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
    scene, disc, recording = start.scene, start.disc, start.recording
    result = recording.result
    stages.prepare(disc)
    surface = result.surface = Surface(scene, disc, start.surface) if scene.wear.geometry == "surface" else None
    clock = (Clock(scene, disc.contact.largest_rate(), result.rejected, start.step) if scene.programme is None
             else StopClock(scene, disc.contact, result, surface))      # its drive set where the rows end
    clock.replay(result.times, [disc.contact.alpha(t) * p for t, p in zip(result.times, result.pressure)])
    stepper = Stepper(Problem(disc), StepCheck(result), Validity(result))
    stepper.heating = result.heating = Heating.of(scene, disc, start.heat)
    integrator = WearIntegrator(scene.wear.integrator, disc.contact.law, disc.points.n)
    saver = Saver(start.checkpoint, scene.output.checkpoint_seconds, rows=start.kept)
    steps_bar = _progress(scene, result) if progress else None
    before, solving = result.wall_time, time.perf_counter()
    x, lam = start.x, start.lam
    try:
        if result.steps < 0:
            x, lam = _first(stepper, integrator, recording, x, lam)
            recording.continuation = (x, lam, clock.next_step)
            worn_out(result)
        while result.completed and not clock.done(result.steps, result.times[-1]):
            if stop is not None and stop.is_set():
                recording.interrupt()
                break
            attempt = _next(stepper, integrator, clock, recording, x, lam)
            if attempt is None:
                break
            x, lam = attempt
            recording.continuation = (x, lam, clock.next_step)
            if worn_out(result):
                break
            if surface is not None and surface.due(result.wear[-1]):
                stepper = surface.apply(result, clock)
                if stepper is None:
                    break
            if steps_bar is not None:
                steps_bar.update(1 if not scene.time.adaptive else result.times[-1] - result.times[-2])
            if not saver.maybe(result):
                break
    except KeyboardInterrupt:
        recording.settle()
        recording.interrupt()
    except OSError as err:                      # the rows found no room to grow
        if not no_space(err):
            raise
        recording.settle()
        saver.full = err
    result.wall_time, result.rejected = before + time.perf_counter() - began, clock.rejected
    result.solve_time += time.perf_counter() - solving
    stepper.validity.report(result)
    if clock.unmet:
        result.warnings.append(f"time.tolerance: steps at time.min_step = {scene.time.min_step:g} missed the "
                               "tolerance; lower time.min_step")
    saver.write(result)
    if steps_bar is not None:
        steps_bar.close()
    if saver.full is not None:
        raise NoSpace(saver.kept(result), result, resumable=saver.rows > 0)
    if result.status not in ("completed", WORN_OUT):
        log.warning("%s: %s", scene.name, result.status)
    return result


@dataclass
class _Start:
    """Where a run starts, new or resumed: one state the time loop goes on from.

    Its scene, discretization and recording, the solver's warm start (x, λ), the output folder it checkpoints into,
    and for a resumed run the adaptive clock's next step and the rows the checkpoint read keeps (``kept``; 0 when the
    run goes on in another folder).
    """

    scene: Scene
    disc: Discretization
    recording: Recording
    x: np.ndarray
    lam: np.ndarray
    checkpoint: object
    step: float | None = None
    kept: int = 0
    heat: dict | None = None
    surface: dict | None = None


def _start(scene, discretization, checkpoint, stages, stop) -> _Start:
    """A new run: its discretization (of ``discretization`` where the scene allows), empty rows, the unloaded state."""
    cautions = plausibility.warnings(scene)         # an SI scene's unlikely moduli, stiffness, wear: said first
    for caution in cautions:
        log.warning("%s", caution)
    if discretization is None:
        disc = stages.run("mesh (Netgen, or the cache)", lambda: Discretization(scene, build_mesh(scene, stop=stop)))
    else:
        disc = discretization if discretization.scene == scene else discretization.with_scene(scene)
    refusal = diverging(scene, disc.contact.largest_rate())
    if refusal:
        stages.close()
        raise SceneError(refusal)
    if checkpoint is not None:
        clear(checkpoint)                           # an earlier run's files go: a folder never mixes two runs
    recording = Recording.start(scene, disc, checkpoint)
    recording.result.warnings.extend(cautions)
    warning = None if scene.time.adaptive else explicit_stability(scene, disc.contact.largest_rate())
    if warning:
        log.warning("%s", warning)
        recording.result.warnings.append(warning)
    return _Start(scene, disc, recording, Problem(disc).unknowns(), np.zeros(disc.points.n), checkpoint)


def _resume(scene, resume, checkpoint, stages) -> _Start:
    """A run going on from the checkpoint in ``resume`` (into ``checkpoint``, else into ``resume``)."""
    saved = stages.run("reading the checkpoint and its mesh", lambda: Checkpoint(resume, scene))
    recording, folder = saved.recording, checkpoint if checkpoint is not None else resume
    if Path(folder).resolve() != Path(resume).resolve():
        clear(folder)                           # the run goes on in another folder: the first stays as it was
    if not recording.history.is_in(folder):
        recording.keep_in(folder)
    recording.continuation = (saved.x, saved.lam, saved.step)
    kept = len(saved.result.times) if recording.history.is_in(resume) else 0
    return _Start(saved.scene, saved.result.discretization, recording, saved.x, saved.lam, folder, saved.step, kept,
                  saved.heat, saved.surface)


@dataclass
class _Attempt:
    """One solved step: the unknowns, the contact-point values and the Newton record."""

    x: np.ndarray
    lam: np.ndarray
    s: np.ndarray
    delta: np.ndarray
    pressure: np.ndarray
    wear: np.ndarray
    record: object


def _solve(stepper, integrator, t: float, t_prev: float | None, x, lam) -> _Attempt:
    """Solve the step ending at t with the prepared wear law; ConvergenceError or ArithmeticError on failure."""
    step, problem = Step(t, t_prev, integrator), stepper.problem
    x, lam, record = stepper.solve(step, x, lam)
    s, delta = problem.normal(x), problem.plate(x)
    pressure = step.law.pressure(s - problem.d0)
    if not all(np.all(np.isfinite(a)) for a in (s, lam, pressure, delta)):
        raise ArithmeticError(record)
    return _Attempt(x, lam, s, delta, pressure, integrator.wear_at(s - problem.d0), record)


def _record(recording: Recording, stepper, t: float, attempt: _Attempt, heating: tuple = (0, ()),
            still: bool = False) -> bool:
    """Record the step if it keeps the invariants; else stop the run.

    ``heating``: (the stops a cycle jump applied, the heat's steps) over it (:meth:`~ngwear.runs.clock.Clock.heating`;
    none at step 0); ``still``: it slid nothing.
    """
    broken = stepper.check(t, attempt.wear, attempt.s, attempt.pressure, attempt.lam)
    if broken is not None:
        name, value = broken
        remedy = (f"a cycle jump of {heating[0]} stops ended here: try a smaller programme.jump_tolerance or "
                  f"programme.jump = false" if heating[0] else "try wear.integrator = 'implicit' or more time.steps")
        recording.fail(f"step {len(recording.result.times)} (t = {t:.4g}): invariant {name} broken by {value:.3g} "
                       f"(allowed {stepper.check.checker.allowed[name]:.0e}; see ngwear.results.invariants); "
                       f"{remedy}", attempt.record)
        return False
    forces = stepper.problem.contact.forces(attempt.pressure, attempt.lam, t)
    heated = {} if stepper.heating is None else stepper.heating.advance(heating[1], t, attempt.pressure, still,
                                                                        heating[0])
    recording.append(StepRecord({"times": t, "wear": attempt.wear, "normal_displacement": attempt.s,
                                 "pressure": attempt.pressure, "reaction": attempt.lam, "forces": forces,
                                 "plate_displacement": attempt.delta, **heated}, attempt.record))
    if heated and stepper.heating.heat is not None:
        recording.keep_temperature(stepper.heating.heat.temperature)
    displacement = stepper.displacement(attempt.x)
    if displacement is not None:          # a nonlinear body's field is kept for the frames and the last step
        recording.keep_field(displacement)
    beyond = stepper.validity(recording.result.steps, t, attempt.s, attempt.delta, attempt.wear)
    if beyond is not None:                # the step holds the model's equations, but beyond where it is valid
        recording.result.status = beyond
        return False
    return True


def _failed(recording: Recording, scene: Scene, j: int, t: float, err: Exception) -> None:
    if isinstance(err, ArithmeticError):
        recording.fail(f"step {j} (t = {t:.4g}): non-finite solution", err.args[0])
    else:
        recording.fail(f"step {j} (t = {t:.4g}): {err}; {_remedy(scene, err.record)}", err.record)


def _first(stepper, integrator, recording: Recording, x, lam):
    """Step 0: the contact problem at t = 0, before any wear (from the unloaded state)."""
    try:
        attempt = _solve(stepper, integrator, 0.0, None, x, lam)
    except (ConvergenceError, ArithmeticError) as err:
        _failed(recording, stepper.scene, 0, 0.0, err)
        return x, lam
    _record(recording, stepper, 0.0, attempt)
    return attempt.x, attempt.lam


def _next(stepper, integrator, clock: Clock, recording: Recording, x, lam):
    """The step after the last recorded one, redone smaller while the clock rejects it; (x, λ) or None."""
    result = recording.result
    contact, j = stepper.problem.contact, result.steps
    t, w, p = result.times[j], result.wear[j], result.pressure[j]
    refusal = None if stepper.heating is None else stepper.heating.prepare(stepper, t, p)   # coefficients of state
    if refusal is not None:
        result.status = f"step {j + 1}: {refusal}"
        return None
    times = list(result.times[max(j - 1, 0):j + 1])
    rates = [contact.alpha(tt) * pp for tt, pp in zip(times, result.pressure[max(j - 1, 0):j + 1])]
    while True:
        t_next = clock.next_time(j, t)
        clock.prepare(integrator, contact, stepper.check, w, p, t, t_next)
        try:
            attempt = _solve(stepper, integrator, t_next, t, x, lam)
        except (ConvergenceError, ArithmeticError) as err:
            if clock.shrink():
                continue
            _failed(recording, stepper.scene, j + 1, t_next, err)
            return None
        if clock.judge([*times, t_next], [*rates, contact.alpha(t_next) * attempt.pressure]):
            kept = _record(recording, stepper, t_next, attempt, clock.heating(t, t_next), clock.still)
            return (attempt.x, attempt.lam) if kept else None


class Stages:
    """Work outside the time loop, stage by stage on a progress bar.

    The set-up before the first step (minutes on large 3D meshes), the CLI's uniqueness check after the last.

    Stages already done (a reused discretization) are skipped; without ``show`` nothing is drawn.  A set ``stop``
    ends the set-up after the stage it is in (meshing at once) with :class:`~ngwear.model.meshing.Stopped`.
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




def _remedy(scene: Scene, record) -> str:
    """What to try after a Newton failure, from the failure's history."""
    last = record.residuals[-1] if record.residuals else np.inf
    if np.isfinite(last) and last < 1e3 * scene.solver.tolerance:
        return f"the merit stalled at round-off: raise solver.tolerance above {last:.1e}"
    tips = [f"more time.steps (now {scene.time.steps})",
            f"solver.max_iterations > {scene.solver.max_iterations}"]
    if bound(scene.contact.friction) != 0:
        tips.append(f"a smaller contact.friction (μ = {describe(scene.contact.friction)} may exceed the smallness "
                    f"bound (H_S): see `ngwear verify`)")
    return "try " + ", ".join(tips)


def _progress(scene: Scene, result: Result):
    """A progress bar over the steps (uniform) or over time (adaptive), from where the run starts."""
    if not scene.time.adaptive:
        return bar(total=scene.time.steps, initial=max(result.steps, 0), desc=scene.name, unit="step",
                   leave=False)
    return bar(total=scene.time.T, initial=result.times[-1] if len(result.times) else 0.0, desc=scene.name,
               leave=False, bar_format="{l_bar}{bar}| t = {n:.4g} of {total:.4g} [{elapsed}<{remaining}]")
