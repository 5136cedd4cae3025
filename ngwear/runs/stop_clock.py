"""A programme's clock: its stops one after the other, and the cycle jumps between them.

:class:`StopClock` stands where :class:`~ngwear.runs.clock.Clock` does when the scene has a ``[programme]``
(:mod:`ngwear.model.programme`).  Stop i records m + 1 rows: its start t_i, a solve with no wear step (as step 0 of
a run), then its m steps t_i + d j/m, each with the factors s_v, s_F of its place on the stop's grid
(:meth:`~ngwear.numerics.contact.Motion.at`), k the differences of the stop's own grid: the stops of a block are one
problem.  Between two simulated stops one step crosses the dwell (and the jumped stops): no load and no sliding, so
no wear but what a jump adds; it ends at the next simulated stop's start, solved there with its factors.  After
the last stop one more such step crosses the programme's last dwell to its end T (if it has one), unloaded.

After each simulated stop its wear increment Δw (end minus start) goes to :class:`~ngwear.runs.jumps.CycleJumps`
(``programme.jump``): a jump of N stops adds N Δw on that crossing step and the N stops are recorded as jumped
(:attr:`Result.jumped <ngwear.results.result.Result>`).  N is bounded as :mod:`ngwear.runs.jumps` derives, by the
block's end (the programme's last stop is always simulated), by the layer left (``"layer"``: w ≤ g) and by
``wear.limit``.  A resumed run replays its stops through the jumps' account, so it goes on as if it had never stopped.
"""
from __future__ import annotations

import math

import numpy as np

from ..model.programme import Schedule
from .jumps import CycleJumps, rigid_modes
from .step import Target

DWELL_STEPS = 64
"""Most backward-Euler steps of the heat over a dwell (steps of the stop's d/m; longer ones over a longer dwell)."""


