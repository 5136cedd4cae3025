"""Each step's Newton record as flat arrays in ``result.npz`` and ``checkpoint.npz``, and back."""
from __future__ import annotations

import numpy as np

from ..numerics.systems.newton import NewtonRecord


def records_to_arrays(newton: list[NewtonRecord]) -> dict[str, np.ndarray]:
    """Newton records as flat arrays (residual histories concatenated, with their lengths)."""
    return {"newton_iterations": np.array([r.iterations for r in newton], dtype=int),
            "newton_converged": np.array([r.converged for r in newton], dtype=bool),
            "newton_active": np.array([r.active for r in newton], dtype=int),
            "newton_damped": np.array([r.damped for r in newton], dtype=int),
            "newton_bulk": np.array([r.bulk for r in newton], dtype=int),
            "newton_tangents": np.array([r.tangents for r in newton], dtype=int),
            "newton_cutbacks": np.array([r.cutbacks for r in newton], dtype=int),
            "newton_lengths": np.array([len(r.residuals) for r in newton], dtype=int),
            "newton_residuals": np.array([v for r in newton for v in r.residuals], dtype=float)}


def records_from_arrays(data) -> list[NewtonRecord]:
    """The Newton records that :func:`records_to_arrays` flattened."""
    bounds = np.concatenate([[0], np.cumsum(data["newton_lengths"])])
    residuals = data["newton_residuals"]
    cutbacks, bulk, tangents = (data[name] for name in ("newton_cutbacks", "newton_bulk", "newton_tangents"))
    return [NewtonRecord(bool(c), int(i), [float(v) for v in residuals[a:b]], int(act), int(dmp), bulk=int(blk),
                         tangents=int(tan), cutbacks=int(cut))
            for i, c, act, dmp, blk, tan, cut, a, b in zip(data["newton_iterations"], data["newton_converged"],
                                                           data["newton_active"], data["newton_damped"], bulk,
                                                           tangents, cutbacks, bounds[:-1], bounds[1:])]
