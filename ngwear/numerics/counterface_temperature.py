"""The counterface's temperature T_f: given (a number or a table of time), or a lumped thermal mass (a disc).

The lumped counterface takes the share 1 − η of the frictional power Q = Σ_i m_i μ_i p_i ‖v*_i‖ and cools:

    C_d dT_f/dt = (1 − η) Q − H_d (T_f − T_∞),

by backward Euler on the body's steps (as the body's temperature), with the power of the step's end:

    T_f^{n+1} = (C_d T_f^n + Δt ((1 − η) Q^{n+1} + H_d T_∞)) / (C_d + Δt H_d),

so that C_d (T_f^{n+1} − T_f^n) = Δt ((1 − η) Q^{n+1} − H_d (T_f^{n+1} − T_∞)) holds to round-off: the heat it
received less the heat it lost is what it stores.  Under a constant power it tends to T_∞ + (1 − η) Q / H_d with
the time constant C_d / H_d (the discrete factor per step 1 / (1 + Δt H_d / C_d)).
"""
from __future__ import annotations

import numpy as np

from ..model.keys import piecewise_linear


class Given:
    """A counterface at a given temperature: ``foundation.temperature`` (a number or [[t, T_f], …]) or T_∞."""

    def __init__(self, temperature, ambient: float):
        self.table = temperature if isinstance(temperature, tuple) else ((0.0, ambient if temperature is None
                                                                           else float(temperature)),)

    def temperature(self, t: float) -> float:
        return piecewise_linear(self.table, t)

    def advance(self, t: float, dt: float, power: float) -> float:
        """T_f(t) (``power``, what the body does not take, is the counterface's business: not tracked)."""
        return self.temperature(t)

    @property
    def state(self) -> tuple[float, ...]:
        return ()

    @state.setter
    def state(self, values) -> None:
        pass


class Lumped:
    """A lumped counterface: heat capacity C_d (``foundation.thermal_mass``), cooling H_d, surroundings at T_∞."""

    def __init__(self, capacity: float, cooling: float, ambient: float, start: float):
        self.capacity, self.cooling, self.ambient = capacity, cooling, ambient
        self.start = self.T = start
        self.received = self.cooled = self.given = 0.0     # ∫ (1 − η) Q, ∫ H_d (T_f − T_∞), ∫ Σ g (T_f − T) dt

    def temperature(self, t: float) -> float:
        return self.T

    def advance(self, t: float, dt: float, power: float) -> float:
        """T_f at the end of a step of length dt that received ``power`` = (1 − η) Q (backward Euler)."""
        C, H = self.capacity, self.cooling
        self.T = (C * self.T + dt * (power + H * self.ambient)) / (C + dt * H)
        self.received += dt * power
        self.cooled += dt * H * (self.T - self.ambient)
        return self.T

    def exchange(self, dt: float, power: float, gains: np.ndarray, free: np.ndarray, unit: np.ndarray) -> float:
        """T_f at the end of a step that also exchanges Σ_i g_i (T_i − T_f) with the body's face, implicitly in both.

        The body's face temperatures are E T = ``free`` + ``unit`` T_f (its solve for T_f = 0 and per unit T_f), so

            C_d (T_f − T_f^n) = Δt ((1 − η) Q + H_d (T_∞ − T_f) + Σ_i g_i (free_i + unit_i T_f − T_f))

        is one linear equation in T_f (its coefficient C_d + Δt (H_d + Σ g_i (1 − unit_i)) > 0 as 0 ≤ unit_i < 1).
        """
        C, H = self.capacity, self.cooling
        self.T = (C * self.T + dt * (power + H * self.ambient + gains @ free)) / (
            C + dt * (H + gains.sum() - gains @ unit))
        self.received += dt * power
        self.cooled += dt * H * (self.T - self.ambient)
        self.given += dt * float(gains @ (self.T - free - unit * self.T))
        return self.T

    @property
    def stored(self) -> float:
        """C_d (T_f − T_f(0)): received − cooled − given, to round-off."""
        return self.capacity * (self.T - self.start)

    @property
    def state(self) -> tuple[float, ...]:
        """(T_f, received, cooled, given): what a checkpoint keeps."""
        return self.T, self.received, self.cooled, self.given

    @state.setter
    def state(self, values) -> None:
        self.T, self.received, self.cooled, self.given = (float(v) for v in values)


def counterface(scene):
    """The counterface of a scene: :class:`Lumped` with ``foundation.thermal_mass``, else :class:`Given`."""
    f, h = scene.foundation, scene.heat
    if f.thermal_mass is not None:
        return Lumped(f.thermal_mass, f.cooling, h.ambient, h.start)
    return Given(f.temperature, h.ambient)