class StopClock:
    """Where the next step of a programme's run ends, and what it solves: a stop's step or the crossing to the next.

    The clock interface of :class:`~ngwear.runs.clock.Clock` (uniform steps: ``judge`` accepts every step).
    ``surface``: a run's geometry updates (:class:`~ngwear.runs.surface.Surface`), whose next update bounds a jump.
    """

    adaptive = False
    """A programme's steps are its stops' grids (``time.adaptive`` is refused with a programme)."""

    def __init__(self, scene, result, surface=None):
        self.schedule, self.result, self.surface = Schedule.of(scene.programme), result, surface
        self.m, self.gap, self.limit = scene.programme.steps_per_stop, scene.contact.gap, scene.wear.limit
        self.rejected, self.unmet, self.next_step = 0, False, 0.0
        self.jumps = CycleJumps(scene.programme.jump_tolerance) if scene.programme.jump else None
        plate = scene.loads.plate
        self.modes = rigid_modes(result.contact_points, scene.contact.direction, plate is not None,
                                 plate is not None and plate.tilt)
        self.aim: tuple[int, int] | None = None         # (stop, step) of the step being solved
        self.added = 0                                  # the stops a jump adds on the crossing being solved
        self._replay()

    # ---- where the run is ------------------------------------------------------------------
    def _replay(self) -> None:
        """The position after the recorded rows, and the jumps' account of the simulated stops so far."""
        result, m = self.result, self.m
        rows = len(result.times)
        stops, steps = self.schedule.rows(result.jumped)
        self.stop, self.step = (int(stops[rows - 1]), int(steps[rows - 1])) if rows else (0, 0)   # step 0: first
        if self.jumps is None:
            return
        jumped = set(result.jumped.tolist())
        for end in self.schedule.ends(rows - 1):      # the last stop's jump is decided when the run goes on
            stop = int(stops[end])
            increment = result.total_wear_at(end) - result.total_wear_at(end - m)
            self.jumps.simulated(stop, int(self.schedule.block[stop]), increment)
            if stop + 1 in jumped:
                self.jumps.jumped()

    def done(self, state, contact) -> bool:
        """Whether the programme is done: its last stop (simulated, or jumped over) and its last dwell, if any."""
        if self.step > self.m:
            return True
        return self.step == self.m and self._following(contact) >= self.schedule.count and not self.schedule.cools

    def _following(self, contact) -> int:
        """The next stop to simulate after the current one (its end reached), once the jump is decided."""
        if self.aim is None or self.aim[0] <= self.stop:
            n = self._jump_length(contact)
            self.aim, self.added = (self.stop + 1 + n, 0), n
        return self.aim[0]

    def target(self, state, contact, integrator) -> Target:
        """The next step: the stop's next grid point, or the crossing to the start of the next simulated stop.

        A crossing slides nothing and wears nothing but a jump's N Δw; its heat steps cover the dwell before the stop
        it reaches, in steps of that block's d/m (at most :data:`DWELL_STEPS`); with a jump of N stops one dwell, and
        the heat then takes the N cycles (stop and dwell) as the jump does the wear
        (:meth:`~ngwear.runs.heating.Heating.after`).
        """
        s, t = self.schedule, state.instant.t
        if self.step < self.m:
            stop, step = self.aim = (self.stop, self.step + 1)
            instant = contact.motion.at(float(s.start[stop] + s.local(stop)[step]), self.aim)
            local = s.local(stop)
            before = contact.alpha(state.coefficients, contact.motion.at(t, (stop, step - 1)).speed)
            wear = integrator.step(state.wear, state.pressure, before,
                                   contact.alpha(state.coefficients, instant.speed), local[step] - local[step - 1])
            return Target(instant, wear, heat_steps=(instant.t - t,))
        stop = self._following(contact)
        if stop >= s.count:                             # the last dwell, to the programme's end
            self.aim = (s.count - 1, self.m + 1)
            instant = contact.motion.at(s.end, self.aim)
            return Target(instant, integrator.rest(state.wear), still=True,
                          heat_steps=self._dwell_steps(instant.t - t, s.count - 1), unloaded=True)
        instant = contact.motion.at(float(s.start[stop]), (stop, 0))
        start = state.wear + self.added * self._increment() if self.added else state.wear
        before = stop - 1                               # the dwell before the stop it reaches
        length = float(s.dwell[before]) if self.added else instant.t - t
        return Target(instant, integrator.rest(start), still=True, jumped=int(self.added),
                      heat_steps=self._dwell_steps(length, before))

    def _dwell_steps(self, length: float, stop: int) -> tuple[float, ...]:
        """The heat's steps over a dwell of ``length`` after ``stop``: of that stop's d/m, at most :data:`DWELL_STEPS`."""
        if length <= 0:
            return ()
        count = min(math.ceil(length * self.m / self.schedule.duration[stop]), DWELL_STEPS)
        return (length / count,) * count

    def judge(self, times, rates) -> bool:
        """Every step is accepted (a stop's steps are uniform); the run is now at the step solved."""
        stop, step = self.aim
        if step == 0 and self.added:
            self.result.jumped = np.concatenate([self.result.jumped, np.arange(self.stop + 1, stop)])
        if step == 0 and self.jumps is not None and self.added:
            self.jumps.jumped()
        self.stop, self.step = stop, step
        return True

    def shrink(self) -> bool:
        return False

    def replay(self, times, rates) -> None:
        """Nothing to replay: the position and the jumps' account come from the rows (see :meth:`_replay`)."""

    # ---- cycle jumps -------------------------------------------------------------------------
    def _increment(self) -> np.ndarray:
        """Δw of the last simulated stop: the total wear at its end minus at its start."""
        result = self.result
        return result.total_wear_at(-1) - result.total_wear_at(result.steps - self.m)

    def _jump_length(self, contact) -> int:
        """N, the stops after the current one applied at once (0: simulate the next)."""
        if self.jumps is None:
            return 0
        s, stop = self.schedule, self.stop
        self.jumps.simulated(stop, int(s.block[stop]), self._increment())
        result, law, coefficients = self.result, contact.wear_law, contact.coefficients
        sliding = law.sliding(s.factors(stop)[0], s.local(stop), contact.motion.speed)
        rate = law.slope(law.alpha(coefficients.wear, coefficients.friction, sliding), contact.law, self.gap)
        wear = result.wear[-1]
        room = [self.gap - wear] if self.surface is None else []                  # "layer": within the layer
        if self.limit is not None:
            room.append(result.remaining_thickness_of(result.total_wear_at(-1)) - self.limit)
        last = s.last_of_block(stop)
        left = last - stop - (last == s.count - 1)      # the programme's last stop is simulated: its state recorded
        return self.jumps.length(left, rate, self.modes, result.weights,
                                 to_update=math.inf if self.surface is None else self.surface.threshold - wear,
                                 to_limit=np.min(room, axis=0) if room else math.inf)
