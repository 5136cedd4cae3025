"""The time loop, written once: the clock's steps one after the other, and what watches each of them.

    state₀ → advance → state₁ → advance → …        (:func:`~ngwear.runs.step.advance`, one step each)

Step 0 solves the contact problem at t = 0 with no wear; then, step after step, the heat sets the coefficients of the
next step from the last state (:meth:`~ngwear.runs.heating.Heating.before`), the clock says where the step ends and
what wear law it solves (:class:`~ngwear.runs.clock.Clock`, :class:`~ngwear.runs.stop_clock.StopClock`; a rejected
adaptive step is redone smaller), and :func:`~ngwear.runs.step.advance` solves it.  A step is kept when it holds the
scheme's invariants (:class:`~ngwear.runs.checks.StepCheck`); then the heat heats the body over it, the recording
records its row, the validity checks (:mod:`ngwear.runs.validity`), ``wear.limit``, the geometry update
(:class:`~ngwear.runs.surface.Surface`), the progress bar and the checkpoints see it, in that order.  The first that
ends the run says why in ``Result.status``; every step before it is kept.
"""
from __future__ import annotations

import time

import numpy as np

from ..model import plausibility
from ..model.coefficients import bound, describe
from ..model.keys import SceneError
from ..numerics.systems.newton import ConvergenceError
from ..results.checkpoint import write_checkpoint
from ..results.folder import no_space
from .checks import StepCheck, worn_out
from .clock import Clock
from .heating import Heating
from .step import State, StepCaches, Target, advance
from .stop_clock import StopClock
from .surface import Surface
from .validity import Validity


