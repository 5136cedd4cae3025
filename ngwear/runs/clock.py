"""Time steps: uniform, or chosen by an estimate of the wear's local error.

Uniform: t_j = j T/N (the paper's grid).  Adaptive (``time.adaptive``): the wear rates r_j = α_j p_j at
the contact points give the local error of a step k = t_{j+1} − t_j without a second solve:

* the first-order integrators (explicit, implicit): e_i = ±k/2 (r_{j+1} − r_j)_i, their difference to the
  trapezoidal rule on the same rates (≈ ±k²/2 r'_i);
* trapezoidal: e = k³/12 ‖r''‖∞, r'' from the divided differences of the last three rates (on the
  first step, the first-order estimate).

Trapezoidal: a step is accepted when e ≤ k ε, ε = tolerance · g / T (errors per unit time, adding up to at
most tolerance · g at T).  First order: the local errors of a point add up with their signs (for w' = r(t)
the sum of k/2 Δr telescopes to k/2 (r(T) − r(0)) at constant k), and a point's wear changes for part of the
run only (a wear front passes), so a bound per unit time on the largest local error over the points spends a
third of the tolerance on the paper's scene.  Instead each point keeps its own account: E_i, the signed sum
of its local errors so far, and B_i = tolerance · g − |E_i| what is left; a step is accepted when
|e_i| ≤ k B_i / (T − t_j) at every point (what is left, spread over the time left).  Then |E_i| < tolerance · g
at every point and time.  Otherwise the step is redone with a smaller k.  The next step is
k · min(4, max(0.2, 0.9 (allowed / e)^(1/q))) (q the order), kept within [min_step, max_step] and
below the wear update's stability limit (:func:`ngwear.numerics.wear.stable_step`), and shortened
(or stretched by up to a fifth, unless it is being redone) to end exactly on the output times and on
the breakpoints of the load and speed tables, so that the frames do not depend on the steps.
"""
from __future__ import annotations

import numpy as np

from ..model.scene import SceneError
from ..numerics.wear import stable_step
from .step import Target

GROWTH, SHRINK, SAFETY = 4.0, 0.2, 0.9


class Clock:
    """Where the next step ends, and whether the step just solved is accurate enough (adaptive)."""

    def __init__(self, scene, largest_rate: float, rejected: int = 0, step: float | None = None):
        """``rejected`` and ``step`` (the next step) of a run that resumes; None: the scene's first step."""
        t = scene.time
        self.T, self.uniform, self.adaptive = t.T, t.T / t.steps, t.adaptive
        self.steps = t.steps
        self.unmet = False               # a step at min_step missed the tolerance (the run warns once)
        self.rejected = rejected         # steps redone smaller (so far, when a run is resumed)
        self.retrying = False            # the step about to be redone smaller
        if not self.adaptive:
            return
        self.floor, limit = t.min_step, stable_step(scene, largest_rate)
        self.ceiling = min(t.max_step, limit)
        if self.ceiling < self.floor:
            raise SceneError(f"time.min_step: {self.floor:g} is above the {scene.wear.integrator} update's stability "
                             f"limit {limit:.3g}; use wear.integrator = 'implicit' or a smaller time.min_step")
        self.step = float(np.clip(self.uniform, self.floor, self.ceiling)) if step is None else step
        self.order = 2 if scene.wear.integrator == "trapezoidal" else 1
        self.budget = t.tolerance * scene.contact.gap
        self.per_time = self.budget / t.T
        self.spent = 0.0                 # first order: E_i, the signed sum of each point's local errors so far
        out = scene.output
        frames = out.times if out.times is not None else np.arange(0.0, t.T, out.every)
        tables = [time for table in (scene.loads.time_table, scene.foundation.speed_table) for time, _ in table]
        self.marks = np.unique([m for m in (*frames, *tables, t.T) if 0 < m <= t.T])

    @property
    def next_step(self) -> float:
        """The step the clock proposes next (the uniform k without adaptivity): what a checkpoint keeps."""
        return self.step if self.adaptive else self.uniform

    def done(self, state, contact=None) -> bool:
        """Whether the run's last step has reached T (adaptive) or its N steps (uniform)."""
        return state.instant.t >= self.T if self.adaptive else state.steps >= self.steps

    def next_time(self, j: int, t: float) -> float:
        """The end of the step after t_j: (j + 1) T/N, or t + k cut to land on the next mark."""
        if not self.adaptive:
            return (j + 1) * self.uniform
        mark = self.marks[np.searchsorted(self.marks, t, side="right")]
        end = t + self.step
        # a step redone smaller is not stretched back, nor any step past the ceiling (the stability limit)
        stretch = 0.0 if self.retrying else min(0.2 * self.step, self.ceiling - self.step)
        return mark if end >= mark - stretch else end

    def target(self, state, contact, integrator) -> Target:
        """The step after the state's: its end t_{j+1} (:meth:`next_time`), instant and wear law.

        The wear law from w_j, p_j and the rates α at both ends, with the coefficients the step is solved with.
        """
        t = state.instant.t
        instant = contact.motion.at(self.next_time(state.steps, t))
        alpha = contact.alpha(state.coefficients, state.instant.speed)
        wear = integrator.step(state.wear, state.pressure, alpha, contact.alpha(state.coefficients, instant.speed),
                               instant.t - t)
        return Target(instant, wear, heat_steps=(instant.t - t,))

    def judge(self, times: list[float], rates: list[np.ndarray]) -> bool:
        """Accept the step to ``times[-1]`` from the rates at the last (up to three) times; set the next step."""
        if not self.adaptive:
            return True
        k = times[-1] - times[-2]
        signed, order = self.local_error(times, rates)
        allowed = k * (self.budget - np.abs(self.spent)) / max(self.T - times[-2], k)
        ratio = float(np.max(np.abs(signed) / allowed, initial=0.0))
        factor = GROWTH if ratio == 0 else min(GROWTH, max(SHRINK, SAFETY * ratio ** (-1 / order)))
        floored = k <= self.floor * (1 + 1e-12)
        accept = ratio <= 1 or floored
        if accept:
            self.spent = self.spent + signed
        self.unmet |= ratio > 1 and floored
        self.rejected += not accept
        self.retrying = not accept
        self.step = float(np.clip(k * factor, self.floor, self.ceiling))
        return accept

    def local_error(self, times, rates) -> tuple[np.ndarray, int]:
        """The signed local errors of the step to ``times[-1]`` at the points, and the order of the estimate."""
        k = times[-1] - times[-2]
        if self.order == 2 and len(rates) == 3:
            h = times[-2] - times[-3]
            return k ** 3 / 6 * ((rates[2] - rates[1]) / k - (rates[1] - rates[0]) / h) / (k + h), 2
        return k / 2 * (rates[-1] - rates[-2]), 1          # first order (and the trapezoidal rule's first step)

    def replay(self, times: np.ndarray, rates: list[np.ndarray]) -> None:
        """The accounts E_i of the steps kept by a run that resumes (as :meth:`judge` made them)."""
        if self.adaptive:
            for j in range(1, len(times)):
                self.spent = self.spent + self.local_error(times[max(j - 2, 0):j + 1], rates[max(j - 2, 0):j + 1])[0]

    def shrink(self) -> bool:
        """After a failed solve: a quarter of the step, if the floor allows (adaptive only)."""
        if not self.adaptive or self.step <= self.floor * (1 + 1e-12):
            return False
        self.step = max(self.step / 4, self.floor)
        return True
