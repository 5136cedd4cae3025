"""Result of a run: per-step contact-point arrays, Newton records and displacement fields.

Arrays of shape (steps + 1, n_c) over the contact points (fewer rows if the run stopped early;
``times`` t_j need not be uniform, see ``time.adaptive``):
``wear`` w, ``normal_displacement`` u_ν, ``pressure`` p(u_ν − d₀ − w), ``reaction`` λ (the
constraint multiplier, a traction like the pressure); ``plate_displacement`` δ (steps + 1, r) of a
rigid plate (its translation along ν, then its tilts; r = 0 without a plate).  What an engineer
reads off a part, one value per step, with m_i the nodal weights of the contact points:

* ``normal_force``  Σ m_i (p_i + λ_i), the force the foundation carries;
* ``torque``  T = Σ m_i μ p_i ((x_i − c) × n*_i)·e, the friction moment about the counterface's axis
  (negative: it opposes the rotation; see :mod:`ngwear.model.kinematics`);
* ``tangential_force``  F_t = Σ m_i μ_i p_i n*_i (steps + 1, d), the friction force on the foundation (against
  its slip), ``friction_force`` ‖F_t‖ and ``apparent_friction`` ‖F_t‖ / normal force (0 where that is 0; it is
  μ where every point slides one way and none is held at the bound, less on a turning counterface);
* ``contact_area``  Σ m_i over the points with p_i + λ_i > 0;
* ``wear_volume``  Σ m_i w_i, the worn volume (area in 2D).

The contact coefficients at the points, shape (n_c,): ``friction_coefficient`` μ_i, ``wear_coefficient`` κ_i and
``contact_stiffness`` L_i (numbers or fields of the scene, as evaluated there).  The per-step fields are declared in
:mod:`ngwear.results.step_fields`; a run records its rows through a :class:`~ngwear.results.recording.Recording`.

Full displacement fields are kept for the frames (``stored_steps``): the steps nearest to the
output times (``output.every`` apart from t = 0, or ``output.times``) and the last step, so that the
number of frames does not grow with the number of steps.  ``save(dir)`` writes ``result.npz``
(these names as keys, with the Newton records), ``scene.json``, ``summary.json``, ``mesh.vol`` and
a VTU/PVD series of the frames (with each cell's region), each file written under a temporary name and then renamed, so that
an interrupt never leaves half a file; :func:`load_result` reads them back.  A scene in SI (``units``) adds
the unit of every number (:mod:`ngwear.results.units`) to ``summary.json`` and ``result.npz``.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.integrate import cumulative_trapezoid

from ..model.kinematics import Slip
from ..model.programme import Schedule
from ..model.scene import Scene
from ..numerics.points import initial_distance
from ..numerics.solver import NewtonRecord
from ..numerics.topology import coordinates
from .folder import FolderError, replacing
from .mesh_file import keep_mesh, saved_discretization
from .provenance import canonical
from .records import records_from_arrays, records_to_arrays
from .step_fields import DERIVED, RECORDED
from .summary import summary
from .table import to_dataframe, write_history
from .units import units

ARRAYS = tuple(f.name for f in RECORDED if f.when is None)
"""The rows every run records (:data:`~ngwear.results.step_fields.RECORDED`; :func:`recorded`: those of a scene)."""
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
        the area in contact and the worn volume (properties; ``tangential_force`` is F_t itself, (N, d)).
    max_wear, max_pressure, mean_pressure, friction_power, dissipated_energy : ndarray
        Per step (N,): max w, max p, normal force / contact area, P = Σ m μ p ‖v*‖ and ∫₀ᵗ P dt (properties).
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
    recording : Recording or None
        How the run recorded itself (its rows' storage and its warm start: a checkpoint needs them); None when read
        from files.
    meshes : dict of int to ndarray
        ``wear.geometry = "surface"``: the vertices (nv, d) of the body after k geometry updates, kept for the meshes
        the frames show (:meth:`body_coordinates`).
    provenance : dict or None
        ``ngwear``, ``ngsolve``, ``python``: the versions that computed it; ``scene_sha256``: the SHA-256 of its
        scene's canonical JSON (:mod:`ngwear.results.provenance`).  Every run records it; None for a Result made by hand.
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
    recording: object = field(default=None, repr=False)          # the run's Recording: its rows, to go on from
    heating: object = field(default=None, repr=False)            # the run's Heating: thermal expansion's displacement
    surface: object = field(default=None, repr=False)            # the run's Surface ("surface"): a checkpoint keeps it
    mesh_digest: str | None = field(default=None, repr=False)   # SHA-256 of the mesh.vol written for it
    provenance: dict | None = field(default=None, repr=False)    # versions and scene hash (None: not made by a run)
    jumped: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int), repr=False)
    measured: np.ndarray | None = field(default=None, repr=False)   # the worn region's thickness (see thickness)
    removed_rows: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int), repr=False)
    removed: np.ndarray | None = field(default=None, repr=False)      # (U, n): each geometry update's W at the points
    moved_weights: np.ndarray | None = field(default=None, repr=False)  # (U, n): m_i after each update
    meshes: dict[int, np.ndarray] = field(default_factory=dict, repr=False)   # k: the vertices after k updates

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

    @property
    def compression(self) -> np.ndarray:
        """u_ν − d₀ − w: how far the remaining (unworn) layer is compressed (p acts where > 0)."""
        return self.penetration - self.wear

    @property
    def penetration(self) -> np.ndarray:
        """u_ν − d₀: how far Γ_C has moved into the layer (≤ g); d₀ of the face as it is (moved by the updates)."""
        reached = self.normal_displacement - self.d0[None, :]
        return reached - (self.total_wear - self.wear) if len(self.removed_rows) else reached

    @property
    def normal_force(self) -> np.ndarray:
        """Σ m_i (p_i + λ_i) per step."""
        return _weighted(self.pressure + self.reaction, self.row_weights)

    def _factors(self) -> tuple[Slip, np.ndarray]:
        """The slip at the points and the factor s_v of each step (a programme's: of the step's place in its stop)."""
        slip = Slip(self.scene.foundation, self.contact_points, self.scene.contact.direction)
        if self.scene.programme is not None:
            return slip, np.asarray(Schedule.of(self.scene.programme).row_factors(self.jumped, len(self.times))[0],
                                    dtype=float)
        return slip, np.array([slip.factor(t) for t in self.times], dtype=float)

    @property
    def torque(self) -> np.ndarray:
        """Friction moment about the counterface's axis per step (negative when it brakes a rotation)."""
        slip, factors = self._factors()
        return np.sign(factors) * _weighted(self.pressure, self.friction * slip.moment_arms() * self.row_weights)

    @property
    def tangential_force(self) -> np.ndarray:
        """F_t = Σ m_i μ_i p_i n*_i per step, shape (steps + 1, d): the friction force on the foundation."""
        slip, factors = self._factors()
        return np.sign(factors)[:, None] * ((self.pressure * self.friction * self.row_weights) @ slip.direction)

    @property
    def max_wear(self) -> np.ndarray:
        """max_i w_i per step."""
        return self.wear.max(axis=1, initial=0.0)

    @property
    def max_pressure(self) -> np.ndarray:
        """max_i p_i per step."""
        return self.pressure.max(axis=1, initial=0.0)

    @property
    def mean_pressure(self) -> np.ndarray:
        """Normal force / contact area per step (0 where nothing touches)."""
        area = self.contact_area
        return np.divide(self.normal_force, area, out=np.zeros_like(area), where=area > 0)

    @property
    def friction_power(self) -> np.ndarray:
        """P = Σ m_i μ_i p_i ‖v*_i(t)‖ per step (‖v*_i(t)‖: the slip speed at s_v = 1 times the factor's size)."""
        slip, factors = self._factors()
        return np.abs(factors) * _weighted(self.pressure, self.friction * slip.speed * self.row_weights)

    @property
    def dissipated_energy(self) -> np.ndarray:
        """∫₀^{t_j} P dt per step, by the trapezoidal rule over the steps."""
        power = self.friction_power
        return cumulative_trapezoid(power, self.times, initial=0.0) if len(power) else power

    @property
    def friction(self) -> np.ndarray:
        """μ_i of each step, shape (N, n) or (1, n) (coefficients fixed for the run: ``friction_coefficient``)."""
        return self.rows["step_friction"] if "step_friction" in self.rows else self.friction_coefficient[None, :]

    @property
    def friction_force(self) -> np.ndarray:
        """‖F_t‖ per step."""
        return np.linalg.norm(self.tangential_force, axis=1)

    @property
    def apparent_friction(self) -> np.ndarray:
        """‖F_t‖ / Σ m_i (p_i + λ_i) per step; 0 where the normal force is 0."""
        normal = self.normal_force
        return np.divide(self.friction_force, normal, out=np.zeros_like(normal), where=normal > 0)

    @property
    def contact_area(self) -> np.ndarray:
        """Σ m_i over the points in contact (p_i + λ_i > 0) per step."""
        return _weighted(self.pressure + self.reaction > 0, self.row_weights)

    @property
    def wear_volume(self) -> np.ndarray:
        """Σ m_i w_i per step: the worn volume (an area in 2D)."""
        return _weighted(self.total_wear, self.row_weights)

    @property
    def total_wear(self) -> np.ndarray:
        """All material removed at the contact points per step: w plus what the geometry updates moved into the body.

        ``wear.geometry = "layer"``: w.  ``"surface"``: w (the wear since the last update) + Σ W of the updates at or
        before the step (:attr:`removed`, at :attr:`removed_rows`).
        """
        if not len(self.removed_rows):
            return self.wear
        moved = np.zeros_like(self.wear)
        np.add.at(moved, self.removed_rows, self.removed)
        return self.wear + np.cumsum(moved, axis=0)

    def total_wear_at(self, step: int) -> np.ndarray:
        """``total_wear`` of one step alone (O(n): what the time loop reads after each step)."""
        step = self.step_index(step)
        if not len(self.removed_rows):
            return self.wear[step]
        return self.wear[step] + self.removed[self.removed_rows <= step].sum(axis=0)

    def last_total_wear(self) -> np.ndarray:
        """``total_wear`` of the last step."""
        return self.total_wear_at(-1)

    @property
    def row_weights(self) -> np.ndarray:
        """m_i of each step, (N, n), or of all (n,) while the geometry never moved: an update moves them."""
        if not len(self.removed_rows):
            return self.weights
        rows = np.searchsorted(self.removed_rows, np.arange(len(self.times)), side="left")   # updates before each
        return np.vstack([self.weights, self.moved_weights])[rows]

    @property
    def geometry_updates(self) -> int:
        """The number of geometry updates (``wear.geometry = "surface"``)."""
        return len(self.removed_rows)

    def updates_by(self, step: int) -> int:
        """The number of geometry updates at or before ``step``: the body's mesh there (0: as built)."""
        return int(np.searchsorted(self.removed_rows, self.step_index(step), side="right"))

    def body_coordinates(self, step: int) -> np.ndarray | None:
        """The vertices (nv, d) of the body at ``step``: its mesh moved by the geometry updates at or before the step.

        None while the geometry never moved (the discretization's mesh is the body's).  After k updates the
        body is mesh k (0: as built), kept (:attr:`meshes`) for the frames that show it; the last (the
        discretization's) always.  A run's other meshes are made again from the first k updates' wear
        (:meth:`~ngwear.numerics.motion.Recession.after`); a result read from its files has only the frames'.
        """
        if not len(self.removed_rows):
            return None
        k = self.updates_by(step)
        if k not in self.meshes and self.surface is not None and self.surface.recession is not None:
            return self.surface.recession.after(self.removed[:k])
        if k not in self.meshes:
            raise KeyError(f"the body's mesh at step {step} (after {k} geometry updates) was not kept; the frames' "
                           f"steps: {self.stored_steps}")
        return self.meshes[k]

    def moved(self, realised: np.ndarray, disc, before: np.ndarray) -> None:
        """A geometry update after the last step: its wear W at the points leaves the layer for the body (on ``disc``).

        The mesh in force until now (its vertices ``before``) is kept if a frame since the last update shows it (and
        ``disc``'s, in force from this step, until the next update tells), and the displacement of those frames and
        of this step (a frame, or not: the next steps tell) is recovered on the discretization it was solved on,
        before ``disc`` replaces it.
        """
        start, k = (self.removed_rows[-1] if len(self.removed_rows) else 0), len(self.removed_rows)
        frames = [j for j in self.stored_steps if start <= j < self.steps]    # exact: no later step is nearer
        if frames:
            self.meshes[k] = before
        else:
            self.meshes.pop(k, None)
        self.meshes[k + 1] = coordinates(disc.mesh)
        for j in [j for j in self.fields if start <= j < self.steps and j not in frames]:
            del self.fields[j]                          # the last update's step, no frame after all
        for j in [*frames, self.steps]:
            self.displacement(j)
        w = np.maximum(self.wear[-1] - realised, 0.0)
        self.removed = np.vstack([self.removed, realised]) if len(self.removed_rows) else realised[None, :].copy()
        self.removed_rows = np.append(self.removed_rows, self.steps)
        self.moved_weights = np.vstack([self.moved_weights, disc.points.weights]) if self.moved_weights is not None \
            else disc.points.weights[None, :].copy()
        self.recording.revise("wear", w)
        self.discretization, self.mesh_digest = disc, None

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
    def remaining_thickness(self) -> np.ndarray:
        """The worn region's thickness along ν under each contact point minus ``total_wear``, per step."""
        return self.remaining_thickness_of(self.total_wear)

    @property
    def stops(self):
        """One row per stop of the programme (a pandas DataFrame; None without a programme).

        See :func:`ngwear.results.stops.stop_table`.
        """
        from .stops import stop_table
        return stop_table(self) if self.scene.programme is not None else None

    @property
    def d0(self) -> np.ndarray:
        """Initial distance d₀ to the foundation at the contact points."""
        return initial_distance(self.contact_points, self.scene.contact.direction)

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
        """DOF vector of u at a step, recovered with one back-substitution and cached."""
        step = self.step_index(step)
        if step not in self.fields:
            if self.discretization is None:
                raise KeyError(f"step {step} was not stored; stored steps: {sorted(self.fields)}")
            u = self.discretization.recover(self.forces[step], self.times[step], self.plate_displacement[step])
            thermal = None if self.heating is None else self.heating.displacement(self.temperatures[step])
            self.fields[step] = u if thermal is None else u + thermal
        return self.fields[step]

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

    def summary(self) -> dict:
        """Key numbers of the run (what ``ngwear run`` prints): see :func:`ngwear.results.summary.summary`."""
        return summary(self)

    def to_dataframe(self):
        """The run's per-step numbers, one row per step, as a pandas DataFrame: the table of ``history.csv``.

        Its columns (:mod:`ngwear.results.table`): ``step``, ``times``, every per-step number (``torque``, …), the
        components of the short vectors, ``newton_iterations``; with the unit in their names in a scene in SI
        (``torque [N m]``).
        """
        return to_dataframe(self)

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
        """Write result.npz, scene.json, mesh.vol, history.csv, summary.json and a VTU/PVD series of the frames."""
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        steps = self.stored_steps
        fields = np.array([self.displacement(s) for s in steps]) if self.discretization else np.zeros((0, 0))
        mesh = {"mesh_sha256": np.array(keep_mesh(self, out))} if self.discretization is not None else {}
        arrays = {**self.arrays(), **{f.name: getattr(self, f.name) for f in DERIVED},
                  "field_steps": np.array(steps, dtype=int), "fields": fields, **mesh, **self._temperature_fields(steps)}
        if self.discretization is not None:                 # the worn body of each frame ("surface")
            arrays["frame_coordinates"] = (np.array([self.body_coordinates(s) for s in steps]) if self.geometry_updates
                                           else np.zeros((0, 0, self.scene.dim)))
        if self.scene.units:
            arrays["units"] = np.array(json.dumps(units(self.scene, arrays), ensure_ascii=False))
        with replacing(out / "result.npz") as tmp:
            np.savez(tmp, **arrays)                 # not compressed: zlib costs far more time than it saves space

        with replacing(out / "scene.json") as tmp:
            tmp.write_text(json.dumps(self.scene.to_dict(), indent=2))
        write_history(self, out / "history.csv")
        with replacing(out / "summary.json") as tmp:
            tmp.write_text(json.dumps(self.summary(), indent=2, ensure_ascii=False), encoding="utf-8")
        if self.scene.programme is not None:
            with replacing(out / "stops.csv") as tmp:
                self.stops.to_csv(tmp)
        if self.discretization is not None:
            from .vtk import write_series
            write_series(self, out)
        return out


    def _temperature_fields(self, steps) -> dict[str, np.ndarray]:
        """The nodal temperature (P1) of the frames, ``temperature_fields`` (with ``heat``; none else)."""
        if self.scene.heat.model == "none" or not all(s in self.temperatures for s in steps):
            return {}
        return {"temperature_fields": np.array([self.temperatures[s] for s in steps])}


def _weighted(values: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Σ_i values_ji m_i of each step j: one set of weights (n,) or (1, n), or a row per step (N, n)."""
    if weights.ndim == 1 or len(weights) == 1:
        return values @ weights.reshape(-1)
    return np.einsum("ji,ji->j", values, weights)


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
    data = np.load(src / "result.npz")
    scene = Scene.from_dict(json.loads((src / "scene.json").read_text()))
    meshed = ("mesh_sha256", "frame_coordinates") if (src / "mesh.vol").is_file() else ()   # saved with its mesh
    missing = [key for key in (*HEADER, *recorded(scene), "field_steps", "fields", *meshed) if key not in data.files]
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