class Run:
    """One run: its discretization and caches, its state, its clock and the observers of its steps.

    Parameters
    ----------
    scene, disc
        What runs, on which discretization (a geometry update replaces ``disc``: :meth:`moved`).
    recording : Recording
        The record (``recording.result``) and where its rows go.
    state : State
        Where the run starts: the unloaded body, or a checkpoint's last step.
    integrator : WearIntegrator
        The wear scheme.
    saved : dict
        A resumed run's heat and surface state and the adaptive clock's next step (empty for a new run).
    saver, progress, stop
        The checkpoints (:class:`Saver`), the progress bar (None: none) and a stop event.
    """

    def __init__(self, scene, disc, recording, state: State, integrator, saved: dict, saver, progress=None,
                 stop=None):
        result = recording.result
        self.scene, self.disc, self.recording, self.state, self.integrator = scene, disc, recording, state, integrator
        self.saver, self.progress, self.stop = saver, progress, stop
        self.caches = StepCaches.on(disc)
        self.surface = Surface(scene, disc, saved.get("surface")) if scene.wear.geometry == "surface" else None
        if self.surface is not None:
            result.recession = self.surface.recession
        self.clock = (Clock(scene, disc.contact.largest_rate(), result.rejected, saved.get("step"))
                      if scene.programme is None else StopClock(scene, result, self.surface))
        contact = disc.contact
        self.clock.replay(result.times, [contact.rate(state.coefficients, v, p) for v, p in
                                         zip(result.speed_factor, result.pressure)])
        self.heating = Heating.of(scene, disc, saved.get("heat"))
        self._thermal()
        self.check, self.validity = StepCheck(result, disc), Validity(result, disc)
        self.proposed = self.clock.next_step        # the clock's next step after the last recorded one
        self.cautions = plausibility.warnings(scene) + plausibility.load_warnings(scene, float(disc.points.weights.sum()))

    @property
    def result(self):
        return self.recording.result

    def first(self) -> bool:
        """Step 0: the contact problem at the first instant, before any wear (from the unloaded state)."""
        target = Target(self.disc.contact.motion.first(), self.integrator.rest(self.state.wear))
        try:
            state, _ = advance(self.disc, self.caches, self.state, target)
        except (ConvergenceError, ArithmeticError) as err:
            self._failed(0, 0.0, err)
            return False
        return self._keep(state, target) and not worn_out(self.result)

    def next(self) -> bool:
        """The step after the last recorded one, redone smaller while the clock rejects it; whether the run goes on."""
        result, contact, j = self.result, self.disc.contact, self.state.steps
        if self.heating is not None:
            try:
                self.state = self.heating.before(self.state, self.caches)
            except SceneError as err:                   # a coefficient of the state out of its range
                result.status = f"step {j + 1}: {err}"
                return False
        state, adaptive = self.state, self.clock.adaptive
        rows = slice(max(j - 1, 0), j + 1)          # an adaptive step's error from the rates of the last two and its own
        times = list(result.times[rows]) if adaptive else []
        rates = [contact.rate(state.coefficients, v, p) for v, p in zip(result.speed_factor[rows],
                                                                         result.pressure[rows])] if adaptive else []
        while True:
            target = self.clock.target(state, contact, self.integrator)
            if target.still:
                self.check.cross(target.instant.t, target.wear.a)
            try:
                new, _ = advance(self.disc, self.caches, state, target)
            except (ConvergenceError, ArithmeticError) as err:
                if self.clock.shrink():
                    continue
                self._failed(j + 1, target.instant.t, err)
                return False
            rate = contact.rate(new.coefficients, new.instant.speed, new.pressure) if adaptive else None
            if self.clock.judge([*times, target.instant.t], [*rates, rate]):
                return self._keep(new, target) and self._watched()

    def done(self) -> bool:
        """Whether the clock has reached the run's end."""
        return self.clock.done(self.state, self.disc.contact)

    def _keep(self, state: State, target: Target) -> bool:
        """Record the step if it keeps the invariants (else stop the run); then whether the model holds there."""
        broken = self.check(state)
        if broken is not None:
            name, value = broken
            remedy = (f"a cycle jump of {target.jumped} stops ended here: try a smaller programme.jump_tolerance or "
                      "programme.jump = false" if target.jumped else likeliest(self.cautions) or
                      "try wear.integrator = 'implicit' or more time.steps")
            self.recording.fail(f"step {state.steps} (t = {state.instant.t:.4g}): invariant {name} broken by "
                                f"{value:.3g} (allowed {self.check.allowed(name):.0e}; see ngwear.runs.checks); "
                                f"{remedy}", state.record)
            return False
        self.recording.reserve()
        heated = {} if self.heating is None else self.heating.after(state, target)
        self.state, self.proposed = state, self.clock.next_step
        self.recording.append(state, heated)
        if heated and self.heating.heat is not None:
            self.recording.keep_temperature(self.heating.heat.temperature)
        if state.displacement is not None:          # a nonlinear body's field is kept for the frames and the last step
            self.recording.keep_field(state.displacement)
        beyond = self.validity(state)
        if beyond is not None:                      # the step holds the model's equations, but beyond where it is valid
            self.result.status = beyond
            return False
        return True

    def _watched(self) -> bool:
        """After a recorded step (not step 0): ``wear.limit``, the geometry update, the progress, the checkpoints."""
        if worn_out(self.result):
            return False
        if self.surface is not None and self.surface.due(self.state.wear):
            disc = self.surface.update(self.recording, self.state.wear)
            if disc is None:
                return False
            self.moved(disc)
        if self.progress is not None:
            self.progress.update(self.result)
        return self.saver.maybe(self.recording, self.continuation)

    def moved(self, disc) -> None:
        """Go on on ``disc`` after a geometry update: its caches and checks anew, the heat on the moved body."""
        self.disc, self.caches = disc, StepCaches.on(disc)
        self.state.wear, self.state.displacements = self.result.wear[-1], ()
        self.check, self.validity = StepCheck(self.result, disc), Validity(self.result, disc)
        if self.heating is not None:
            self.heating.moved(disc)
        self._thermal()

    def _thermal(self) -> None:
        """The record recovers its steps' thermal displacement with the G of the discretization in force."""
        if self.heating is not None and self.heating.heat is not None:
            self.result.thermal = (self.disc, self.heating.load)

    def continuation(self) -> dict[str, np.ndarray]:
        """What a checkpoint needs besides the record to go on from the last step, bit for bit."""
        state = self.state
        heat = {} if self.heating is None else self.heating.state(state.reference)
        surface = {} if self.surface is None else self.surface.state
        return {"x": state.x, "lam": state.lam, "step": np.array(self.proposed), **heat, **surface}

    def _failed(self, j: int, t: float, err: Exception) -> None:
        if isinstance(err, ArithmeticError):
            self.recording.fail(f"step {j} (t = {t:.4g}): non-finite solution", err.args[0])
        else:
            advice = likeliest(self.cautions) or remedy(self.scene, err.record, j)
            self.recording.fail(f"step {j} (t = {t:.4g}): {err}; {advice}", err.record)


