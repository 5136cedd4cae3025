"""Result of a run: per-step contact-point arrays, Newton records and displacement fields.

Arrays of shape (steps + 1, n_c) over the contact points (fewer rows if the run stopped early;
``times`` t_j need not be uniform, see ``time.adaptive``):
``wear`` w, ``normal_displacement`` u_ν, ``pressure`` p(u_ν − d₀ − w), ``reaction`` λ (the
constraint multiplier, a traction like the pressure); ``plate_displacement`` δ (steps + 1, r) of a
rigid plate (its translation along ν, then its tilts; r = 0 without a plate); ``speed_factor`` s_v and
``load_factor`` s_F, the factors each step was solved with.  What an engineer reads off a part, one value per step
(``normal_force``, ``torque``, ``friction_power``, ``wear_volume``, …), is computed from these rows by
:mod:`ngwear.results.derived`, each quantity once.

The contact coefficients at the points, shape (n_c,): ``friction_coefficient`` μ_i, ``wear_coefficient`` κ_i and
``contact_stiffness`` L_i (numbers or fields of the scene, as evaluated there; a coefficient of the state is recorded
per step, ``step_friction`` and ``step_wear_coefficient``).  The per-step fields are declared in
:mod:`ngwear.results.step_fields`; a run records its rows through a :class:`~ngwear.results.recording.Recording`.

Full displacement fields are kept for the frames (``stored_steps``): the steps nearest to the output times
(``output.every`` apart from t = 0, or ``output.times``) and the last step, so that the number of frames does not
grow with the number of steps.  ``save(dir)`` writes the files of :mod:`ngwear.results.files` (``result.npz`` with
these names as keys, each under a temporary name, then renamed); :func:`load_result` reads them back.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import ngsolve as ngs
import numpy as np

from ..model.scene import Scene
from ..numerics.contact import Motion
from ..numerics.expansion import ThermalLoad
from ..numerics.systems.newton import NewtonRecord
from .derived import QUANTITIES
from .files import save
from .folder import FolderError, read_arrays
from .history_csv import to_dataframe
from .mesh_file import saved_discretization
from .newton_records import records_from_arrays, records_to_arrays
from .provenance import canonical
from .step_fields import DERIVED, RECORDED
from .stops import stop_table
from .summary import summary

ARRAYS = tuple(f.name for f in RECORDED if f.when is None)
"""The rows every run records (:data:`~ngwear.results.step_fields.RECORDED`; :func:`recorded`: those of a scene)."""
_DOCS = {f.name: f"{f.doc}, shape {f.shown}." for f in DERIVED}


def _stops(result):
    """One row per stop of the programme (a pandas DataFrame; None without a programme).

    See :func:`ngwear.results.stops.stop_table`.
    """
    return stop_table(result) if result.scene.programme is not None else None


def _summary(result) -> dict:
    """Key numbers of the run (what ``ngwear run`` prints): see :func:`ngwear.results.summary.summary`."""
    return summary(result)


def _to_dataframe(result):
    """The run's per-step numbers, one row per step, as a pandas DataFrame: the table of ``history.csv``.

    Its columns (:mod:`ngwear.results.history_csv`): ``step``, ``times``, every per-step number (``torque``, …), the
    components of the short vectors, ``newton_iterations``, by their bare names (``history.csv`` heads them with their
    units in a scene in SI, ``torque [N m]``).
    """
    return to_dataframe(result)


VIEWS = {"stops": property(_stops, doc=_stops.__doc__), "summary": _summary, "to_dataframe": _to_dataframe}
"""The record's views, each computed by the module that knows it: the stop table, the summary, the per-step table."""
COEFFICIENTS = ("friction_coefficient", "wear_coefficient", "contact_stiffness")
HEADER = ("contact_points", "weights", *COEFFICIENTS, *records_to_arrays([]), "status", "wall_time", "solve_time",
          "rejected", "warnings", "jumped", "thickness", "removed_rows", "removed", "moved_weights", "provenance")
"""The keys :meth:`Result.header` writes, of every run."""


