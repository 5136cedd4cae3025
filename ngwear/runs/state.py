"""A run's changing state in one object: what its next step reads and what its last step wrote.

The time loop (:mod:`ngwear.runs.simulate`) holds one :class:`State`; :func:`~ngwear.runs.step.advance` makes the
next one from it and a :class:`Target` (where the step ends and its wear law), and the loop's observers read it:
the recording and the checks, the heat (which sets the temperatures and the coefficients of the next step), the
geometry updates (which move the layer's wear into the body: the record keeps the total) and the checkpoints.
Everything else a run uses is either fixed for the run (the scene, the
:class:`~ngwear.numerics.discrete.Discretization`) or a cache (:class:`~ngwear.runs.step.StepCaches`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.coefficients import Coefficients
from ..model.motion import Instant
from ..numerics.solver import NewtonRecord
from ..numerics.wear import WearStep


@dataclass(frozen=True)
class Target:
    """Where the next step ends and what it solves: its instant and its wear law, from the clock.

    ``still``: the step slides nothing (a programme's crossing of a dwell: no wear, no frictional heat); ``jumped``:
    the stops a cycle jump applies on it; ``heat_steps``: the heat's backward-Euler steps over it.
    """

    instant: Instant
    wear: WearStep
    still: bool = False
    jumped: int = 0
    heat_steps: tuple[float, ...] = ()


@dataclass
class State:
    """The state after a run's last recorded step (before step 0: the unloaded body).

    Attributes
    ----------
    instant : Instant or None
        t, s_v and s_F of the last step (None before step 0).
    x, lam : ndarray
        The solver's unknowns (s and δ, or the free DOFs) and multipliers λ: the next step's warm start.
    normal, pressure, wear, plate, forces : ndarray
        s = ν·u, p, w (the layer's), δ and the contact forces of the last step.
    coefficients : Coefficients
        μ, κ, L at the points for the next step: fields of x, or of the last step's state (:mod:`ngwear.runs.heating`).
    reference : ndarray or None
        With μ of the state, the reference μ whose dense factors precondition the steps'.
    heat : Heat or None
        The body's and the counterface's temperatures (:class:`~ngwear.numerics.heat.Heat`).
    displacements : tuple
        (t, u) of a nonlinear body's last two steps (the bulk's warm start); ``displacement`` the last step's u where
        it is not recovered from the contact forces (a nonlinear body), else None.
    record : NewtonRecord or None
        The last step's.
    steps : int
        The index of the last recorded step (−1: none).
    """

    x: np.ndarray
    lam: np.ndarray
    coefficients: Coefficients
    wear: np.ndarray
    instant: Instant | None = None
    normal: np.ndarray | None = None
    pressure: np.ndarray | None = None
    plate: np.ndarray | None = None
    forces: np.ndarray | None = None
    reference: np.ndarray | None = None
    heat: object = None
    displacements: tuple = ()
    displacement: np.ndarray | None = None
    record: NewtonRecord | None = None
    steps: int = -1
