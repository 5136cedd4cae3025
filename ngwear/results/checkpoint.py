"""Checkpoints: everything a run needs to go on, written atomically into its output folder.

``checkpoint.npz`` holds the result so far but its per-step rows (:meth:`Result.header`: Newton records,
status), how many rows count and the folder of the files that hold them (``steps-<id>``, see
:mod:`ngwear.results.history`), the solver's warm start (x, λ), the adaptive clock's next step and the
scene (as JSON); the mesh is the folder's ``mesh.vol``, so a resumed run needs no meshing.  A checkpoint
costs what the rows since the last one cost to write, not the whole run.  Resumed, a run computes the same numbers,
to the last bit, as if it had never stopped: every step starts from values that the checkpoint holds
exactly.  A resumed scene may differ from the checkpoint's only in ``time.T`` (growing, to extend a
run; with uniform steps ``time.steps`` grows with it, k = T/N kept) and in ``output.*``.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..model.scene import Scene, SceneError
from .history import History, remove_others
from .result import Result, from_arrays, replacing, row_shapes, save_mesh

CHECKPOINT = "checkpoint.npz"
FREE = ("time.T", "time.steps")


def write_checkpoint(folder, result: Result) -> Path:
    """Write (or replace) the checkpoint of ``result`` (its ``continuation``) in ``folder``; the mesh too, once.

    Rows kept elsewhere (in memory: the explorer's runs) are copied into a new history folder of ``folder``;
    the history folders of earlier runs there go once this checkpoint names another.
    """
    x, lam, step = result.continuation
    folder, history = Path(folder), result.history
    if not history.is_in(folder):
        history = history.moved(folder, len(result.times))
    if not (folder / "mesh.vol").is_file():
        save_mesh(result.discretization.mesh, folder)
    history.flush()
    with replacing(folder / CHECKPOINT) as tmp:
        np.savez(tmp, **result.header(), rows=np.array(len(result.times)), history=np.array(history.folder.name),
                 x=x, lam=lam, step=np.array(step), scene=np.array(json.dumps(result.scene.to_dict())))
    remove_others(folder, history.folder)
    return folder / CHECKPOINT


def saved_scene(folder) -> Scene:
    """The scene of the checkpoint in ``folder`` (read alone: no mesh, no rows)."""
    with np.load(_path(folder)) as data:
        return _scene(data)


def _scene(data) -> Scene:
    return Scene.from_dict(json.loads(str(data["scene"])))


def _path(folder) -> Path:
    path = Path(folder) / CHECKPOINT
    if not path.is_file():
        raise SceneError(f"resume: {folder} holds no {CHECKPOINT} (not the output folder of a run)")
    return path


class Checkpoint:
    """A checkpoint read back: its scene, the result on the folder's mesh, the warm start and the next step."""

    def __init__(self, folder, scene: Scene | None = None):
        from ..model.geometry import load_mesh
        from ..numerics.discrete import Discretization

        folder = Path(folder)
        with np.load(_path(folder)) as data:
            saved = _scene(data)
            self.scene = saved if scene is None else _continuing(saved, scene)
            disc = Discretization(self.scene, load_mesh(folder / "mesh.vol", self.scene.dim))
            if "history" in data:
                history = History.reopen(folder / str(data["history"]), row_shapes(self.scene, disc))
                self.result = from_arrays(self.scene, data, disc, history)
            else:                                   # written before the rows had their own files: they are here
                self.result = from_arrays(self.scene, data, disc)
                self.result.keep_in(folder)
            self.x, self.lam, self.step = np.array(data["x"]), np.array(data["lam"]), float(data["step"])
        self.result.status = "completed"


def _continuing(saved: Scene, scene: Scene) -> Scene:
    """``scene`` if it may continue the run of ``saved`` (see the module docstring), else a SceneError."""
    differing = [key for key in _dotted(saved.to_dict()) | _dotted(scene.to_dict())
                 if _value(saved, key) != _value(scene, key) and not key.startswith("output.")]
    refused = [key for key in differing if key not in FREE]
    if refused:
        raise SceneError(f"resume: the scene differs from the checkpoint's in {', '.join(sorted(refused))} "
                         "(only time.T may change, to extend the run)")
    if scene.time.T < saved.time.T:
        raise SceneError(f"time.T: a resumed run may only go on longer (got {scene.time.T} < {saved.time.T})")
    if not saved.time.adaptive and scene.dt != saved.dt:
        steps = saved.time.steps * scene.time.T / saved.time.T
        raise SceneError(f"time.steps: must be {steps:g} to keep the checkpoint's step k = {saved.dt:g} "
                         f"(got {scene.time.steps})")
    return scene


def _dotted(data: dict, prefix: str = "") -> set[str]:
    keys = set()
    for name, value in data.items():
        keys |= _dotted(value, f"{prefix}{name}.") if isinstance(value, dict) else {f"{prefix}{name}"}
    return keys


def _value(scene: Scene, key: str):
    node = scene.to_dict()
    for part in key.split("."):
        node = node.get(part) if isinstance(node, dict) else None
    return node
