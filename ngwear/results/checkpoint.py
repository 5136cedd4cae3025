"""Checkpoints: everything a run needs to go on, written atomically into its output folder.

``checkpoint.npz`` holds the result so far but its per-step rows (:meth:`Result.header`: Newton records, status), how
many rows count and the folder of the files that hold them (``steps-<id>``, see
:class:`~ngwear.results.recording.History`), the solver's warm start (x, λ), the adaptive clock's next step, the heat's
and a moved surface's state and the scene (as JSON), the CRC-32 of the counted rows and the SHA-256 of the mesh, which
is the folder's ``mesh.vol``, so a resumed run needs no meshing.  A checkpoint costs what the rows since the last one
cost to write, not the whole run.  Resumed, a run computes the same numbers, to the last bit, as if it had never
stopped: every step starts from values that the checkpoint holds exactly.  A resumed scene may differ from the
checkpoint's only in ``time.T`` (growing, to extend a run; with uniform steps ``time.steps`` grows with it, k = T/N
kept) and in ``output.*``.  Each file of the folder is checked before a resume uses it (:class:`Checkpoint`); the time
loop decides when to write one (:class:`~ngwear.runs.loop.Saver`).
"""
from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import numpy as np

from ..model.scene import Scene, SceneError
from ..model.thermal import limited
from ..numerics.systems import unknowns
from .folder import FolderError, read_arrays, replacing
from .mesh_file import checked_mesh, kept_mesh
from .provenance import canonical, scene_hash
from .recording import PREFIX, History, Recording, remove_others
from .result import HEADER, Result, from_arrays, row_shapes

CHECKPOINT = "checkpoint.npz"
FREE = ("time.T", "time.steps")
KEYS = ("scene", "x", "lam", "step", "rows", "history", "checksums", "mesh_sha256", *HEADER)
"""What every checkpoint holds (:func:`write_checkpoint`); a run's scene adds its heat's (:func:`_heat_keys`)."""


def write_checkpoint(folder, result: Result, recording: Recording | None = None,
                     continuation: dict[str, np.ndarray] | None = None) -> Path:
    """Write (or replace) the checkpoint of a run in ``folder``: its record and its continuation; the mesh, once.

    ``continuation``: the solver's warm start ``x``, ``lam``, the adaptive clock's next ``step`` and the heat's and
    the moved surface's state (:meth:`~ngwear.runs.loop.Run.continuation`; default: the finished run's,
    ``result.continuation``).  ``recording``: where the run's rows are (default: the result's rows, in memory).  Rows
    kept elsewhere (in memory: the explorer's runs) are copied into a new history folder of ``folder``; the history
    folders of earlier runs there go once this checkpoint names another.
    """
    recording = recording or Recording(result, History(dict(result.rows)))
    continuation = result.continuation if continuation is None else continuation
    folder, history, rows = Path(folder), recording.history, len(result.times)
    if not history.is_in(folder):
        history = history.moved(folder, rows)
    history.flush()
    with kept_mesh(result, folder) as mesh, replacing(folder / CHECKPOINT) as tmp:
        np.savez(tmp, **result.header(), **continuation, **_temperatures(result), **_moved(result),
                 rows=np.array(rows), history=np.array(history.folder.name),
                 checksums=np.array(json.dumps(history.checksums(rows))), mesh_sha256=np.array(mesh),
                 scene=np.array(json.dumps(result.scene.to_dict())))
    remove_others(folder, history.folder)
    return folder / CHECKPOINT


def _temperatures(result: Result) -> dict[str, np.ndarray]:
    """The kept nodal temperatures of a run with heat (none else)."""
    if result.scene.heat.model == "none":
        return {}
    steps = sorted(result.temperatures)
    return {"temperature_steps": np.array(steps, dtype=int),
            "temperature_fields": np.array([result.temperatures[s] for s in steps])}


