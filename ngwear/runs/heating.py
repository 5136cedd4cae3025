"""Heat in the time loop: the coefficients of state before each step, the frictional heat after it.

One :class:`Heating` per run, made when the scene has a temperature (``heat.model = "conduction"``) or a contact
coefficient of the state (T, p, v); with neither, :meth:`Heating.of` is None and the loop is the paper's, bit for
bit.  The coupling is explicit (docs/guide/heat.md): the step at t_{j+1}

1. reads μ, κ at the state of step j, μ_{j+1}(x_i) = μ(x_i, T_j, p_j, ‖v*(x_i, t_j)‖) into the run's state
   (:meth:`Heating.before`; a value out of range stops the run with one line), and the thermal load of T_j,
   f_th = G (T_j − T₀), as a right-hand side (:func:`~ngwear.numerics.systems.expand`);
2. is solved as the paper's step with these fixed fields;
3. heats the body by one backward-Euler step of Δt = t_{j+1} − t_j with the frictional power of its solution,
   q_i = μ_{j+1,i} p_{j+1,i} ‖v*(x_i, t_{j+1})‖ (:class:`~ngwear.numerics.heat.Heat`), the counterface with it.

Step 0 (t = 0) heats nothing: its temperature is T₀.  A programme's crossing of a dwell
(:class:`~ngwear.runs.stop_clock.StopClock`) slides nothing: backward-Euler steps of the stop's length over the dwell
with q = 0, the body and the counterface cool (an adiabatic body keeps its heat), and its row's ``heat_flux`` is 0,
the power over the step, so that Σ Δt ``heat_flux`` is the heat supplied.  The stops a cycle jump applies change the
heat's state as they change the wear: N cycles of the last simulated stop (:meth:`Heating._jump`).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..model.coefficients import at_points
from ..numerics.expansion import ThermalLoad
from ..numerics.heat import CONDUCTANCE, Heat, frictional_power
from ..results.units import suffix
from .temperature_limits import CHECKPOINT as LIMITS
from .temperature_limits import Limits

REFERENCE = "heat_friction_reference"
"""A checkpoint's key of the reference μ."""
DRIFT = 0.1
"""Largest change of a μ of the state, relative to its largest value, within which the dense Newton matrices of the
reference μ are kept (:attr:`~ngwear.runs.step.State.reference`)."""
UNDERSHOOT = "heat.scheme:"
"""What the warning of an undershoot starts with."""
STARTED = "heat_started_"
"""The prefix of a checkpoint's keys of the heat's state at the last simulated stop's start (a programme's)."""


