"""The per-step numbers of a run as one table, and the one rule of every CSV ngwear writes.

One row per step (N rows). The columns follow the declarations of :mod:`ngwear.results.step_fields`: ``step``, then
every field with a number per step (``times``, ``speed_factor``, ``normal_force``, ``torque``, …), then each
component of the fields with a short vector per step (``tangential_force_x``, …; the plate's ``plate_displacement``
and ``plate_tilt_1``, ``plate_tilt_2`` as it declares them), then ``newton_iterations``; fields per contact point stay
in ``result.npz``, fields a run does not record (the temperatures without ``heat``) are left out.

The rule of every CSV (``history.csv``, ``stops.csv``, a study's ``results.csv``): a column is headed
``name [unit]`` in a scene in SI (ASCII: ``torque [N m]``, ``contact_area [m^2]``, :mod:`ngwear.results.units`), and
``name`` for a ratio, a count or a dimensionless scene; the DataFrames (:meth:`Result.to_dataframe`,
``Result.stops``) use the bare names, and a reader matches the text before `` [`` (:func:`bare`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .folder import replacing
from .step_fields import STEP_FIELDS
from .units import unit

ASCII = str.maketrans({"·": " ", "²": "^2", "³": "^3"})


def history(result) -> dict[str, tuple[str | None, np.ndarray]]:
    """``{name: (quantity, column)}`` of a run's per-step table (the module docstring lists the columns)."""
    scene, rows = result.scene, len(result.times)
    named = [("step", None, np.arange(rows))]
    for f in sorted(STEP_FIELDS, key=lambda f: len(f.shape)):
        if "n" in f.shape or len(f.shape) > 1 or not f.recorded_in(scene):
            continue
        values = np.asarray(getattr(result, f.name))
        if not f.shape:
            named.append((f.name, f.quantity, values))
        else:
            named += [(name, quantity, values[:, k]) for k, (name, quantity) in enumerate(f.columns(values.shape[1]))]
    named.append(("newton_iterations", None, np.array([r.iterations for r in result.newton[:rows]], dtype=int)))
    return {name: (quantity, values) for name, quantity, values in named}


def heading(scene, name: str, quantity: str | None) -> str:
    """``name [unit]`` (ASCII) in a scene in SI, ``name`` for a ratio, a count or a dimensionless scene."""
    symbol = unit(scene, quantity) if quantity is not None else None
    return name if symbol is None else f"{name} [{symbol.translate(ASCII)}]"


def bare(column: str) -> str:
    """The name of a CSV column: the text before `` [`` (its unit)."""
    return column.split(" [", 1)[0]


def headed(scene, table, quantities: dict[str, str | None]):
    """``table`` (a DataFrame of bare names) with its columns headed by the rule: ``name [unit]``."""
    return table.rename(columns={name: heading(scene, name, quantities.get(name)) for name in table.columns})


def to_dataframe(result, table: dict | None = None):
    """The table (:func:`history`, or ``table`` of it) as a pandas DataFrame, its columns by their bare names."""
    import pandas as pd

    return pd.DataFrame({name: values for name, (_, values) in (table or history(result)).items()})


def write_history(result, path) -> Path:
    """Write the table as CSV to ``path``, headed by the rule (floats in full precision: ``read_csv`` gives them back)."""
    table = history(result)
    quantities = {name: quantity for name, (quantity, _) in table.items()}
    with replacing(path) as tmp:
        headed(result.scene, to_dataframe(result, table), quantities).to_csv(tmp, index=False)
    return Path(path)
