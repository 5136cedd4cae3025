"""Heat in the time loop: the coefficients of state before each step, the frictional heat after it.

One :class:`Heating` per run, made when the scene has a temperature (``heat.model = "conduction"``) or a contact
coefficient of the state (T, p, v); with neither, :meth:`Heating.of` is None and the loop is the paper's, bit for
bit.  The coupling is explicit (docs/guide/heat.md): the step at t_{j+1}

1. reads μ, κ at the state of step j, μ_{j+1}(x_i) = μ(x_i, T_j, p_j, ‖v*(x_i, t_j)‖)
   (:meth:`~ngwear.numerics.contact.Contact.update`; a value out of range stops the run with one line), and the
   thermal load of T_j, f_th = G (T_j − T₀), as a right-hand side (:meth:`~ngwear.numerics.problem.Problem.expand`);
2. is solved as the paper's step with these fixed fields;
3. heats the body by one backward-Euler step of Δt = t_{j+1} − t_j with the frictional power of its solution,
   q_i = μ_{j+1,i} p_{j+1,i} ‖v*(x_i, t_{j+1})‖ (:class:`~ngwear.numerics.heat.Heat`), the counterface with it.

Step 0 (t = 0) heats nothing: its temperature is T₀.  A programme's crossing of a dwell
(:class:`~ngwear.runs.life.StopClock`) slides nothing: backward-Euler steps of the stop's length over the dwell
with q = 0, the body and the counterface cool (an adiabatic body keeps its heat), and its row's ``heat_flux`` is 0,
the power over the step, so that Σ Δt ``heat_flux`` is the heat supplied.  The stops a cycle jump applies change the
heat's state as they change the wear: N cycles of the last simulated stop (:meth:`Heating._jump`).
"""
from __future__ import annotations

import numpy as np

from ..model.scene import SceneError
from ..numerics.expansion import ThermalLoad
from ..numerics.heat import Heat, frictional_power

REFERENCE = "heat_friction_reference"
"""A checkpoint's key of the reference μ."""
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
    """

    def __init__(self, scene, disc):
        self.scene, self.contact, self.disc = scene, disc.contact, disc
        self.contact.reset()
        self.heat = Heat(scene, disc.mesh, disc.points) if scene.heat.model == "conduction" else None
        self.programme = scene.programme is not None
        self.started: dict | None = None        # a programme's: the heat's state at the last simulated stop's start
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
        if saved and f"{STARTED}temperature" in saved:
            heating.started = {k: np.asarray(saved[f"{STARTED}{k}"], dtype=float) for k in heating.heat.state}
        if saved and REFERENCE in saved:
            heating.contact.reference = np.asarray(saved[REFERENCE], dtype=float)
        return heating

    def moved(self, disc) -> None:
        """After a geometry update (``wear.geometry = "surface"``): go on on ``disc``, the moved body's discretization.

        Its contact (the coefficients of state are read from the last step's state before each step: nothing to
        carry), the temperature carried node by node onto the moved mesh with its matrices rebuilt
        (:meth:`~ngwear.numerics.heat.Heat.moved`), and the thermal load's G assembled there.
        """
        self.contact, self.disc = disc.contact, disc
        if self.heat is not None:
            self.heat.moved(disc.mesh, disc.points)
            if self.load is not None:
                self.load = ThermalLoad(self.scene, disc.fes, self.heat.space)

    def prepare(self, stepper, t: float, pressure: np.ndarray) -> str | None:
        """Before the step after t: the coefficients at the state of t (p = ``pressure``), the thermal load of T(t).

        Returns the refusal of a coefficient out of range (one line), else None.
        """
        if self.contact.stateful:
            state = {"p": pressure, "v": self.contact.slip.speeds(t)}
            if self.heat is not None:
                state["T"] = self.heat.surface_temperature()
            try:
                self.contact.update(state, t)
            except SceneError as err:
                return str(err)
        if self.load is not None:
            stepper.expand(self.load(self.heat.temperature))
        return None

    def advance(self, steps: tuple[float, ...], t: float, pressure: np.ndarray, still: bool = False,
                jumped: int = 0) -> dict[str, np.ndarray]:
        """Heat the body over the step that ended at t with ``pressure``: backward-Euler steps of lengths ``steps``.

        One step (a dwell's: several, :meth:`~ngwear.runs.life.StopClock.heating`); none at step 0: no heating,
        T = T₀, the flux is the power at t all the same.  ``still``: the step slid nothing (a programme's dwell),
        q = 0 over it.  ``jumped``: the stops a cycle jump applied on this crossing (:meth:`_jump`).  Returns the
        step's rows.
        """
        now = self.contact.coefficients_at(t)
        rows = {"step_friction": now.friction, "step_wear_coefficient": now.wear} if self.contact.stateful else {}
        if self.heat is None:
            return rows
        q = np.zeros_like(pressure) if still else frictional_power(now.friction, pressure, self.contact.slip.speeds(t))
        heat = self.heat
        for dt in steps:
            heat.advance(dt, q)
        if not steps:
            heat.power = float(heat.weights @ q)
        if jumped:
            self._jump(jumped)
        if self.programme and (still or not steps):                     # a stop starts
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
        self.heat.restore({key: now[key] + stops * change[key] for key in now})

    def displacement(self, temperature: np.ndarray) -> np.ndarray | None:
        """K⁻¹ f_th of a nodal temperature: what thermal expansion adds to a linear body's recovered displacement."""
        if self.load is None:
            return None
        return self.disc.elastic.operator.solve(self.load(temperature))

    @property
    def state(self) -> dict[str, np.ndarray]:
        """What a checkpoint keeps to go on bit for bit.

        The temperature's state (the coefficients come from it), and the reference μ of the Newton matrices
        (:attr:`~ngwear.numerics.contact.Contact.reference`).
        """
        state = {} if self.heat is None else {f"heat_{k}": v for k, v in self.heat.state.items()}
        if self.started is not None:
            state.update({f"{STARTED}{k}": v for k, v in self.started.items()})
        if self.contact.reference is not None:
            state[REFERENCE] = self.contact.reference
        return state
