"""What :meth:`Result.save <ngwear.results.result.Result.save>` writes: a run's files in its output folder.

``result.npz`` holds the record's rows and header (points, weights, coefficients, Newton records, status, …), the
derived per-step numbers, the frames' displacements (and temperatures, and the worn body's vertices) and, in an SI
scene, the unit of every number; beside it ``scene.json``, ``mesh.vol``, ``history.csv``, ``summary.json``,
``stops.csv`` (a programme) and the VTU/PVD series of the frames.  Each file is written under a temporary name and
then renamed, so that an interrupt never leaves half a file; :func:`~ngwear.results.result.load_result` reads them.
"""
from __future__ import annotations

import json
from contextlib import ExitStack
from pathlib import Path

import numpy as np

from .folder import replacing
from .history_csv import headed, write_history
from .mesh_file import kept_mesh
from .step_fields import DERIVED
from .stops import QUANTITIES as STOP_QUANTITIES
from .units import units
from .vtk import write_series


def save(result, directory) -> Path:
    """Write result.npz, scene.json, mesh.vol, history.csv, summary.json and a VTU/PVD series of the frames."""
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    steps = result.stored_steps
    fields = np.array([result.displacement(s) for s in steps]) if result.discretization else np.zeros((0, 0))
    arrays = {**result.arrays(), **{f.name: getattr(result, f.name) for f in DERIVED},
              "field_steps": np.array(steps, dtype=int), "fields": fields, **_temperature_fields(result, steps)}
    if result.discretization is not None:                 # the worn body of each frame ("surface")
        arrays["frame_coordinates"] = (np.array([result.body_coordinates(s) for s in steps]) if result.geometry_updates
                                       else np.zeros((0, 0, result.scene.dim)))
    if result.scene.units:
        arrays["units"] = np.array(json.dumps(units(result.scene, arrays), ensure_ascii=False))
    with ExitStack() as written:
        if result.discretization is not None:              # result.npz names its mesh by its SHA-256
            arrays["mesh_sha256"] = np.array(written.enter_context(kept_mesh(result, out)))
        tmp = written.enter_context(replacing(out / "result.npz"))
        np.savez(tmp, **arrays)                 # not compressed: zlib costs far more time than it saves space

    with replacing(out / "scene.json") as tmp:
        tmp.write_text(json.dumps(result.scene.to_dict(), indent=2))
    write_history(result, out / "history.csv")
    with replacing(out / "summary.json") as tmp:
        tmp.write_text(json.dumps(result.summary(), indent=2, ensure_ascii=False), encoding="utf-8")
    if result.scene.programme is not None:
        with replacing(out / "stops.csv") as tmp:
            headed(result.scene, result.stops, STOP_QUANTITIES).to_csv(tmp)
    if result.discretization is not None:
        write_series(result, out)
    return out


def _temperature_fields(result, steps) -> dict[str, np.ndarray]:
    """The nodal temperature (P1) of the frames, ``temperature_fields`` (with ``heat``; none else)."""
    if result.scene.heat.model == "none" or not all(s in result.temperatures for s in steps):
        return {}
    return {"temperature_fields": np.array([result.temperatures[s] for s in steps])}