def run(loop: Run) -> None:
    """The loop: step 0 if the run has none, then the clock's steps until its end, a stop or a failure."""
    result, stop = loop.result, loop.stop
    if loop.state.steps < 0 and not loop.first():
        return
    while result.completed and not loop.done():
        if stop is not None and stop.is_set():
            loop.recording.interrupt()
            return
        if not loop.next():
            return


def likeliest(cautions: list[str]) -> str | None:
    """The likeliest cause of a failure in a scene with implausible numbers: the first of them (None: none)."""
    return f"the likeliest cause: {cautions[0]}" if cautions else None


def remedy(scene, record, step: int) -> str:
    """What to try after a Newton failure of ``step``, from the failure's history.

    Smaller steps help from step 1 on (step 0 is the contact problem at t = 0, before any wear): more
    ``time.steps``, or ``programme.steps_per_stop`` in a programme, which sets the steps.
    """
    last = record.residuals[-1] if record.residuals else np.inf
    if np.isfinite(last) and last < 1e3 * scene.solver.tolerance:
        return f"the merit stalled at round-off: raise solver.tolerance above {last:.1e}"
    programme = scene.programme
    steps = ([] if step == 0 else [f"more time.steps (now {scene.time.steps})"] if programme is None else
             [f"more programme.steps_per_stop (now {programme.steps_per_stop})"])
    tips = [*steps, f"solver.max_iterations > {scene.solver.max_iterations}"]
    if bound(scene.contact.friction) != 0:
        tips.append(f"a smaller contact.friction (μ = {describe(scene.contact.friction)} may exceed the smallness "
                    f"bound (H_S): see `ngwear verify`)")
    return "try " + ", ".join(tips)


class Saver:
    """A run's checkpoints into ``folder`` (None: none): every ``seconds`` of wall time (0: never) and at its end.

    A checkpoint that finds the disk full is not written (the last one stays) and ends the run (``full``).
    """

    def __init__(self, folder, seconds: float, rows: int = 0):
        self.folder, self.seconds, self.last = folder, seconds, time.perf_counter()
        self.full: OSError | None = None
        self.rows = rows                    # the steps the last checkpoint written (or read, resuming) keeps

    def maybe(self, recording, continuation) -> bool:
        """Checkpoint if it is time (``continuation()``: what it needs besides the record); whether the run may go on."""
        if self.folder is not None and self.seconds > 0 and time.perf_counter() - self.last >= self.seconds:
            self.write(recording, continuation)
        return self.full is None

    def write(self, recording, continuation) -> None:
        """Write the checkpoint now (not before step 0: nothing to go on from)."""
        if self.folder is not None and len(recording.result.times):
            try:
                write_checkpoint(self.folder, recording.result, recording, continuation())
            except OSError as err:
                if not no_space(err):
                    raise
                self.full = err
                return
            self.last, self.rows = time.perf_counter(), len(recording.result.times)

    def kept(self, result) -> str:
        """What a run stopped by a full disk keeps, in one line."""
        t = result.times[-1] if len(result.times) else 0.0
        stopped = f"no space left on device in {self.folder}: the run stopped after step {result.steps} (t = {t:.4g})"
        if not self.rows:
            return f"{stopped}; no checkpoint fitted: free space and run again"
        return (f"{stopped}; its checkpoint keeps steps 0-{self.rows - 1} (t <= {result.times[self.rows - 1]:.4g}): "
                "free space, then resume from it")