@dataclass
class Result:
    """What a run produced: per-step arrays at the contact points, what a part's engineer reads, the fields.

    Made by :func:`~ngwear.simulate` or read by :func:`load_result`; the module docstring gives the layout.

    Attributes
    ----------
    scene : Scene
        The scene that ran.
    contact_points, weights : ndarray
        x_i (n, d) and the quadrature weights m_i (n,) of Γ_C.
    friction_coefficient, wear_coefficient, contact_stiffness : ndarray
        μ_i, κ_i and L_i at the contact points (n,): the scene's numbers or fields.
    times, wear, normal_displacement, pressure, reaction, forces, plate_displacement : ndarray
        The recorded per-step arrays t_j (N,); w, u_ν, p and λ at the contact points (N, n); the contact forces
        (N, n, d); δ of a rigid plate (N, r), r = 0 without one (properties, as declared in
        :mod:`~ngwear.results.step_fields`).
    normal_force, torque, friction_force, apparent_friction, contact_area, wear_volume : ndarray
        Per step (N,): Σ m (p + λ), the friction moment about the counterface's axis, ‖F_t‖, ‖F_t‖ / normal force,
        the area in contact and the worn volume (properties, :mod:`ngwear.results.derived`; ``tangential_force`` is
        F_t itself, (N, d)).
    max_wear, max_pressure, mean_pressure, friction_power, dissipated_energy : ndarray
        Per step (N,): max of the total wear, max p, normal force / contact area, P = Σ m μ p ‖v*‖ and ∫₀ᵗ P dt.
    newton : list of NewtonRecord
        Each step's Newton iterations, residuals, active set, cut-backs.
    status : str
        ``completed``, ``interrupted`` or what stopped the run.
    warnings : list of str
        What the run warns of (the explicit update's stability, a missed tolerance).
    wall_time, solve_time : float
        Seconds of the whole run (meshing and factorising included) and of its time loop.
    discretization : Discretization or None
        The mesh and factorisation it ran on (``displacement`` and pictures need it).
    rows : dict of ndarray
        The recorded per-step arrays by name.
    meshes : dict of int to ndarray
        ``wear.geometry = "surface"``: the vertices (nv, d) of the body after k geometry updates, kept for the meshes
        the frames show (:meth:`body_coordinates`); ``recession`` the map that moves the mesh by a wear (the others').
    provenance : dict
        ``ngwear``, ``ngsolve``, ``python``: the versions that computed it; ``scene_sha256``: the SHA-256 of its
        scene's canonical JSON (:mod:`ngwear.results.provenance`).  Every run records it; None for a Result made by hand.
    continuation : dict or None
        What a checkpoint needs besides the rows to go on from the last step (the solver's warm start, the adaptive
        clock's next step, the heat's and a moved surface's state): a finished run's, for
        :func:`~ngwear.results.checkpoint.write_checkpoint`.
    """

    scene: Scene
    contact_points: np.ndarray
    weights: np.ndarray
    rows: dict[str, np.ndarray] = field(repr=False)
    friction_coefficient: np.ndarray = field(default=None, repr=False)
    wear_coefficient: np.ndarray = field(default=None, repr=False)
    contact_stiffness: np.ndarray = field(default=None, repr=False)
    newton: list[NewtonRecord] = field(default_factory=list)
    status: str = "completed"
    warnings: list[str] = field(default_factory=list)
    wall_time: float = 0.0
    solve_time: float = 0.0
    rejected: int = 0
    fields: dict[int, np.ndarray] = field(default_factory=dict)
    temperatures: dict[int, np.ndarray] = field(default_factory=dict)   # nodal T (P1) of the frames (`heat`)
    discretization: object = field(default=None, repr=False)
    recession: object = field(default=None, repr=False)           # "surface": the map moving the mesh by a wear
    mesh_digest: str | None = field(default=None, repr=False)     # SHA-256 of the mesh.vol written for it
    provenance: dict | None = field(default=None, repr=False)     # versions and scene hash (None: not made by a run)
    jumped: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int), repr=False)
    measured: np.ndarray | None = field(default=None, repr=False)   # the worn region's thickness (see thickness)
    removed_rows: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int), repr=False)
    removed: np.ndarray | None = field(default=None, repr=False)      # (U, n): each geometry update's W at the points
    moved_weights: np.ndarray | None = field(default=None, repr=False)  # (U, n): m_i after each update
    meshes: dict[int, np.ndarray] = field(default_factory=dict, repr=False)   # k: the vertices after k updates
    thermal: tuple | None = field(default=None, repr=False)       # (discretization, its f_th's G), for recovery
    continuation: dict | None = field(default=None, repr=False)   # what a checkpoint needs to go on from the end

    @property
    def completed(self) -> bool:
        return self.status == "completed"

    @property
    def steps(self) -> int:
        """Index of the last completed step."""
        return len(self.times) - 1

    def step_index(self, step: int) -> int:
        """The index of ``step`` as a list's (−1: the last step); IndexError for a step the run does not have."""
        return range(self.steps + 1)[step]

    @cached_property
    def motion(self) -> Motion:
        """The foundation's motion at the contact points (their moment arms, ‖v*‖ and n* at s_v = 1)."""
        return Motion(self.scene, self.contact_points, self.scene.contact.direction)

    def total_wear_at(self, step: int) -> np.ndarray:
        """``total_wear`` of one step alone (O(n): what the time loop reads after each step; −1: the last)."""
        step = self.step_index(step)
        if not len(self.removed_rows):
            return self.wear[step]
        return self.wear[step] + self.removed[self.removed_rows <= step].sum(axis=0)

    def last_total_wear(self) -> np.ndarray:
        """``total_wear`` of the last step."""
        return self.total_wear_at(-1)

    def updates_by(self, step: int) -> int:
        """The number of geometry updates at or before ``step``: the body's mesh there (0: as built)."""
        return int(np.searchsorted(self.removed_rows, self.step_index(step), side="right"))

    def body_coordinates(self, step: int) -> np.ndarray | None:
        """The vertices (nv, d) of the body at ``step``: its mesh moved by the geometry updates at or before the step.

        None while the geometry never moved (the discretization's mesh is the body's).  After k updates the
        body is mesh k (0: as built), kept (:attr:`meshes`) for the frames that show it; the last (the
        discretization's) always.  A run's other meshes are made again from the first k updates' wear
        (:meth:`~ngwear.numerics.recession.Recession.after`); a result read from its files has only the frames'.
        """
        if not len(self.removed_rows):
            return None
        k = self.updates_by(step)
        if k not in self.meshes and self.recession is not None:
            return self.recession.after(self.removed[:k])
        if k not in self.meshes:
            raise KeyError(f"the body's mesh at step {step} (after {k} geometry updates) was not kept; the frames' "
                           f"steps: {self.stored_steps}")
        return self.meshes[k]

    @property
    def thickness(self) -> np.ndarray:
        """The worn region's thickness along ν under each contact point, measured once on the mesh as built (n,).

        See :func:`ngwear.numerics.thickness.thickness`; read back from ``result.npz`` (and checkpoints).
        """
        if self.measured is None:
            from ..numerics.thickness import thickness
            disc = self._disc()
            self.measured = thickness(disc.mesh, self.contact_points, disc.condensation.nu)
        return self.measured

    def remaining_thickness_of(self, total_wear: np.ndarray) -> np.ndarray:
        """The thickness left under each point after the wear ``total_wear`` (any leading shape)."""
        return self.thickness - total_wear

    @property
    def stored_steps(self) -> list[int]:
        """The frames: for each output time up to the last step's, the step nearest to it; and the last step."""
        if self.steps < 0:
            return []
        out, end = self.scene.output, self.times[-1]
        wanted = output_times(out, self.times, end)
        wanted = wanted[wanted <= end * (1 + 1e-12)]
        right = np.minimum(np.searchsorted(self.times, wanted), self.steps)       # the nearest step, the earlier on a tie
        left = np.maximum(right - 1, 0)
        nearest = np.where(np.abs(self.times[left] - wanted) <= np.abs(self.times[right] - wanted), left, right)
        return sorted({int(j) for j in nearest} | {self.steps})

    def displacement(self, step: int) -> np.ndarray:
        """DOF vector of u at a step, recovered with one back-substitution and cached.

        u = s_F K⁻¹ f + D δ − K⁻¹ Pᵀ f_c with the step's recorded forces, δ and s_F, plus K⁻¹ f_th of the step's
        temperature where a region expands (:class:`~ngwear.numerics.expansion.ThermalLoad`).
        """
        step = self.step_index(step)
        if step not in self.fields:
            disc = self.discretization
            if disc is None:
                raise KeyError(f"step {step} was not stored; stored steps: {sorted(self.fields)}")
            u = disc.recover(self.forces[step], self.load_factor[step], self.plate_displacement[step])
            load = self._thermal_load(disc)
            if load is not None and step not in self.temperatures:
                raise KeyError(f"step {step}: its temperature was not kept (the frames': {sorted(self.temperatures)})")
            self.fields[step] = u if load is None else u + disc.elastic.operator.solve(load(self.temperatures[step]))
        return self.fields[step]

    def _thermal_load(self, disc):
        """f_th's G on ``disc`` (None: no temperature, or no region expands).

        A run keeps the G of the discretization in force (:attr:`thermal`, assembled on its mesh as it was when it
        came into force: a geometry update moves the vertices of the mesh it shares with the next); a result read
        from its files assembles G on its saved mesh.
        """
        if self.scene.heat.model == "none":
            return None
        if self.thermal is None or self.thermal[0] is not disc:
            load = ThermalLoad(self.scene, disc.fes, ngs.H1(disc.mesh, order=1))
            self.thermal = (disc, load if load.matrix is not None else None)
        return self.thermal[1]

    def displacement_at(self, points, step: int) -> np.ndarray:
        """U at reference points of the body (shape (m, d)) at a step; shape (m, d)."""
        disc = self._disc()
        gf = disc.gridfunction(self.displacement(step))
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        return np.asarray(gf(disc.locate(pts))).reshape(len(pts), -1)

    def _disc(self):
        if self.discretization is None:
            raise RuntimeError("this result has no mesh attached")
        return self.discretization

    def arrays(self) -> dict[str, np.ndarray]:
        """Everything of the run as named arrays (``result.npz``): its steps and :meth:`header`."""
        return {**self.header(), **self.rows}

    def header(self) -> dict[str, np.ndarray]:
        """Everything of the run but its per-step rows: points, weights, Newton records, status."""
        return {"contact_points": self.contact_points, "weights": self.weights,
                **{name: getattr(self, name) for name in COEFFICIENTS}, **records_to_arrays(self.newton),
                "status": np.array(self.status), "wall_time": np.array(self.wall_time),
                "solve_time": np.array(self.solve_time),
                "rejected": np.array(self.rejected), "warnings": np.array(self.warnings, dtype=str),
                "jumped": self.jumped, "thickness": self.thickness, "removed_rows": self.removed_rows,
                **{name: getattr(self, name) if len(self.removed_rows) else np.zeros((0, len(self.weights)))
                   for name in ("removed", "moved_weights")},
                "provenance": np.array(canonical(self.provenance))}

    def save(self, directory) -> Path:
        """Write result.npz, scene.json, mesh.vol, history.csv, summary.json, stops.csv and the VTU/PVD series.

        See :func:`ngwear.results.files.save`.
        """
        return save(self, directory)


