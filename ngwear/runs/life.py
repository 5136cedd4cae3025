"""A part's life in the time loop: a programme's stops one after the other, cycle jumps, and ``wear.limit``.

:class:`StopClock` stands where :class:`~ngwear.runs.clock.Clock` does when the scene has a ``[programme]``
(:mod:`ngwear.model.programme`).  Stop i records m + 1 rows: its start t_i, a solve with no wear step (as step 0 of
a run), then its m steps t_i + d j/m, each with the factors s_v, s_F of its place on the stop's grid (the contact's
:class:`~ngwear.model.programme.Drive`), k the differences of the stop's own grid: the stops of a block are one
problem.  Between two simulated stops one step crosses the dwell (and the jumped stops): no load and no sliding, so
no wear but what a jump adds; it ends at the next simulated stop's start, solved there with its factors.

After each simulated stop its wear increment Δw (end minus start) goes to :class:`~ngwear.runs.jumps.CycleJumps`
(``programme.jump``): a jump of N stops adds N Δw on that crossing step and the N stops are recorded as jumped
(:attr:`Result.jumped <ngwear.results.result.Result>`).  N is bounded as :mod:`ngwear.runs.jumps` derives, by the
block's end (the programme's last stop is always simulated), by the layer left (``"layer"``: w ≤ g) and by
``wear.limit``.  A resumed run replays its stops through the jumps' account, so it goes on as if it had never stopped.

:func:`worn_out` ends a run whose remaining thickness reached ``wear.limit`` (status ``worn_out``, a warning line
saying when, where and in which stop).
"""
from __future__ import annotations

import math

import ngsolve as ngs
import numpy as np

from ..model.programme import Schedule
from ..numerics.motion import Recession, contact_height
from ..numerics.topology import coordinates
from .jumps import CycleJumps, rigid_modes

WORN_OUT = "worn_out"
"""The status of a run ended by ``wear.limit``."""
DWELL_STEPS = 64
"""Most backward-Euler steps of the heat over a dwell (steps of the stop's d/m; longer ones over a longer dwell)."""


