"""The checks of each step as it is recorded: the scheme's invariants, and ``wear.limit``.

:class:`StepCheck` holds the invariants of :mod:`ngwear.results.invariants` at the new row after the last one, O(n);
the first step that breaks one stops the run (status naming the step, the invariant and by how much), keeping the
steps before it.  :func:`worn_out` ends a run whose remaining thickness reached ``wear.limit`` (status ``worn_out``,
a warning line saying when, where and in which stop).  Whether a step stays where the model is valid is
:mod:`ngwear.runs.validity`'s.
"""
from __future__ import annotations

import numpy as np

from ..model.programme import Schedule
from ..results.invariants import Checker, Row

WORN_OUT = "worn_out"
"""The status of a run ended by ``wear.limit``."""


class StepCheck:
    """The invariants of each step as it is recorded (the time loop): the new row after the last one, O(n).

    It carries the last row and the running maximum of (z)₊ (read from the rows kept when a run resumes, or when a
    geometry update replaces the discretization).
    """

    def __init__(self, result, disc):
        self.checker = checker = Checker(result.scene, disc)
        self.last = None
        if len(result.times):
            peak = np.maximum(result.normal_displacement - checker.d0, 0).max(axis=0)
            self.last = Row(result.times[-1], result.wear[-1], result.pressure[-1],
                            checker.speeds(result.speed_factor[-1]), peak)

    def __call__(self, state) -> tuple[str, float] | None:
        """The worst broken invariant of the state's step (None: all hold, and the step becomes the last)."""
        checker, instant, c = self.checker, state.instant, state.coefficients
        w, s, p = state.wear, state.normal, state.pressure
        broken = checker.broken(checker.violations(np.array([instant.t]), w[None, :], s[None, :], p[None, :],
                                                   state.lam[None, :], [instant.speed], [instant.load], self.last,
                                                   halves=False, kappa=c.wear[None, :], friction=c.friction[None, :]))
        if broken is None:
            peak = np.maximum(s - checker.disc.condensation.d0, 0)
            self.last = Row(instant.t, w, p, checker.speeds(instant.speed),
                            peak if self.last is None else np.maximum(self.last.peak, peak))
        return broken

    def cross(self, t: float, w: np.ndarray) -> None:
        """The next step crosses a programme's dwell to t: from the wear ``w`` (a jump's added), no wear across it."""
        self.last = Row(t, w, np.zeros_like(w), np.zeros_like(w), self.last.peak)

    def allowed(self, name: str) -> float:
        """The allowance of the invariant ``name``."""
        return self.checker.allowed[name]


def worn_out(result) -> bool:
    """End the run (status ``worn_out``, a warning line) if its last row's remaining thickness reached ``wear.limit``."""
    limit = result.scene.wear.limit
    if limit is None or not len(result.times):
        return False
    remaining = result.remaining_thickness_of(result.total_wear_at(-1))
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