def _moved(result: Result) -> dict[str, np.ndarray]:
    """What a run that moved its worn surface keeps of its record to go on (none before the first update).

    The bodies its frames show (:attr:`Result.meshes`) and the displacements recovered on an earlier body (up to the
    last update); the surface's own state is the continuation's (:attr:`~ngwear.runs.surface.Surface.state`).
    """
    if not result.geometry_updates:
        return {}
    steps = sorted(j for j in result.fields if j <= result.removed_rows[-1])
    meshes = sorted(result.meshes)
    return {"body_meshes": np.array(meshes, dtype=int), "body_coordinates": np.array([result.meshes[k] for k in meshes]),
            "moved_steps": np.array(steps, dtype=int), "moved_fields": np.array([result.fields[j] for j in steps])}


def saved_scene(folder) -> Scene:
    """The scene of the checkpoint in ``folder`` (read alone: no mesh, no rows)."""
    return _scene(_read(folder), Path(folder) / CHECKPOINT)


def _read(folder) -> dict[str, np.ndarray]:
    """Every array of the folder's checkpoint, or a FolderError saying what is wrong with it."""
    path = Path(folder) / CHECKPOINT
    if not path.is_file():
        raise FolderError("resume", f"{folder} holds no {CHECKPOINT} (not the output folder of a run)")
    arrays = read_arrays(path, "resume")
    missing = [key for key in KEYS if key not in arrays]
    if missing:
        raise FolderError("resume", f"{path} is damaged or not a checkpoint of ngwear (no {', '.join(missing)})")
    broken = [key for key, value in arrays.items() if key not in MAY_BE_NAN and value.dtype.kind == "f"
              and not np.isfinite(value).all()]
    if broken:
        raise FolderError("resume", f"{path} is damaged (not finite: {', '.join(broken)})")
    return arrays


MAY_BE_NAN = ("newton_residuals",)
"""The only numbers of a checkpoint that may be NaN or infinite: a failed Newton iteration's merit is one."""


def _scene(data: dict, path: Path) -> Scene:
    """The checkpoint's scene, once its SHA-256 is the one its run recorded (``provenance``): an edited scene is refused."""
    try:
        given, recorded = json.loads(str(data["scene"])), json.loads(str(data["provenance"]))["scene_sha256"]
        same = hashlib.sha256(canonical(given).encode()).hexdigest() == recorded
    except (ValueError, TypeError, KeyError, RecursionError) as err:
        raise FolderError("resume", f"{path} holds no valid scene ({err})") from None
    if not same:
        raise FolderError("resume", f"{path} is damaged (its scene is not the one its run recorded: edited after "
                                    "the run? change a resumed run with SCENE or --set, not in the checkpoint)")
    try:
        return Scene.from_dict(given)
    except (ValueError, TypeError, RecursionError) as err:
        raise FolderError("resume", f"{path} holds no valid scene ({err})") from None


class Checkpoint:
    """A checkpoint read back: its scene, the result and its recording on the folder's mesh, the warm start, the step.

    Each file is checked before it is used (see :class:`FolderError`): the checkpoint's keys, that the
    folder's ``mesh.vol`` is the checkpoint's (SHA-256) and that the rows' files hold the counted rows.
    """

    def __init__(self, folder, scene: Scene | None = None):
        from ..numerics.discrete import Discretization

        folder = Path(folder)
        data = _read(folder)
        saved = _scene(data, folder / CHECKPOINT)
        missing = [key for key in _heat_keys(saved, int(data["rows"])) if key not in data]
        if missing:
            raise FolderError("resume", f"{folder / CHECKPOINT} is damaged or not a checkpoint of ngwear (no "
                                        f"{', '.join(missing)})")
        self.scene = saved if scene is None else _continuing(saved, scene)
        mesh = checked_mesh(folder, data, self.scene.dim, "resume")
        self.surface = _surface(folder / CHECKPOINT, data, mesh)
        disc = Discretization(self.scene, mesh)
        disc.elastic.ordering = _ordering(folder / CHECKPOINT, data.get("surface_ordering"), disc)
        _check_counts(folder / CHECKPOINT, data, disc, moved=bool(self.surface))
        _check_shapes(folder / CHECKPOINT, data, disc)
        _check_signs(folder / CHECKPOINT, data)
        if not re.fullmatch(rf"{PREFIX}[0-9a-f]{{12}}", str(data["history"])):    # a folder of its own, here
            raise FolderError("resume", f"{folder / CHECKPOINT} names no history folder of its own "
                                        f"({str(data['history'])[:80]!r})")
        rows, shapes = int(data["rows"]), row_shapes(self.scene, disc)
        history = History.reopen(folder / str(data["history"]), shapes, rows, _checksums(folder / CHECKPOINT, data))
        self.result = from_arrays(self.scene, data, disc, {name: history.buffers[name][:rows] for name in shapes})
        self.recording = Recording(self.result, history)
        self.result.mesh_digest = str(data["mesh_sha256"])
        self.result.provenance = {**self.result.provenance, "scene_sha256": scene_hash(self.scene)}  # the scene run on
        self.x, self.lam, self.step = np.array(data["x"]), np.array(data["lam"]), float(data["step"])
        self.heat = {key: np.array(value) for key, value in data.items() if key.startswith("heat_")}
        if "temperature_steps" in data:
            self.result.temperatures = {int(s): np.array(f) for s, f in zip(data["temperature_steps"],
                                                                            data["temperature_fields"])}
        if self.surface:
            self.result.meshes = dict(zip(data["body_meshes"].tolist(), data["body_coordinates"]))
            self.result.fields.update(zip(data["moved_steps"].tolist(), data["moved_fields"]))
        self.result.status = "completed"