class StopClock:
    """Where the next step of a programme's run ends, and what it prepares: a stop's step or the crossing to the next.

    The clock interface of :class:`~ngwear.runs.clock.Clock` (uniform steps: ``judge`` accepts every step) and
    :meth:`prepare`, which sets the contact's drive and the wear law of the step.
    """

    def __init__(self, scene, contact, result, surface=None):
        self.schedule, self.contact, self.result = Schedule.of(scene.programme), contact, result
        self.surface = surface                          # "surface": the next update bounds a jump
        self.drive, self.m = contact.drive, scene.programme.steps_per_stop
        self.gap, self.limit = scene.contact.gap, scene.wear.limit
        self.rejected, self.unmet, self.retrying, self.next_step = 0, False, False, 0.0
        self.jumps = CycleJumps(scene.programme.jump_tolerance) if scene.programme.jump else None
        plate = scene.loads.plate
        self.modes = rigid_modes(result.contact_points, scene.contact.direction, plate is not None,
                                 plate is not None and plate.tilt)
        self.target: tuple[int, int] | None = None      # (stop, step) of the step being solved
        self.added = 0.0                                # the wear a jump adds on the crossing being solved
        self._replay()
        self.drive.at(self.stop, self.step)            # where the rows end (a resumed run's invariants read it)

    # ---- where the run is ------------------------------------------------------------------
    def _replay(self) -> None:
        """The position after the recorded rows, and the jumps' account of the simulated stops so far."""
        result, m = self.result, self.m
        rows = len(result.times)
        stops, steps = self.schedule.rows(result.jumped)
        self.stop, self.step = (int(stops[rows - 1]), int(steps[rows - 1])) if rows else (0, 0)   # step 0: _first
        if self.jumps is None:
            return
        jumped = set(result.jumped.tolist())
        for end in self.schedule.ends(rows - 1):      # the last stop's jump is decided when the run goes on
            stop = int(stops[end])
            increment = result.total_wear_at(end) - result.total_wear_at(end - m)
            self.jumps.simulated(stop, int(self.schedule.block[stop]), increment)
            if stop + 1 in jumped:
                self.jumps.jumped()

    def done(self, j: int, t: float) -> bool:
        """Whether the programme's last stop is done (simulated, or jumped over)."""
        return self.step == self.m and self._following() >= self.schedule.count

    def _following(self) -> int:
        """The next stop to simulate after the current one (its end reached), once the jump is decided."""
        if self.target is None or self.target[0] <= self.stop:
            n = self._jump_length()
            self.target, self.added = (self.stop + 1 + n, 0), n
        return self.target[0]

    def next_time(self, j: int, t: float) -> float:
        """The end of the next step: the stop's next grid point, or the start of the next simulated stop."""
        s = self.schedule
        if self.step < self.m:
            self.target = (self.stop, self.step + 1)
            return float(s.start[self.stop] + s.local(self.stop)[self.step + 1])
        return float(s.start[self._following()])

    def prepare(self, integrator, contact, check, w: np.ndarray, p: np.ndarray, t: float, t_next: float) -> None:
        """Set the drive at the step's end and prepare its wear law (none on a crossing, but a jump's N Δw).

        A crossing tells ``check`` (the run's invariants) that it wears nothing but the jump's.
        """
        stop, step = self.target
        if step == 0:                                   # the crossing: no sliding, no load, the jump's wear added
            still = np.zeros_like(w)
            start = w + self.added * self._increment() if self.added else w
            integrator.prepare(start, p, still, still, t_next - t)
            check.cross(t_next, start)
            self.drive.at(stop, 0)
            return
        local = self.schedule.local(stop)
        self.drive.at(stop, step - 1)
        before = contact.alpha(t)
        self.drive.at(stop, step)
        integrator.prepare(w, p, before, contact.alpha(t_next), local[step] - local[step - 1])

    @property
    def still(self) -> bool:
        """Whether the step being solved is a crossing: no sliding over it (no frictional heat)."""
        return self.target[1] == 0

    def heating(self, t: float, t_next: float) -> tuple[int, tuple[float, ...]]:
        """(The stops a cycle jump applied, the heat's backward-Euler steps) over the step just solved, t to t_next.

        A stop's step: itself.  A crossing: the dwell before the stop it reached, in steps of that block's d/m (at most
        :data:`DWELL_STEPS`); with a jump of N stops, one dwell, and the heat then takes the N cycles (stop and dwell)
        as the jump does the wear (:meth:`~ngwear.runs.heating.Heating.advance`).
        """
        if self.step:
            return 0, (t_next - t,)
        s, before = self.schedule, self.stop - 1
        length = float(s.dwell[before]) if self.added else t_next - t
        if length <= 0:
            return int(self.added), ()
        count = min(math.ceil(length * self.m / s.duration[before]), DWELL_STEPS)
        return int(self.added), (length / count,) * count

    def judge(self, times, rates) -> bool:
        """Every step is accepted (a stop's steps are uniform); the run is now at the step solved."""
        stop, step = self.target
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

    def _jump_length(self) -> int:
        """N, the stops after the current one applied at once (0: simulate the next)."""
        if self.jumps is None:
            return 0
        s, stop = self.schedule, self.stop
        self.jumps.simulated(stop, int(s.block[stop]), self._increment())
        result, contact = self.result, self.contact
        coefficients = contact.coefficients
        local, speed = s.local(stop), np.abs(s.factors(stop)[0])
        sliding = float(np.sum(np.diff(local) * 0.5 * (speed[1:] + speed[:-1]))) * contact.slip.speed
        rate = coefficients.wear * sliding * contact.law.slope(self.gap)
        wear = result.wear[-1]
        room = [self.gap - wear] if self.surface is None else []                  # "layer": within the layer
        if self.limit is not None:
            room.append(result.remaining_thickness_of(result.last_total_wear()) - self.limit)
        last = s.last_of_block(stop)
        left = last - stop - (last == s.count - 1)      # the programme's last stop is simulated: its state recorded
        return self.jumps.length(left, rate, self.modes, result.weights,
                                 to_update=math.inf if self.surface is None else self.surface.threshold - wear,
                                 to_limit=np.min(room, axis=0) if room else math.inf)


def worn_out(result) -> bool:
    """End the run (status ``worn_out``, a warning line) if its last row's remaining thickness reached ``wear.limit``."""
    limit = result.scene.wear.limit
    if limit is None or not len(result.times):
        return False
    remaining = result.remaining_thickness_of(result.last_total_wear())
    if remaining.min() > limit:
        return False
    i = int(np.argmin(remaining))
    place = ", ".join(f"{x:.4g}" for x in result.contact_points[i])
    where = ""
    if result.scene.programme is not None:
        stop = int(Schedule.of(result.scene.programme).rows(result.jumped)[0][result.steps])
        where = f" in stop {stop}"
    result.status = WORN_OUT
    result.warnings.append(f"wear.limit: the remaining thickness reached {limit:g} (min {remaining[i]:.4g}) at "
                           f"t = {result.times[-1]:.6g}{where}, at ({place})")
    return True


