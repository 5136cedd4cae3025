"""The run's controls, each key declared once: ``[time]``, ``[wear]``, ``[solver]`` and ``[output]``.

The scene's other tables are in :mod:`ngwear.model.sections`, whose ``SECTIONS`` lists them all.
"""
from __future__ import annotations

from typing import Literal

from .keys import Flag, Level, Number, Section, Whole, key


class TimeGrid(Section):
    """Time steps: uniform, t_j = j T / steps, or chosen by an error controller (``adaptive``)."""

    T: Number = key(1.0, "final time (set by a `[programme]`: its end)", reuse=Level.NOTHING, gt=0)
    steps: Whole = key(100, "number of steps N (k = T/N); with `time.adaptive` the first step is T/N (set by a "
                       "`[programme]`: its stops' steps)",
                       reuse=Level.NOTHING, ge=1, le=1_000_000)
    adaptive: Flag = key(False, "choose the steps by an error estimate of the wear (see `time.tolerance`)",
                         reuse=Level.NOTHING)
    tolerance: Number = key(1e-3, "`adaptive`: the wear error to meet at T, relative to g", reuse=Level.NOTHING,
                            gt=0, le=0.5)
    min_step: Number | None = key(None, "`adaptive`: smallest step", reuse=Level.NOTHING, shown="T·1e-8",
                                  allowed="(0, max_step]")
    max_step: Number | None = key(None, "`adaptive`: largest step", reuse=Level.NOTHING, shown="T/10",
                                  allowed="(0, T]")


class WearSpec(Section):
    """Wear integrator: the paper's ``explicit`` (eq. 15), ``implicit`` (backward Euler), ``trapezoidal``."""

    integrator: Literal["explicit", "implicit", "trapezoidal"] | None = key(
        None, "`explicit` (paper eq. 15), `implicit` (backward Euler), `trapezoidal`", reuse=Level.NOTHING,
        shown="explicit; trapezoidal with `time.adaptive`", allowed="explicit, implicit, trapezoidal")
    allow_unstable: Flag = key(False, "run an explicit update known to diverge (k·α·L > 2 at the uniform step, α "
                               "the largest κ‖v*‖, L the largest slope of p on [0, g]) instead of refusing it",
                               reuse=Level.NOTHING)
    geometry: Literal["layer", "surface"] = key(
        "layer", "`layer`: the paper's model, the wear removes the soft layer of a body whose shape never changes; "
        "`surface`: the worn material leaves the body, its contact surface recedes along ν (the layer keeps its "
        "thickness g)", reuse=Level.NOTHING)
    update: Number = key(0.25, "`surface`: the wear since the last geometry update, relative to the height of the "
                         "smallest element at Γ_C (or to `contact.gap` if smaller), that moves the surface (at most "
                         "half: the layer never wears through between updates)", reuse=Level.NOTHING, gt=0, le=0.5)
    limit: Number | None = key(None, "the smallest remaining thickness of the worn region (along ν, e.g. a pad's "
                               "2 mm): reaching it ends the run as worn out", reuse=Level.NOTHING, shown="none",
                               allowed="> 0", gt=0)


class SolverSpec(Section):
    """Nonlinear solver: ``condensed`` onto the contact points (fast) or ``full`` system (reference)."""

    method: Literal["condensed", "full"] = key(
        "condensed", "`condensed` (fast) or `full` (straightforward full-system Newton, reference; explicit wear "
        "only)", reuse=Level.NOTHING)
    tolerance: Number = key(1e-10, "Newton stopping rule: relative merit", reuse=Level.NOTHING, ge=1e-15, le=1e-2)
    max_iterations: Whole = key(50, "Newton iterations per step", reuse=Level.NOTHING, ge=1, le=10_000)


class Output(Section):
    """When full fields are written and rendered (by time, whatever the steps), and checkpoints."""

    every: Number | None = key(None, "time between the frames whose full fields are written and rendered "
                               "(from t = 0, plus the last step)", reuse=Level.NOTHING, shown="T/4",
                               allowed="(0, T]")
    times: tuple[Number, ...] | None = key(None, "the frames' times (then `output.every` is not used)",
                                           reuse=Level.NOTHING, shown="—", allowed="in [0, T], increasing")
    checkpoint_seconds: Number = key(60.0, "wall time between checkpoints of a run with an output folder "
                                     "(0: none)", reuse=Level.NOTHING, ge=0)
    max_frames: Whole = key(10_000, "most frames a run may write (each a full field, kept in memory and written as a "
                            "VTU file): a scene whose `output.every` or `output.times` gives more is refused before "
                            "the run", reuse=Level.NOTHING, ge=1, le=1_000_000)
