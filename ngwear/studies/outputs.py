"""Scalar outputs of a run that a study tabulates: name → function of the :class:`~ngwear.Result`.

On the contact points x_i with nodal weights m_i (∫_ΓC f da ≈ Σ_i m_i f_i), wear w_i(t_j), pressure
p_i(t_j) and J the last completed step:

* ``max_wear`` = max_i of the total wear at t_J (w, and what geometry updates moved into the body); it never
  decreases, so this is also the maximum over the run;
* ``mean_wear`` = the worn volume over the area of Γ_C at t_J, the final wear averaged over Γ_C;
* ``worn_volume`` = Σ_i m_i (total wear)_i(t_J), the volume worn away (an area per unit depth in 2D);
* ``torque``, ``normal_force`` at t_J (see :class:`~ngwear.results.result.Result`);
* ``max_pressure`` = max_{i,j} p_i(t_j), the largest compliance pressure of the run;
* ``contact_fraction`` = Σ_{i : p_i(t_J) > 0} m_i / Σ_i m_i, the part of Γ_C in contact at the end;
* ``max_temperature`` = max_j of the body's highest temperature (NaN without ``heat``);
* ``newton_iterations``: all Newton iterations of the run (its cost);
* ``steps``: J, the number of completed time steps (less than ``time.steps`` if the run stopped).

Values that need a completed step are NaN when there is none.  Adding an output is one line (and its quantity in
:data:`QUANTITIES`, for the unit of its column in an SI study's ``results.csv``).
"""
from __future__ import annotations

import numpy as np


def _final(result, values) -> float:
    return float(values(result)) if result.steps >= 0 else float("nan")


OUTPUTS = {
    "max_wear": lambda r: _final(r, lambda r: r.max_wear[-1]),
    "mean_wear": lambda r: _final(r, lambda r: r.wear_volume[-1] / np.atleast_2d(r.row_weights)[-1].sum()),
    "worn_volume": lambda r: _final(r, lambda r: r.wear_volume[-1]),
    "torque": lambda r: _final(r, lambda r: r.torque[-1]),
    "normal_force": lambda r: _final(r, lambda r: r.normal_force[-1]),
    "max_pressure": lambda r: _final(r, lambda r: r.pressure.max()),
    "contact_fraction": lambda r: _final(r, lambda r: r.weights @ (r.pressure[-1] > 0) / r.weights.sum()),
    "max_temperature": lambda r: _final(r, lambda r: r.rows["max_temperature"].max() if "max_temperature" in r.rows
                                        else float("nan")),
    "newton_iterations": lambda r: int(sum(record.iterations for record in r.newton)),
    "steps": lambda r: int(r.steps),
}


QUANTITIES = {"max_wear": "length", "mean_wear": "length", "worn_volume": "volume", "torque": "torque",
              "normal_force": "force", "max_pressure": "pressure", "max_temperature": "temperature"}
"""The quantity of each output with a unit (:mod:`ngwear.results.units`); the others are ratios or counts."""


def outputs(result, names=tuple(OUTPUTS)) -> dict[str, float]:
    """The named outputs of a result."""
    return {name: OUTPUTS[name](result) for name in names}