def _heat_keys(scene: Scene, rows: int) -> tuple[str, ...]:
    """The keys of the heat's state (:func:`_heat`) that a checkpoint of ``scene`` with ``rows`` rows holds.

    With a temperature: its state and the kept nodal temperatures; in a programme also its state at the last simulated
    stop's start, which step 0 is (:meth:`~ngwear.runs.heating.Heating.advance`).
    """
    if scene.heat.model != "conduction":
        return ()
    parts = ("temperature", "heat", "counterface")
    started = parts if scene.programme is not None and rows else ()
    return (*(f"heat_{p}" for p in parts), "temperature_steps", "temperature_fields",
            *(f"heat_started_{p}" for p in started), *(("heat_limits",) if limited(scene) else ()))


def _surface(path: Path, data: dict, mesh) -> dict[str, np.ndarray]:
    """A moved body's state (see :func:`_moved`), its mesh put where the run left it; {} before the first update."""
    from ..numerics.topology import place

    updates = len(data["removed_rows"])
    if not updates:
        return {}
    missing = [key for key in ("surface_coordinates", "surface_reference", "surface_wear", "body_meshes",
                               "body_coordinates", "moved_steps", "moved_fields") if key not in data]
    if missing:
        raise FolderError("resume", f"{path} is damaged (it moved its worn surface {updates} times but holds no "
                                    f"{', '.join(missing)})")
    coords = np.array(data["surface_coordinates"])
    if coords.shape != (mesh.nv, mesh.dim):
        raise FolderError("resume", f"{path.parent / 'mesh.vol'} is not the mesh of {path.name} ({mesh.nv} vertices, "
                                    f"its moved mesh has {len(coords)})")
    place(mesh, coords)
    return {key: np.array(data[key]) for key in ("surface_reference", "surface_wear")}


def _ordering(path: Path, ordering: np.ndarray | None, disc) -> np.ndarray | None:
    """The ordering the updates' factorisations took (None: METIS's), checked to be a permutation of the free DOFs."""
    if ordering is not None and not np.array_equal(np.sort(ordering), np.arange(np.count_nonzero(disc.body.free))):
        raise FolderError("resume", f"{path} is damaged (its surface_ordering is not an ordering of the "
                                    f"{np.count_nonzero(disc.body.free)} free DOFs)")
    return ordering


def _check_counts(path: Path, data: dict, disc, moved: bool = False) -> None:
    """The checkpoint's contact points are the mesh's (``moved``: as many); one Newton record per row (+ a failure)."""
    built = len(data["contact_points"]) == disc.points.n if moved else \
        np.array_equal(data["contact_points"], disc.points.coords)
    if not built:
        raise FolderError("resume", f"{path.parent / 'mesh.vol'} is not the mesh of {path.name} (its contact "
                                    "points differ)")
    rows = int(data["rows"])
    records = len(data["newton_iterations"])
    if records - rows not in (0, 1) or len(data["lam"]) != disc.points.n:
        raise FolderError("resume", f"{path} is damaged ({records} Newton records for {rows} steps, {len(data['lam'])} "
                                    f"multipliers for {disc.points.n} contact points)")


