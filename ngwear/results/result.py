"""Result of a run: per-step contact-point arrays, Newton records and displacement fields.

Arrays of shape (steps + 1, n_c) over the contact points (fewer rows if the run stopped early):
``wear`` w, ``normal_displacement`` u_ν, ``pressure`` p(u_ν − d₀ − w), ``reaction`` λ (the
constraint multiplier, a traction like the pressure); ``plate_displacement`` δ (steps + 1, r) of a
rigid plate (its translation along ν, then its tilts; r = 0 without a plate).  What an engineer
reads off a part, one value
per step, with m_i the nodal weights of the contact points:

* ``normal_force``  Σ m_i (p_i + λ_i), the force the foundation carries;
* ``torque``  T = Σ m_i μ p_i ((x_i − c) × n*_i)·e, the friction moment about the counterface's axis
  (negative: it opposes the rotation; see :mod:`ngwear.model.kinematics`);
* ``contact_area``  Σ m_i over the points with p_i + λ_i > 0;
* ``wear_volume``  Σ m_i w_i, the worn volume (area in 2D).

``save(dir)`` writes ``result.npz`` (these names as keys), ``scene.json``, ``mesh.vol`` and a
VTU/PVD series of the stored steps; :func:`load_result` reads them back.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..model.kinematics import Slip
from ..model.scene import Scene
from ..numerics.forms import initial_distance
from ..numerics.solver import NewtonRecord

ARRAYS = ("times", "wear", "normal_displacement", "pressure", "reaction", "forces", "plate_displacement")
PART = ("normal_force", "torque", "contact_area", "wear_volume")


@dataclass
class Result:
    """What a run produced; see the module docstring for the array layout."""

    scene: Scene
    contact_points: np.ndarray
    weights: np.ndarray
    times: np.ndarray
    wear: np.ndarray
    normal_displacement: np.ndarray
    pressure: np.ndarray
    reaction: np.ndarray
    forces: np.ndarray
    plate_displacement: np.ndarray
    newton: list[NewtonRecord] = field(default_factory=list)
    status: str = "completed"
    warnings: list[str] = field(default_factory=list)
    wall_time: float = 0.0
    fields: dict[int, np.ndarray] = field(default_factory=dict)
    discretization: object = field(default=None, repr=False)
    _buffers: dict = field(default_factory=dict, repr=False)

    @classmethod
    def empty(cls, scene: Scene, disc) -> Result:
        """A result with room for every step; the public arrays are views of the completed rows."""
        rows, n, d = scene.time.steps + 1, disc.points.n, scene.dim
        shapes = {"times": (rows,), "forces": (rows, n, d), "plate_displacement": (rows, disc.plate_modes_count)}
        buffers = {name: np.zeros(shapes.get(name, (rows, n))) for name in ARRAYS}
        result = cls(scene, disc.points.coords, disc.points.weights,
                     *(buf[:0] for buf in buffers.values()), discretization=disc)
        result._buffers = buffers
        return result

    def append(self, t, w, s, p, lam, forces, delta, record: NewtonRecord) -> None:
        """Record step j = number of steps so far."""
        j = len(self.times)
        for name, value in zip(ARRAYS, (t, w, s, p, lam, forces, delta)):
            self._buffers[name][j] = value
            setattr(self, name, self._buffers[name][:j + 1])
        self.newton.append(record)

    def fail(self, message: str, record: NewtonRecord) -> None:
        self.status = message
        self.newton.append(record)

    @property
    def completed(self) -> bool:
        return self.status == "completed"

    @property
    def steps(self) -> int:
        """Index of the last completed step."""
        return len(self.times) - 1

    @property
    def compression(self) -> np.ndarray:
        """u_ν − d₀ − w: how far the remaining (unworn) layer is compressed (p acts where > 0)."""
        return self.normal_displacement - self.d0[None, :] - self.wear

    @property
    def normal_force(self) -> np.ndarray:
        """Σ m_i (p_i + λ_i) per step."""
        return (self.pressure + self.reaction) @ self.weights

    @property
    def torque(self) -> np.ndarray:
        """Friction moment about the counterface's axis per step (negative when it brakes a rotation)."""
        slip = Slip(self.scene.foundation, self.contact_points, self.scene.contact.direction)
        arms = np.array([slip.moment_arms(t) for t in self.times]).reshape(len(self.times), -1)
        return self.scene.contact.friction * (self.pressure * arms) @ self.weights

    @property
    def contact_area(self) -> np.ndarray:
        """Σ m_i over the points in contact (p_i + λ_i > 0) per step."""
        return (self.pressure + self.reaction > 0) @ self.weights

    @property
    def wear_volume(self) -> np.ndarray:
        """Σ m_i w_i per step: the worn volume (an area in 2D)."""
        return self.wear @ self.weights

    @property
    def d0(self) -> np.ndarray:
        """Initial distance d₀ to the foundation at the contact points."""
        return initial_distance(self.contact_points, self.scene.contact.direction)

    @property
    def stored_steps(self) -> list[int]:
        """Steps written with full fields: every ``output.every``-th and the last completed."""
        every = self.scene.output.every
        return sorted(set(range(0, self.steps + 1, every)) | {self.steps}) if self.steps >= 0 else []

    def displacement(self, step: int) -> np.ndarray:
        """DOF vector of u at a step, recovered with one back-substitution and cached."""
        step = range(self.steps + 1)[step]
        if step not in self.fields:
            if self.discretization is None:
                raise KeyError(f"step {step} was not stored; stored steps: {sorted(self.fields)}")
            self.fields[step] = self.discretization.recover(self.forces[step], self.times[step],
                                                            self.plate_displacement[step])
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
        """Key numbers of the run (what ``ngwear run`` prints)."""
        g = self.scene.contact.gap
        its = [r.iterations for r in self.newton if r.converged]
        # the paper's "penetration": how far Γ_C has moved into the layer, u_ν − d₀ ≤ g
        pen = self.normal_displacement - self.d0[None, :] if len(self.times) else np.zeros((1, 1))
        last = -1
        part = {name: float(getattr(self, name)[last]) if len(self.times) else 0.0 for name in PART}
        return {
            "status": self.status,
            "steps": self.steps,
            "contact_points": len(self.weights),
            "max_wear": float(self.wear.max(initial=0.0)),
            "max_penetration": float(pen.max(initial=0.0)),
            "gap": g,
            **part,
            **({"plate_displacement": float(self.plate_displacement[last, 0])}
               if self.plate_displacement.shape[1] and len(self.times) else {}),
            "contact_fraction": float((self.pressure[last] > 0).mean()) if len(self.times) else 0.0,
            "active_fraction": float((self.reaction[last] > 0).mean()) if len(self.times) else 0.0,
            "newton_iterations_total": int(sum(its)),
            "newton_iterations_max": int(max(its, default=0)),
            "wall_time_s": round(self.wall_time, 3),
        }

    def save(self, directory) -> Path:
        """Write result.npz, scene.json, mesh.vol, summary.json and a VTU/PVD series."""
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        steps = self.stored_steps
        fields = np.array([self.displacement(s) for s in steps]) if self.discretization else np.zeros((0, 0))
        np.savez_compressed(
            out / "result.npz", contact_points=self.contact_points, weights=self.weights,
            **{name: getattr(self, name) for name in ARRAYS + PART},
            newton_iterations=np.array([r.iterations for r in self.newton]),
            newton_converged=np.array([r.converged for r in self.newton]),
            newton_active=np.array([r.active for r in self.newton]),
            newton_residuals=np.array([r.residuals[-1] if r.residuals else np.nan for r in self.newton]),
            field_steps=np.array(steps, dtype=int), fields=fields,
            status=np.array(self.status), wall_time=np.array(self.wall_time))
        (out / "scene.json").write_text(json.dumps(self.scene.to_dict(), indent=2))
        (out / "summary.json").write_text(json.dumps(self.summary(), indent=2))
        if self.discretization is not None:
            self.discretization.mesh.ngmesh.Save(str(out / "mesh.vol"))
            from .vtk import write_series
            write_series(self, out)
        return out


def load_result(directory) -> Result:
    """Read a saved result; ``displacement_at`` works for its stored steps."""
    src = Path(directory)
    if not (src / "result.npz").is_file():
        raise FileNotFoundError(f"{src}: no result.npz (not a saved ngwear result)")
    data = np.load(src / "result.npz")
    scene = Scene.from_dict(json.loads((src / "scene.json").read_text()))
    newton = [NewtonRecord(bool(c), int(i), [float(r)], int(a)) for i, c, a, r in zip(
        data["newton_iterations"], data["newton_converged"], data["newton_active"], data["newton_residuals"])]
    disc = None
    if (src / "mesh.vol").is_file():
        import netgen.meshing
        import ngsolve as ngs

        from ..numerics.discrete import Discretization
        ngmesh = netgen.meshing.Mesh(dim=scene.dim)
        ngmesh.Load(str(src / "mesh.vol"))
        disc = Discretization(scene, ngs.Mesh(ngmesh))
    result = Result(scene, data["contact_points"], data["weights"],
                    *(data[name] for name in ARRAYS), newton=newton, status=str(data["status"]),
                    wall_time=float(data["wall_time"]),
                    fields={int(s): f for s, f in zip(data["field_steps"], data["fields"])},
                    discretization=disc)
    return result

