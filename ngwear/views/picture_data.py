"""The arrays of a result's picture: points, the layer's surfaces, colour ranges, the rotor, the camera's bounds.

The picture (paper, Figs. 1–4) in the reference frame with vertical axis e_d (ν = −e_d): the body
is drawn at X + m u(X), X its vertices at the step (``wear.geometry = "surface"``: the mesh the geometry updates at or
before the step moved, as the step's VTU frame shows it).  The rigid foundation's surface stays at x_d = −g and moves
with v*: a block with an arrow for v*, or, for a counterface turning about an axis along ν (a brake disc, the
rotor), a sector of the rotor under the part with an arc arrow for ω.  Under a rigid plate the
body is coloured by its elastic displacement |u − δν| (the plate's translation δ moves it rigidly).
The soft layer is drawn on Γ_C, offset along ν: under a contact point X with displacement u, wear
w and compression r = u_ν − d₀ − w it keeps

    remaining part   from  t = X + m u  to  b = t + ν (g − m w − m r₊)₊,
    worn-away part   from  b  to  b + ν clip(m w, 0, m g),

so the remaining layer is pressed flat on the foundation where r > 0, and the worn part shows the
material the foundation has removed.  ``m`` is ``magnify``.  Each facet of Γ_C becomes one cell of
the layer (a quadrilateral in 2D, a prism in 3D), so flat, curved and CAD contact faces are drawn
alike.  Everything here is plain numpy arrays from the :class:`~ngwear.results.result.Result`, as
``dolfinx.plot`` gives them: :mod:`ngwear.views.render` turns them into pyvista objects.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import ngsolve as ngs
import numpy as np

LAYER_FIELDS = {"displacement": "wear", "wear": "wear", "pressure": "pressure", "region": "wear"}
"""What the layer is coloured by for each ``field`` of a picture (``region`` colours the part by its regions)."""


@dataclass(frozen=True)
class MeshArrays:
    """Reference vertex coordinates, the vertex numbers of the part's elements and of the Γ_C facets.

    ``regions``: each element's region, its index among ``names`` (``mesh.GetMaterials()``: body, backing, …).
    """

    points: np.ndarray
    body: np.ndarray
    facets: np.ndarray
    regions: np.ndarray
    names: tuple[str, ...]

    @classmethod
    def of(cls, mesh: ngs.Mesh) -> MeshArrays:
        names = tuple(mesh.GetMaterials())
        elements = list(mesh.Elements(ngs.VOL))
        body = [[v.nr for v in el.vertices] for el in elements]
        facets = [[v.nr for v in el.vertices] for el in mesh.Elements(ngs.BND) if el.mat == "contact"]
        points = np.array([v.point for v in mesh.vertices])
        return cls(points, np.array(body, dtype=int).reshape(-1, mesh.dim + 1),
                   np.array(facets, dtype=int).reshape(-1, mesh.dim),
                   np.array([names.index(el.mat) for el in elements], dtype=int), names)


@dataclass(frozen=True)
class Scales:
    """Colour ranges shared by every picture of a run, so that frames compare."""

    displacement: float
    wear: float
    pressure: float

    @classmethod
    def of(cls, result, displacements) -> Scales:
        """|u| over the frames, w and p over the run: each colour bar spans its data from 0 (the wear not up to g)."""
        u = max(np.linalg.norm(u, axis=1).max() for u in displacements)
        return cls(_positive(u), _positive(result.wear.max()), _positive(result.pressure.max()))


@dataclass(frozen=True)
class StraightArrow:
    """An arrow from ``start`` along the unit vector ``direction``, ``length`` long (3D points)."""

    start: np.ndarray
    direction: np.ndarray
    length: float


@dataclass(frozen=True)
class ArcArrow:
    """A tube of radius ``thickness`` along the points ``path`` ending in a cone at ``tip``."""

    path: np.ndarray
    tip: np.ndarray
    thickness: float


class PictureData:
    """One run's geometry, colour ranges and view: the arrays a :class:`~ngwear.views.render.Canvas` draws."""

    def __init__(self, result, steps, field: str, magnify: float, mesh: MeshArrays):
        self.result, self.field, self.magnify, self.mesh = result, field, magnify, mesh
        shown = {s: vertex_displacement(result, s) for s in sorted(set(result.stored_steps) | set(steps))}
        self._shown, self._last = shown, (None, None)
        self.scales = Scales.of(result, [elastic(result, s, u) for s, u in shown.items()])
        self.moved = np.array([self.points(s) + magnify * u for s, u in shown.items()])
        self.lo, self.hi = self.moved.min(axis=(0, 1)), self.moved.max(axis=(0, 1))
        self.at_vertices = result.discretization.points.at_vertices

    @property
    def dim(self) -> int:
        return self.result.scene.dim

    def points(self, step: int) -> np.ndarray:
        """The body's vertices X at ``step``: as built, or as the updates at or before it left them ("surface").

        See :meth:`~ngwear.results.result.Result.body_coordinates`.
        """
        moved = self.result.body_coordinates(step)
        return self.mesh.points if moved is None else moved

    def displacement(self, step: int) -> np.ndarray:
        """The displacement at the vertices at ``step``: kept for the picture's steps and the last other one asked."""
        if step in self._shown:
            return self._shown[step]
        if self._last[0] != step:
            self._last = step, vertex_displacement(self.result, step)
        return self._last[1]

    def body(self, step: int) -> tuple[np.ndarray, np.ndarray]:
        """Vertices at X + m u and |u| there (|u − δν| under a plate)."""
        u = self.displacement(step)
        return self.points(step) + self.magnify * u, np.linalg.norm(elastic(self.result, step, u), axis=1)

    def layer(self, step: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Per mesh vertex: the body's surface t, the layer's bottom b, the worn part's bottom, the field (w or p).

        Only the vertices of Γ_C carry meaningful values (see the module docstring).
        """
        result, m, g = self.result, self.magnify, self.result.scene.contact.gap
        at = self.at_vertices
        nu = np.asarray(result.scene.contact.direction)
        top = self.points(step) + m * self.displacement(step)
        wear, squeeze = at @ result.wear[step], np.maximum(at @ result.compression[step], 0.0)
        bottom = top + np.maximum(g - m * wear - m * squeeze, 0.0)[:, None] * nu
        worn = bottom + np.clip(m * wear, 0.0, m * g)[:, None] * nu
        return top, bottom, worn, at @ getattr(result, LAYER_FIELDS[self.field])[step]

    @cached_property
    def rotor(self) -> dict | None:
        """The rotor's sector under the part when the counterface turns about an axis along ν (3D), else None.

        Its radii and angles cover the contact points' with a margin; ``level`` is its surface ν·x.
        """
        scene, motion = self.result.scene, self.result.motion
        nu = np.asarray(scene.contact.direction)
        if self.dim != 3 or not motion.rotating or abs(abs(motion.axis @ nu) - 1) > 1e-9:
            return None
        first = np.cross(nu, np.eye(3)[np.argmin(np.abs(nu))])
        basis = np.array([first / np.linalg.norm(first), np.cross(nu, first / np.linalg.norm(first))])
        arms = (self.result.contact_points - motion.center) @ basis.T
        radius, angle = np.linalg.norm(arms, axis=1), np.unwrap(np.arctan2(arms[:, 1], arms[:, 0]))
        width = max(np.ptp(radius), 0.05 * radius.max())
        turn = max(np.ptp(angle), 3 * width / max(radius.max(), 1e-300))
        level = float((self.result.contact_points @ nu).max()) + scene.contact.gap
        return {"nu": nu, "basis": basis, "level": level,
                "center": motion.center + (level - motion.center @ nu) * nu,
                "radii": (max(radius.min() - 0.3 * width, 0.0), radius.max() + 0.3 * width),
                "angles": (angle.min() - 0.4 * turn, angle.max() + 0.25 * turn), "depth": 0.08 * width,
                "free": angle.min() - 0.05 * turn}

    def rotor_point(self, radius, angle, below=0.0) -> np.ndarray:
        """Points of the rotor at polar coordinates about its axis, ``below`` its surface."""
        r = self.rotor
        radius, angle, below = (a[..., None] for a in np.broadcast_arrays(radius, angle, below))
        return r["center"] + below * r["nu"] + radius * (np.cos(angle) * r["basis"][0] + np.sin(angle) * r["basis"][1])

    def sector(self) -> np.ndarray:
        """The rotor's sector as a structured grid of points, shape (radii, angles, 2 levels, 3)."""
        (r0, r1), (a0, a1) = self.rotor["radii"], self.rotor["angles"]
        r, a, z = np.meshgrid(np.linspace(r0, r1, 8), np.linspace(a0, a1, 64), [0.0, self.rotor["depth"]],
                              indexing="ij")
        return self.rotor_point(r, a, z)

    def box(self) -> tuple:
        """Bounds of the foundation block: below x_d = −g, under the body at every step shown.

        In 3D the block starts just behind the front face (y = y_min) so the worn part stays visible.
        """
        g, dim, lo, hi = self.result.scene.contact.gap, self.dim, self.lo, self.hi
        size = (hi - lo).max()
        depth = max(2 * g, 0.15 * (hi - lo)[dim - 1])
        x0, x1 = lo[0] - 0.05 * size, hi[0] + 0.05 * size
        return ((x0, x1, -g - depth, -g, -0.02, -0.01) if dim == 2
                else (x0, x1, lo[1] + 0.02 * size, hi[1] + 0.05 * size, -g - depth, -g))

    def view(self) -> tuple:
        """(x0, x1, y0, y1) a 2D picture frames: the foundation's block up to the highest point of the body.

        A 3D picture frames :meth:`framed`.
        """
        x0, x1, y0, y1 = self.box()[:4]
        return x0, x1, y0, max(self.hi[-1], y1)

    def framed(self) -> np.ndarray:
        """The points a 3D picture frames: the part, its layer down to the foundation, the motion's arrow and label.

        The part at every step shown, the arrow's path and its label's anchor.  The foundation may run out of the
        picture: it is the ground the part stands on, not what the picture shows.
        """
        nu, g = np.asarray(self.result.scene.contact.direction), self.result.scene.contact.gap
        points = [self.moved.reshape(-1, 3), self.moved[:, np.unique(self.mesh.facets)].reshape(-1, 3) + g * nu]
        for step in self.result.stored_steps:
            motion = self.motion(step)
            if motion is not None:
                shape, where, _ = motion
                points.append(np.vstack([shape.path, shape.tip]) if isinstance(shape, ArcArrow) else
                              np.array([shape.start, shape.start + shape.length * shape.direction]))
                points.append(np.asarray(where)[None])
        return np.vstack(points)

    def motion(self, step: int) -> tuple[StraightArrow | ArcArrow, np.ndarray, str] | None:
        """Arrow, label position and label of the foundation's motion at a step (None when it is at rest)."""
        motion, factor = self.result.motion, float(self.result.speed_factor[step])
        if factor == 0 or not (motion.rotating or np.any(self.result.scene.foundation.velocity)):
            return None
        if self.rotor is not None:
            return self._arc(factor * np.asarray(motion.omega))
        # v* where Γ_C is, at its contact point nearest to the centroid (the translation v₀ s_v if no ω)
        nearest = np.argmin(np.linalg.norm(motion.points - motion.points.mean(axis=0), axis=1))
        v = motion.velocity(factor)[nearest]
        if not v.any():
            return None
        box, dim = self.box(), self.dim
        size, top, bottom = box[1] - box[0], box[2 * dim - 1], box[2 * dim - 2]
        start = np.array([box[0] + 0.05 * size, box[2] - 1e-3, top + 0.7 * (bottom - top)])
        start = start if dim == 3 else start[[0, 2, 1]] * (1, 1, 0)
        direction = xyz(v[None])[0] / np.linalg.norm(v)
        label = "rigid foundation, v* = (" + ", ".join(f"{c:.3g}" for c in v) + ")"
        return StraightArrow(start, direction, 0.2 * size), start + 0.22 * size * direction, label

    def _arc(self, omega: np.ndarray) -> tuple[ArcArrow, np.ndarray, str]:
        """An arc arrow on the rotor in front of the part (the free band of angles below it), turning as ω does."""
        r = self.rotor
        (r0, r1), (a0, _) = r["radii"], r["angles"]
        sense = np.sign(omega @ r["nu"])     # angles turn from e1 to e2 = ν × e1, i.e. counter-clockwise about ν
        start, end = a0 + 0.1 * (r["free"] - a0), r["free"]
        start, end = (start, end) if sense > 0 else (end, start)
        path = self.rotor_point(0.5 * (r0 + r1), np.linspace(start, end, 40), -0.02 * (r1 - r0))
        thickness = 0.02 * (r1 - r0)
        tip = path[-1] + 6 * thickness * (path[-1] - path[-2]) / np.linalg.norm(path[-1] - path[-2])
        label = f"disc, omega = {np.linalg.norm(omega):.3g} rad/s"
        return ArcArrow(path, tip, thickness), path[len(path) // 2] - 0.15 * (r1 - r0) * r["nu"], label

    def caption(self, step: int) -> str:
        return f"t = {self.result.times[step]:.2f} (step {step})"


def elastic(result, step: int, u: np.ndarray) -> np.ndarray:
    """The displacement without the plate's translation, u − δν (u itself without a plate)."""
    if not result.plate_displacement.shape[1]:
        return u
    return u - result.plate_displacement[step, 0] * np.asarray(result.scene.contact.direction)


def vertex_displacement(result, step: int) -> np.ndarray:
    """Displacement at every mesh vertex, shape (nv, d): each component's vertex DOFs (0 off the body)."""
    gf = result.discretization.gridfunction(result.displacement(step))
    nv = result.discretization.mesh.nv
    return np.column_stack([c.vec.FV().NumPy()[:nv] for c in gf.components])


def xyz(points: np.ndarray) -> np.ndarray:
    """Points padded with z = 0 (2D), as VTK takes them."""
    return np.column_stack([points, np.zeros((len(points), 3 - points.shape[1]))])


def _positive(value: float) -> float:
    """A colour-range end that is never zero."""
    return float(value) if value > 0 else 1.0