def _check_shapes(path: Path, data: dict, disc) -> None:
    """Each array of the run's state of the shape the discretization gives it (else a FolderError naming it).

    n contact points, d dimensions, v mesh vertices, x unknowns, U geometry updates, F frames' bodies, M recovered
    fields, K kept temperatures of N heat nodes, R Newton records of L residuals in all.
    """
    updates, frames = len(data["removed_rows"]), len(data.get("body_meshes", ()))
    sizes = {"n": disc.points.n, "d": disc.mesh.dim, "v": disc.mesh.nv, "x": len(unknowns(disc)), "U": updates,
             "F": frames, "M": len(data.get("moved_steps", ())), "K": len(data.get("temperature_steps", ())),
             "R": len(data["newton_iterations"]), "L": int(np.maximum(data["newton_lengths"], 0).sum())}
    if "heat_temperature" in data:
        sizes["N"] = len(data["heat_temperature"])
    for key, shape in SHAPES.items():
        if key in data and key != "moved_fields":
            wanted = tuple(sizes[s] if isinstance(s, str) else s for s in shape)
            if data[key].shape != wanted:
                raise FolderError("resume", f"{path} is damaged ({key} has the shape {data[key].shape}, its run's is "
                                            f"{wanted})")
    fields = data.get("moved_fields")
    if fields is not None and (fields.ndim != 2 or len(fields) != sizes["M"]):
        raise FolderError("resume", f"{path} is damaged (moved_fields has the shape {fields.shape} for "
                                    f"{sizes['M']} recovered steps)")


SHAPES = {"contact_points": ("n", "d"), "weights": ("n",), "friction_coefficient": ("n",),
          "wear_coefficient": ("n",), "contact_stiffness": ("n",), "thickness": ("n",), "x": ("x",), "lam": ("n",),
          "step": (), "rows": (), "wall_time": (), "solve_time": (), "removed": ("U", "n"),
          "moved_weights": ("U", "n"), "surface_reference": ("v", "d"), "surface_coordinates": ("v", "d"),
          "body_meshes": ("F",), "body_coordinates": ("F", "v", "d"), "moved_steps": ("M",),
          "temperature_steps": ("K",), "temperature_fields": ("K", "N"), "heat_started_temperature": ("N",),
          **{f"newton_{name}": ("R",) for name in ("converged", "active", "damped", "bulk", "tangents", "cutbacks",
                                                   "lengths")}, "newton_residuals": ("L",)}
"""The shape of each array of a checkpoint's state (see :func:`_check_shapes`)."""


POSITIVE = ("weights", "thickness", "contact_stiffness")
NON_NEGATIVE = ("step", "friction_coefficient", "wear_coefficient", "rejected", "wall_time", "solve_time", "jumped",
                "removed_rows", *(f"newton_{name}" for name in ("iterations", "active", "damped", "bulk", "tangents",
                                                                "cutbacks", "lengths")))
"""The numbers of a checkpoint that are positive, and those that are steps, counts, times, indices or μ and κ (>= 0)."""


def _check_signs(path: Path, data: dict) -> None:
    """Each number of :data:`POSITIVE` > 0 and of :data:`NON_NEGATIVE` >= 0; the jumped stops increasing."""
    wrong = [key for key in POSITIVE if key in data and not (data[key] > 0).all()] + \
        [key for key in NON_NEGATIVE if key in data and not (data[key] >= 0).all()]
    if len(data["jumped"]) and not (np.diff(data["jumped"]) > 0).all():
        wrong.append("jumped")
    if wrong:
        raise FolderError("resume", f"{path} is damaged (out of range: {', '.join(wrong)})")


def _checksums(path: Path, data: dict) -> dict[str, int]:
    """The rows' CRC-32 by name the checkpoint recorded."""
    try:
        checksums = json.loads(str(data["checksums"]))
    except ValueError:
        checksums = None
    if not isinstance(checksums, dict) or not all(isinstance(v, int) for v in checksums.values()):
        raise FolderError("resume", f"{path} is damaged (its checksums are not a table of the rows' CRC-32)")
    return checksums


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