class Heating:
    """The temperature of a run's body and counterface, and the contact coefficients of state, step by step.

    Parameters
    ----------
    scene : Scene
    disc : Discretization
        Its mesh, contact points, displacement space and :class:`~ngwear.numerics.contact.Contact`.

    Attributes
    ----------
    heat : Heat or None
        The temperature (None with ``heat.model = "none"``: only coefficients of p, v).
    load : ThermalLoad or None
        f_th = G (T − T₀); None when no region expands.
    started : dict or None
        A programme's: the heat's state at the last simulated stop's start (a cycle jump repeats that cycle).
    """

    def __init__(self, scene, disc):
        self.scene, self.contact = scene, disc.contact
        self.heat = Heat(scene, disc.mesh, disc.points) if scene.heat.model == "conduction" else None
        self.programme = scene.programme is not None
        self.started: dict | None = None
        self.limits = None if self.heat is None else Limits.of(scene, disc.mesh)
        load = None if self.heat is None else ThermalLoad(scene, disc.fes, self.heat.space)
        self.load = load if load is not None and load.matrix is not None else None

    @classmethod
    def of(cls, scene, disc, saved: dict | None = None) -> Heating | None:
        """The heating of a run, or None when the scene has neither a temperature nor a coefficient of state.

        ``saved``: a checkpoint's :attr:`state` to go on from.
        """
        if scene.heat.model == "none" and not disc.contact.stateful:
            return None
        heating = cls(scene, disc)
        if saved and heating.heat is not None:
            heating.heat.restore({k: saved[f"heat_{k}"] for k in ("temperature", "heat", "counterface")})
        if saved and heating.limits is not None:
            heating.limits.seen = np.array(saved[LIMITS], dtype=float)
        if saved and f"{STARTED}temperature" in saved:
            heating.started = {k: np.asarray(saved[f"{STARTED}{k}"], dtype=float) for k in heating.heat.state}
        return heating

    @staticmethod
    def reference(scene, contact, saved: dict | None = None):
        """The reference μ a run starts from: the checkpoint's, or the initial μ of a μ of the state (else None)."""
        if saved and REFERENCE in saved:
            return np.asarray(saved[REFERENCE], dtype=float)
        return contact.coefficients.friction if "friction" in contact.stateful else None

    def moved(self, disc) -> None:
        """After a geometry update (``wear.geometry = "surface"``): go on on ``disc``, the moved body's discretization.

        Its contact (the coefficients of state are read from the last step's state before each step: nothing to
        carry), the temperature carried node by node onto the moved mesh with its matrices rebuilt
        (:meth:`~ngwear.numerics.heat.Heat.moved`), and the thermal load's G assembled there.
        """
        self.contact = disc.contact
        if self.heat is not None:
            self.heat.moved(disc.mesh, disc.points)
            if self.load is not None:
                self.load = ThermalLoad(self.scene, disc.fes, self.heat.space)

    def before(self, state, caches):
        """Before the step after the state's: its coefficients at the state (T, p, ‖v*‖), h_c too, the load of T.

        Returns the state with the coefficients and the reference μ the step is solved with (f_th goes into
        ``caches``); a coefficient out of range raises its SceneError (one line naming the key, the point, the state
        there and t).
        """
        contact, heat = self.contact, self.heat
        values = {"p": state.pressure, "v": contact.motion.speeds(state.instant.speed)}
        if heat is not None:
            values["T"] = heat.surface_temperature()
            if heat.conductance_of_state:                   # h_c of the last step's state, as μ and κ are
                heat.conductance = at_points(self.scene.heat.contact_conductance, CONDUCTANCE, contact.coords, values,
                                             state.instant.t)
        if contact.stateful:
            coefficients = state.coefficients.updated(self.scene.contact, contact.coords, values, state.instant.t)
            friction, reference = coefficients.friction, state.reference
            if reference is not None and \
                    np.abs(friction - reference).max() > DRIFT * np.abs(reference).max(initial=0.0):
                reference = friction
            state = replace(state, coefficients=coefficients, reference=reference)
        if self.load is not None:
            caches.expand(self.load(self.heat.temperature))
        return state

    def after(self, state, target) -> dict[str, np.ndarray]:
        """Heat the body over the step just solved (``state``'s): backward-Euler steps of ``target.heat_steps``.

        One step (a dwell's: several); none at step 0: no heating, T = T₀, the flux is the power at t all the same.
        ``target.still``: the step slid nothing (a programme's dwell), q = 0 over it.  ``target.jumped``: the stops a
        cycle jump applied on this crossing (:meth:`_jump`).  Returns the step's rows.
        """
        now, steps = state.coefficients, target.heat_steps
        rows = {"step_friction": now.friction, "step_wear_coefficient": now.wear} if self.contact.stateful else {}
        if self.heat is None:
            return rows
        speeds = self.contact.motion.speeds(state.instant.speed)
        q = np.zeros_like(state.pressure) if target.still else frictional_power(now.friction, state.pressure, speeds)
        heat = self.heat
        touching = None if target.still else state.pressure + state.lam > 0
        for dt in steps:
            heat.advance(dt, q, touching)
        if not steps:
            heat.power = float(heat.weights @ q)
        if self.limits is not None and steps:
            self.limits.check(state.steps, state.instant.t, heat.temperature, heat.foundation_temperature())
        if target.jumped:
            self._jump(target.jumped)
        if self.programme and (target.still or not steps):                     # a stop starts
            self.started = heat.state
        return {**rows, "surface_temperature": heat.surface_temperature(), "max_temperature": heat.max_temperature(),
                "foundation_temperature": heat.foundation_temperature(), "heat_flux": heat.heat_flux}

    def _jump(self, stops: int) -> None:
        """The heat of the N = ``stops`` stops a cycle jump applied: N cycles like the last simulated one.

        The cycle, from the last simulated stop's start to the start it leads to (its dwell cooled), changes the
        state — nodal T, the counterface's, the time and the heat supplied and convected — by Δ; the jump adds N Δ,
        an Euler step of N in stop time, as it adds N Δw to the wear (:mod:`ngwear.runs.jumps`): exact in a periodic
        state (Δ = 0) and while the stops heat the body by the same amount each, and the energy balance holds.
        """
        now = self.heat.state
        change = {key: now[key] - self.started[key] for key in now}
        change["heat"][1] = 0.0                                         # the power is the crossing's own (0)
        change["heat"][6:] = 0.0                                        # the coldest node: the simulated stops'
        self.heat.restore({key: now[key] + stops * change[key] for key in now})

    def report(self, result) -> None:
        """The consistent step's undershoot and the temperature limits passed, as warnings in ``result.warnings``.

        See :meth:`~ngwear.numerics.heat.Heat.undershoot` and :mod:`ngwear.runs.temperature_limits`; they replace a
        resumed run's first part's.
        """
        result.warnings[:] = [w for w in result.warnings if not w.startswith(UNDERSHOOT)
                              and not w.split(" = ")[0].endswith(".max_temperature")]
        if self.limits is not None:
            result.warnings.extend(self.limits.warnings(self.scene, result.times))
        fell = None if self.heat is None else self.heat.undershoot()
        if fell is not None:
            (coldest, when), degrees, seconds = fell, suffix(self.scene, "temperature"), suffix(self.scene, "time")
            result.warnings.append(
                f"{UNDERSHOOT} the temperature fell to {coldest:.4g}{degrees} at t = {when:.4g}{seconds}, "
                f"{self.heat.floor - coldest:.3g}{degrees} below the {self.heat.floor:g}{degrees} it started from (the "
                "consistent step, where a step is short against h²/κ at the face); refine the face "
                "(mesh.contact_maxh), or take heat.scheme = 'bounded', which keeps every temperature above it")

    def state(self, reference) -> dict[str, np.ndarray]:
        """What a checkpoint keeps to go on bit for bit.

        The temperature's state (the coefficients come from it), and the reference μ of the Newton matrices
        (``reference``, the run state's).
        """
        state = {} if self.heat is None else {f"heat_{k}": v for k, v in self.heat.state.items()}
        if self.limits is not None:
            state[LIMITS] = self.limits.seen.copy()
        if self.started is not None:
            state.update({f"{STARTED}{k}": v for k, v in self.started.items()})
        if reference is not None:
            state[REFERENCE] = reference
        return state
