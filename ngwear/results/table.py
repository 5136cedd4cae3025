"""The per-step numbers of a run as one table: ``history.csv`` and :meth:`Result.to_dataframe`.

One row per step (N rows). The columns follow the declarations of :mod:`ngwear.results.step_fields`: ``step``, then
every field with a number per step (``times``, ``normal_force``, ``torque``, …), then each component of the fields
with a short vector per step (``tangential_force_x``, …; the plate's ``plate_displacement`` and ``plate_tilt_1``,
``plate_tilt_2`` as it declares them), then ``newton_iterations``; fields per contact point stay in ``result.npz``,
fields a run does not record (the temperatures without ``heat``) are left out. In a scene in SI each header carries
its unit in ASCII, ``torque [N m]``, ``contact_area [m^2]`` (:mod:`ngwear.results.units`); a dimensionless scene's
headers are the bare names.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .folder import replacing
from .step_fields import STEP_FIELDS
from .units import unit

ASCII = str.maketrans({"·": " ", "²": "^2", "³": "^3"})


def history(result) -> dict[str, np.ndarray]:
    """``{header: column}`` of a run's per-step table (the module docstring lists the columns)."""
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
    return {heading(scene, name, quantity): values for name, quantity, values in named}


def heading(scene, name: str, quantity: str | None) -> str:
    """``name [unit]`` (ASCII) in a scene in SI, ``name`` for a ratio, a count or a dimensionless scene."""
    symbol = unit(scene, quantity) if quantity is not None else None
    return name if symbol is None else f"{name} [{symbol.translate(ASCII)}]"


def to_dataframe(result):
    """The table as a pandas DataFrame (the columns as :func:`history` names them)."""
    import pandas as pd

    return pd.DataFrame(history(result))


def write_history(result, path) -> Path:
    """Write the table as CSV to ``path`` (floats in full precision: ``pandas.read_csv`` gives them back exactly)."""
    with replacing(path) as tmp:
        to_dataframe(result).to_csv(tmp, index=False)
    return Path(path)