class Surface:
    """``wear.geometry = "surface"``: the body's contact face recedes by the wear; the discretization follows.

    After each recorded step: once the wear since the last update (the layer's w) reaches ``wear.update`` × h, h the
    height of the smallest element at Γ_C (:func:`~ngwear.numerics.motion.contact_height`) or the layer's g if
    smaller (at most half of it: a coarse mesh's layer never wears through between updates, where its wear would
    slow down towards g), the mesh of the regions
    that carry Γ_C moves by the accumulated wear along −ν (:class:`~ngwear.numerics.motion.Recession`: a vertex of
    Γ_C by the least wear of the points at it), the wear it realised at the points, W, leaves the layer (w −= W,
    w ≥ 0) and goes to ``Result.removed`` (``total_wear`` = w + ΣW), and the discretization is rebuilt on the moved
    mesh: everything a change of geometry invalidates (the space's element maps, K and its factorisation, the
    contact points' weights, d₀, the compliance, the loads, the plate), the contact's factors and the unmoved
    regions' stiffness blocks kept (:meth:`~ngwear.numerics.discrete.Discretization.moved`).  The step's row is
    rewritten with the new w (its pressure and displacements are those it was solved with: the update moves the
    wear from the layer into the geometry).  A move that would leave an element below the quality bound or inverted
    stops the run with :attr:`~ngwear.numerics.motion.Quality.reason` (the run keeps its steps).  A run's
    :class:`~ngwear.runs.heating.Heating` goes on on the moved body (:meth:`~ngwear.runs.heating.Heating.moved`: T
    carried node by node, the heat's matrices rebuilt).

    A checkpoint keeps :attr:`state` (X₀, W and the moved vertices, exact); a run resumed from it (``saved``, ``disc``
    on the moved mesh) rebuilds the extension on X₀ as the first update did, so it goes on to the bit.
    """

    def __init__(self, scene, disc, saved: dict | None = None):
        self.scene, self.disc = scene, disc
        self.recession = None                          # built on a copy of the mesh at the first update
        if saved:
            self.recession = Recession.resumed(disc.mesh, disc.points, disc.condensation.nu, self._held(),
                                               saved["surface_reference"], saved["surface_wear"])
        self.threshold = self._threshold(disc.mesh)

    def _held(self) -> tuple[str, ...]:
        """The boundaries held in place besides those not parallel to ν: the clamped ones and a plate's."""
        plate = self.scene.loads.plate
        return tuple(self.scene.geometry.dirichlet) + (() if plate is None else (plate.boundary,))

    @property
    def state(self) -> dict[str, np.ndarray]:
        """What a checkpoint keeps to go on across updates ({}: none yet).

        X₀, W at Γ_C's vertices, the vertices now and K's ordering (the first K's, which every update's factorisation
        takes: a resumed run takes it too).
        """
        if self.recession is None:
            return {}
        ordering = self.disc.elastic.factored_ordering
        return {"surface_reference": self.recession.extension.reference, "surface_wear": self.recession.wear,
                "surface_coordinates": coordinates(self.recession.mesh),
                **({} if ordering is None else {"surface_ordering": ordering})}

    def _threshold(self, mesh) -> float:
        """``wear.update`` × the smaller of h (the smallest element's height at Γ_C) and g: never through the layer."""
        return self.scene.wear.update * min(contact_height(mesh), self.scene.contact.gap)

    def due(self, wear: np.ndarray) -> bool:
        """Whether the wear since the last update reaches the threshold somewhere."""
        return float(wear.max(initial=0.0)) >= self.threshold

    def update(self, result, wear: np.ndarray):
        """Move the mesh by ``wear`` (the last row's); the new discretization, or None with the run stopped."""
        disc = self.disc
        if self.recession is None:
            mesh = ngs.Mesh(disc.mesh.ngmesh.Copy())          # the mesh as built may serve other runs
            self.recession = Recession(mesh, disc.points, disc.condensation.nu, self._held())
        coords, quality = self.recession.trial(wear)
        if not quality.acceptable:
            result.status = (f"step {result.steps} (t = {result.times[-1]:.4g}): wear.geometry = 'surface': "
                             f"{quality.reason}; the run stops there (a worn body is not remeshed within a run)")
            return None
        before = coordinates(self.recession.mesh)         # the mesh in force until now: frames may show it
        realised = self.recession.accept(coords, wear)
        drive = disc.contact.drive
        self.disc = disc.moved(self.recession.mesh, self.recession.extension.regions)
        if drive is not None:
            self.disc.contact.drive.at(drive.stop, drive.step)
        self.threshold = self._threshold(self.recession.mesh)
        result.moved(realised, self.disc, before)
        return self.disc

    def apply(self, result, clock):
        """The update after the last step (:meth:`update`) with what the loop solves on: a new Stepper, or None."""
        from ..numerics.problem import Problem
        from ..results.invariants import StepCheck
        from ..results.validity import Validity
        from .stepper import Stepper

        disc = self.update(result, result.wear[-1])
        if disc is None:
            return None
        if isinstance(clock, StopClock):
            clock.contact, clock.drive = disc.contact, disc.contact.drive
        stepper = Stepper(Problem(disc), StepCheck(result), Validity(result))
        if result.heating is not None:
            result.heating.moved(disc)
            stepper.heating = result.heating
        return stepper
