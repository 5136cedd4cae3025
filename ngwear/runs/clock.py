"""Time steps: uniform, or chosen by an estimate of the wear's local error.

Uniform: t_j = j T/N (the paper's grid).  Adaptive (``time.adaptive``): the wear rates r_j = α_j p_j at
the contact points give the local error of a step k = t_{j+1} − t_j without a second solve:

* the first-order integrators (explicit, implicit): e = k/2 ‖r_{j+1} − r_j‖∞, their difference to the
  trapezoidal rule on the same rates (≈ k²/2 |r'|);
* trapezoidal: e = k³/12 ‖r''‖∞, r'' from the divided differences of the last three rates (on the
  first step, the first-order estimate).

A step is accepted when e ≤ k ε, ε = tolerance · g / T: errors per unit time, so that the steps'
errors add up to at most tolerance · g at T; otherwise it is redone with a smaller k.  The next step
is k · min(4, max(0.2, 0.9 (k ε / e)^(1/q))) (q the order), kept within [min_step, max_step] and
below the wear update's stability limit (:func:`ngwear.numerics.wear.stable_step`), and shortened
(or stretched by up to a fifth, unless it is being redone) to end exactly on the output times and on
the breakpoints of the load and speed tables, so that the frames do not depend on the steps.
"""
from __future__ import annotations

import numpy as np

from ..model.scene import SceneError
from ..numerics.wear import stable_step

GROWTH, SHRINK, SAFETY = 4.0, 0.2, 0.9


class Clock:
    """Where the next step ends, and whether the step just solved is accurate enough (adaptive)."""

    def __init__(self, scene, largest_alpha: float, rejected: int = 0):
        t = scene.time
        self.T, self.uniform, self.adaptive = t.T, t.T / t.steps, t.adaptive
        self.steps = t.steps
        self.unmet = False               # a step at min_step missed the tolerance (the run warns once)
        self.rejected = rejected         # steps redone smaller (so far, when a run is resumed)
        self.retrying = False            # the step about to be redone smaller
        if not self.adaptive:
            return
        self.floor, limit = t.min_step, stable_step(scene, largest_alpha)
        self.ceiling = min(t.max_step, limit)
        if self.ceiling < self.floor:
            raise SceneError(f"time.min_step: {self.floor:g} is above the {scene.wear.integrator} update's stability "
                             f"limit {limit:.3g}; use wear.integrator = 'implicit' or a smaller time.min_step")
        self.step = float(np.clip(self.uniform, self.floor, self.ceiling))
        self.order = 2 if scene.wear.integrator == "trapezoidal" else 1
        self.per_time = t.tolerance * scene.contact.gap / t.T
        out = scene.output
        frames = out.times if out.times is not None else np.arange(0.0, t.T, out.every)
        tables = [time for table in (scene.loads.time_table, scene.foundation.speed_table) for time, _ in table]
        self.marks = np.unique([m for m in (*frames, *tables, t.T) if 0 < m <= t.T])

    @property
    def next_step(self) -> float:
        """The step the clock proposes next (the uniform k without adaptivity): what a checkpoint keeps."""
        return self.step if self.adaptive else self.uniform

    def done(self, j: int, t: float) -> bool:
        """Whether the run has reached T (adaptive) or its N steps (uniform)."""
        return t >= self.T if self.adaptive else j >= self.steps

    def next_time(self, j: int, t: float) -> float:
        """The end of the step after t_j: (j + 1) T/N, or t + k cut to land on the next mark."""
        if not self.adaptive:
            return (j + 1) * self.uniform
        mark = self.marks[np.searchsorted(self.marks, t, side="right")]
        end = t + self.step
        # a step redone smaller is not stretched back, nor any step past the ceiling (the stability limit)
        stretch = 0.0 if self.retrying else min(0.2 * self.step, self.ceiling - self.step)
        return mark if end >= mark - stretch else end

    def judge(self, times: list[float], rates: list[np.ndarray]) -> bool:
        """Accept the step to ``times[-1]`` from the rates at the last (up to three) times; set the next step."""
        if not self.adaptive:
            return True
        k = times[-1] - times[-2]
        if self.order == 2 and len(rates) == 3:
            h = times[-2] - times[-3]
            curvature = 2 * ((rates[2] - rates[1]) / k - (rates[1] - rates[0]) / h) / (k + h)
            error = k ** 3 / 12 * np.abs(curvature).max(initial=0.0)
            order = 2
        else:
            error, order = k / 2 * np.abs(rates[-1] - rates[-2]).max(initial=0.0), 1
        allowed = k * self.per_time
        factor = GROWTH if error == 0 else min(GROWTH, max(SHRINK, SAFETY * (allowed / error) ** (1 / order)))
        floored = k <= self.floor * (1 + 1e-12)
        accept = error <= allowed or floored
        self.unmet |= error > allowed and floored
        self.rejected += not accept
        self.retrying = not accept
        self.step = float(np.clip(k * factor, self.floor, self.ceiling))
        return accept

    def shrink(self) -> bool:
        """After a failed solve: a quarter of the step, if the floor allows (adaptive only)."""
        if not self.adaptive or self.step <= self.floor * (1 + 1e-12):
            return False
        self.step = max(self.step / 4, self.floor)
        return True