def output_times(out, times: np.ndarray, end: float) -> np.ndarray:
    """The output times up to ``end`` (and half an ``output.every`` beyond) that can be nearest to one of ``times``.

    ``output.times``, or the multiples k·every next to each of ``times``: the multiples nearest to a step lie on
    either side of its time, so no list of all T/every of them is made (a non-finite k, T/every > 1e308, drops).
    """
    if out.times is not None:
        return np.asarray(out.times)
    k = np.unique(np.floor(times / out.every)[:, None] + np.arange(-1, 3))
    return k[(k >= 0) & (k < np.ceil((end + 0.5 * out.every) / out.every))] * out.every


def load_result(directory) -> Result:
    """Read a result that :meth:`Result.save` wrote.

    Parameters
    ----------
    directory : str or Path
        The run's output folder (``result.npz``, ``scene.json`` and ``mesh.vol``).

    Returns
    -------
    Result
        The run with its discretization on the saved mesh (without ``mesh.vol``: none); ``displacement`` is
        stored for its frames and recovered for the other steps.

    Raises
    ------
    FileNotFoundError
        ``directory`` holds no ``result.npz``.
    FolderError
        ``result.npz`` lacks a key that :meth:`Result.save` writes, or ``mesh.vol`` is not the mesh the result was
        computed on.
    """
    src = Path(directory)
    if not (src / "result.npz").is_file():
        raise FileNotFoundError(f"{src}: no result.npz (not a saved ngwear result)")
    data = read_arrays(src / "result.npz", "directory")
    try:
        scene = Scene.from_dict(json.loads((src / "scene.json").read_text(encoding="utf-8")))
    except (OSError, ValueError, TypeError, RecursionError) as err:
        raise FolderError("directory", f"{src / 'scene.json'} is missing or damaged ({err})") from None
    meshed = ("mesh_sha256", "frame_coordinates") if (src / "mesh.vol").is_file() else ()   # saved with its mesh
    missing = [key for key in (*HEADER, *recorded(scene), "field_steps", "fields", *meshed) if key not in data]
    if missing:
        raise FolderError("directory", f"{src / 'result.npz'} is damaged or not a result of ngwear (no "
                                       f"{', '.join(missing)})")
    result = from_arrays(scene, data, saved_discretization(scene, src, data))
    result.fields = {int(s): f for s, f in zip(data["field_steps"], data["fields"])}
    if meshed and len(data["frame_coordinates"]):
        result.meshes = {result.updates_by(int(s)): x for s, x in zip(data["field_steps"], data["frame_coordinates"])}
    if "temperature_fields" in data:
        result.temperatures = {int(s): f for s, f in zip(data["field_steps"], data["temperature_fields"])}
    return result


def recorded(scene: Scene) -> tuple[str, ...]:
    """The rows a run of ``scene`` records: :data:`ARRAYS`, the heat's only with a temperature (see ``StepField.when``)."""
    return tuple(f.name for f in RECORDED if f.recorded_in(scene))


def row_shapes(scene: Scene, disc) -> dict[str, tuple]:
    """The shape of one step's row of each of the scene's recorded fields (:func:`recorded`)."""
    sizes = {"n": disc.points.n, "d": scene.dim, "r": disc.condensation.plate_modes_count}
    return {f.name: f.size(sizes) for f in RECORDED if f.recorded_in(scene)}


def from_arrays(scene: Scene, data, disc, rows: dict[str, np.ndarray] | None = None) -> Result:
    """The result that :meth:`Result.arrays` wrote (or :meth:`Result.header` and the ``rows``), on ``disc``."""
    rows = {name: np.array(data[name]) for name in recorded(scene)} if rows is None else rows
    coefficients = (np.array(data[name]) for name in COEFFICIENTS)
    return Result(scene, data["contact_points"], data["weights"], rows, *coefficients, newton=records_from_arrays(data),
                  status=str(data["status"]), wall_time=float(data["wall_time"]), solve_time=float(data["solve_time"]),
                  warnings=[str(w) for w in data["warnings"]], rejected=int(data["rejected"]),
                  discretization=disc, provenance=json.loads(str(data["provenance"])),
                  jumped=np.array(data["jumped"], dtype=int), measured=np.array(data["thickness"]),
                  removed_rows=np.array(data["removed_rows"], dtype=int), removed=np.array(data["removed"]),
                  moved_weights=np.array(data["moved_weights"]))


def _row(name: str):
    def read(self) -> np.ndarray:
        if name not in self.rows:
            raise AttributeError(f"{name}: not recorded by this run (see ngwear.results.step_fields: heat.model)")
        return self.rows[name]
    return read


for _field in RECORDED:     # result.times, result.wear, …: the recorded rows, as declared
    setattr(Result, _field.name, property(_row(_field.name), doc=f"{_field.doc}, shape {_field.shown}."))
for _name, _quantity in QUANTITIES.items():     # result.torque, result.total_wear, …: derived from the rows
    setattr(Result, _name, property(_quantity, doc=_quantity.__doc__ or _DOCS.get(_name)))
for _name, _view in VIEWS.items():              # result.summary(), result.to_dataframe(): the record's views
    setattr(Result, _name, _view)
