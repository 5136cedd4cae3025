"""Off-screen pictures of a result: the deformed body, its soft layer and the moving foundation.

The picture (paper, Figs. 1–4) in the reference frame with vertical axis e_d (ν = −e_d): the body
is drawn at X + m u(X).  The rigid foundation's surface stays at x_d = −g and moves with v*.  Under a
point of Γ_C with displacement u, wear w and compression r = u_ν − d₀ − w, the layer keeps

    remaining part   x_d ∈ [b, t],   t = m u_d,   b = min(t − (g − m w) + m r₊, t),
    worn-away part   x_d ∈ [b − m w, b],

so the remaining layer is pressed flat on the foundation (b = −g) where r > 0, and the worn part,
drawn translucent, shows the material the foundation has removed.  ``m`` is ``magnify``.
The numbers come from the :class:`~ngwear.result.Result`; no numerical module imports this one.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import ngsolve as ngs
import numpy as np
import pyvista as pv
from PIL import Image
from scipy.interpolate import LinearNDInterpolator
from scipy.spatial import Delaunay, cKDTree

pv.OFF_SCREEN = True

LAYER_FIELDS = {"displacement": "wear", "wear": "wear", "pressure": "pressure"}
TITLES = {"displacement": "displacement", "wear": "wear w", "pressure": "pressure p"}
CMAPS = {"displacement": "viridis", "wear": "YlOrRd", "pressure": "plasma"}
BODY_COLOR, FOUNDATION_COLOR, WORN_COLOR = "lightsteelblue", "dimgray", "white"
CELL_TYPES = {(2, 3): pv.CellType.TRIANGLE, (3, 4): pv.CellType.TETRA}


@dataclass(frozen=True)
class _Mesh:
    """Reference vertex coordinates and the vertex numbers of the body's and the layer's elements."""

    points: np.ndarray
    body: np.ndarray
    layer: np.ndarray

    @classmethod
    def of(cls, mesh: ngs.Mesh) -> _Mesh:
        cells = {"body": [], "layer": []}
        for el in mesh.Elements(ngs.VOL):
            cells.setdefault(el.mat, []).append([v.nr for v in el.vertices])
        points = np.array([v.point for v in mesh.vertices])
        return cls(points, *(np.array(cells[name], dtype=int).reshape(-1, mesh.dim + 1)
                             for name in ("body", "layer")))


@dataclass(frozen=True)
class _Scales:
    """Colour ranges shared by every picture of a run, so that frames compare."""

    displacement: float
    wear: float
    pressure: float

    @classmethod
    def of(cls, result, displacements) -> _Scales:
        u = max(np.linalg.norm(u, axis=1).max() for u in displacements)
        w = max(result.wear.max(), result.scene.contact.gap)
        return cls(_positive(u), _positive(w), _positive(result.pressure.max()))


class _Picture:
    """One run's geometry and colour ranges; ``plotter(step)`` draws a step."""

    def __init__(self, result, steps, field: str = "displacement", magnify: float = 1.0,
                 window_size=(1200, 500)):
        if field not in LAYER_FIELDS:
            raise ValueError(f"field: must be one of {', '.join(LAYER_FIELDS)} (got {field!r})")
        if result.discretization is None:
            raise ValueError("result: has no mesh attached (save it with its mesh.vol to render it)")
        self.result, self.field, self.magnify, self.window_size = result, field, magnify, window_size
        self.mesh = _Mesh.of(result.discretization.mesh)
        shown = [_vertex_displacement(result, s) for s in sorted(set(result.stored_steps) | set(steps))]
        self.scales = _Scales.of(result, shown)
        moved = np.array([self.mesh.points + magnify * u for u in shown])
        self.lo, self.hi = moved.min(axis=(0, 1)), moved.max(axis=(0, 1))
        self.interpolate = _contact_interpolator(result.contact_points, self.mesh.points[:, :-1])
        self.lit = dict(lighting=result.scene.dim == 3)

    def plotter(self, step: int) -> pv.Plotter:
        """A plotter showing body, layer, foundation, scalar bars and the time of a step."""
        with pv.vtk_verbosity("error"):
            pl = pv.Plotter(off_screen=True, window_size=list(self.window_size))
        pl.set_background("white")
        self._body(pl, step)
        if len(self.mesh.layer):
            self._layer(pl, step)
        self._foundation(pl, step)
        pl.add_text(f"t = {self.result.times[step]:.2f} (step {step})",
                    position=(12, self.window_size[1] - 36), font_size=12, color="black")
        pl.add_text("light grey: worn-away part of the layer", position="lower_right", font_size=9,
                    color="black")
        view = np.array(self._box())
        view[2 * self.result.scene.dim - 1] = self.hi[-1]
        _camera(pl, self.result.scene.dim, view, self.window_size)
        return pl

    def _body(self, pl: pv.Plotter, step: int) -> None:
        """The body at X + m u, coloured by |u| when ``field == "displacement"``."""
        u = _vertex_displacement(self.result, step)
        body = _grid(self.mesh.points + self.magnify * u, self.mesh.body, {"|u|": np.linalg.norm(u, axis=1)})
        colour = (dict(scalars="|u|", cmap=CMAPS["displacement"], clim=(0, self.scales.displacement),
                       scalar_bar_args=_bar(TITLES["displacement"], 0))
                  if self.field == "displacement" else dict(color=BODY_COLOR))
        pl.add_mesh(body, show_edges=True, edge_color="#404040", line_width=0.5, **self.lit, **colour)

    def _layer(self, pl: pv.Plotter, step: int) -> None:
        """The remaining layer coloured by w or p, and its worn-away part in translucent light grey."""
        name = LAYER_FIELDS[self.field]
        at_base = self.interpolate(_contact_columns(self.result, step, name))
        remaining, worn = _layer_points(self.mesh.points, at_base, self.result.scene.contact.gap,
                                        self.magnify)
        bar = _bar(TITLES[name], int(self.field == "displacement"))
        pl.add_mesh(_grid(remaining, self.mesh.layer, {name: at_base[:, -1]}), scalars=name, cmap=CMAPS[name],
                    clim=(0, getattr(self.scales, name)), show_edges=True, edge_color="#808080",
                    line_width=0.5, scalar_bar_args=bar, **self.lit)
        pl.add_mesh(_grid(worn, self.mesh.layer, {}), color=WORN_COLOR, opacity=0.5, **self.lit)

    def _box(self) -> tuple:
        """Bounds of the foundation block: below x_d = −g, under the body at every step shown.

        In 3D the block starts just behind the front face (y = y_min) so the worn part stays visible.
        """
        g, dim, lo, hi = self.result.scene.contact.gap, self.result.scene.dim, self.lo, self.hi
        size = (hi - lo).max()
        depth = max(2 * g, 0.15 * (hi - lo)[dim - 1])
        x0, x1 = lo[0] - 0.05 * size, hi[0] + 0.05 * size
        return ((x0, x1, -g - depth, -g, -0.02, -0.01) if dim == 2
                else (x0, x1, lo[1] + 0.02 * size, hi[1] + 0.05 * size, -g - depth, -g))

    def _foundation(self, pl: pv.Plotter, step: int) -> None:
        """The grey foundation block and an arrow for its velocity v*(t)."""
        box, dim = self._box(), self.result.scene.dim
        pl.add_mesh(pv.Box(box), color=FOUNDATION_COLOR, **self.lit)
        v = self.result.discretization.velocity(self.result.times[step])
        if v.any():
            size, top, bottom = box[1] - box[0], box[2 * dim - 1], box[2 * dim - 2]
            start = np.array([box[0] + 0.05 * size, box[2] - 1e-3, top + 0.7 * (bottom - top)])
            _arrow(pl, start if dim == 3 else start[[0, 2, 1]] * (1, 1, 0), v, 0.2 * size, self.lit)


def _arrow(pl: pv.Plotter, start: np.ndarray, v: np.ndarray, length: float, lit: dict) -> None:
    """White arrow along v with the label "rigid foundation, v* = (…)"."""
    direction = _xyz(v[None])[0] / np.linalg.norm(v)
    arrow = pv.Arrow(start=start, direction=direction, scale=length, shaft_radius=0.04, tip_radius=0.1)
    pl.add_mesh(arrow, color="white", **lit)
    label = "rigid foundation, v* = (" + ", ".join(f"{c:.3g}" for c in v) + ")"
    pl.add_point_labels([start + 1.1 * length * direction], [label], show_points=False, shape="rect",
                        shape_color="white", shape_opacity=0.8, font_size=13, text_color="black",
                        always_visible=True)


def frame(result, step: int, *, field: str = "displacement", magnify: float = 1.0,
          window_size=(1200, 500)) -> np.ndarray:
    """RGB image (height, width, 3) of the body, layer and foundation at a step.

    ``field`` colours the body by |u| and the layer by w (``"displacement"``), or only the layer by
    the wear w (``"wear"``) or the compliance pressure p (``"pressure"``).  ``magnify`` scales u and w.
    """
    step = range(result.steps + 1)[step]
    return _shot(_Picture(result, [step], field, magnify, window_size).plotter(step))


def save_frame(result, step: int, path, **kw) -> Path:
    """Write :func:`frame` as a PNG and return its path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(frame(result, step, **kw)).save(path)
    return path


def paper_figures(result, out_dir, steps=None, **kw) -> list[Path]:
    """The paper's Figs. 1–4: ``figK_stepNNN.png`` at 25, 50, 75 and 100 % of the run (or ``steps``)."""
    steps = quartile_steps(result) if steps is None else [range(result.steps + 1)[s] for s in steps]
    picture = _Picture(result, steps, **kw)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for k, step in enumerate(steps, start=1):
        paths.append(out / f"fig{k}_step{step:03d}.png")
        Image.fromarray(_shot(picture.plotter(step))).save(paths[-1])
    return paths


def animation(result, path, fps: float = 10, steps=None, **kw) -> Path:
    """GIF of the run, one frame per step (or per entry of ``steps``), colour ranges fixed over the run."""
    steps = range(result.steps + 1) if steps is None else steps
    picture = _Picture(result, list(steps), **kw)
    frames = [Image.fromarray(_shot(picture.plotter(s))) for s in steps]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    frames[0].save(path, save_all=True, append_images=frames[1:], duration=round(1000 / fps), loop=0)
    return path


def quartile_steps(result) -> list[int]:
    """Steps at 25, 50, 75 and 100 % of the completed run (the paper's 25, 50, 75, 100 of 100)."""
    return sorted({round(q * result.steps) for q in (0.25, 0.5, 0.75, 1.0)})


# ---------------------------------------------------------------- fields on the picture's points


def _vertex_displacement(result, step: int) -> np.ndarray:
    """Displacement at every mesh vertex, shape (nv, d): each component's vertex DOFs (0 off the body)."""
    gf = result.discretization.gridfunction(result.displacement(step))
    nv = result.discretization.mesh.nv
    return np.column_stack([c.vec.FV().NumPy()[:nv] for c in gf.components])


def _contact_columns(result, step: int, layer_field: str) -> np.ndarray:
    """Columns (u_1..u_d, w, r, field) at the contact points; u = P u_h (exact, also for P2)."""
    disc = result.discretization
    u = (disc.points.P @ result.displacement(step)).reshape(-1, result.scene.dim)
    values = getattr(result, layer_field)[step]
    return np.column_stack([u, result.wear[step], result.compression[step], values])


def _contact_interpolator(points: np.ndarray, base: np.ndarray):
    """Map values at the contact points to the bases (x, 0) / (x, y, 0) of the layer's vertices."""
    if points.shape[1] == 2:
        order = np.argsort(points[:, 0])
        x = points[order, 0]
        return lambda cols: np.column_stack([np.interp(base[:, 0], x, c[order]) for c in cols.T])
    xy = points[:, :2]
    triangulation, nearest = Delaunay(xy), cKDTree(xy).query(base)[1]

    def interpolate(cols):
        out = LinearNDInterpolator(triangulation, cols)(base)
        missing = np.isnan(out).any(axis=1)
        out[missing] = cols[nearest[missing]]
        return out

    return interpolate


def _layer_points(points: np.ndarray, at_base: np.ndarray, g: float, m: float):
    """Deformed positions of the layer's vertices: the remaining part and the worn-away part."""
    d = points.shape[1]
    u, w, r = at_base[:, :d], at_base[:, d], at_base[:, d + 1]
    eta = np.clip((points[:, -1] + g) / g, 0.0, 1.0)
    top = m * u[:, -1]
    bottom = np.minimum(top - (g - m * w) + m * np.maximum(r, 0.0), top)
    worn = np.clip(m * w, 0.0, m * g)
    shifted = points.copy()
    shifted[:, :-1] += m * u[:, :-1]
    remaining, removed = shifted.copy(), shifted.copy()
    remaining[:, -1] = bottom + eta * (top - bottom)
    removed[:, -1] = bottom - worn + eta * worn
    return remaining, removed


# ---------------------------------------------------------------- pyvista plumbing


def _grid(points: np.ndarray, cells: np.ndarray, data: dict) -> pv.UnstructuredGrid:
    """Unstructured grid of the cells, with only the vertices they use."""
    used, inverse = np.unique(cells, return_inverse=True)
    conn = np.column_stack([np.full(len(cells), cells.shape[1]), inverse.reshape(cells.shape)])
    kind = CELL_TYPES[points.shape[1], cells.shape[1]]
    grid = pv.UnstructuredGrid(conn.ravel(), np.full(len(cells), kind), _xyz(points[used]))
    for name, values in data.items():
        grid.point_data[name] = values[used]
    return grid


def _xyz(points: np.ndarray) -> np.ndarray:
    """Points padded with z = 0 (2D) for VTK."""
    return np.column_stack([points, np.zeros((len(points), 3 - points.shape[1]))])


def _bar(title: str, slot: int) -> dict:
    """A vertical scalar bar at the right edge; slot 0 outermost."""
    return dict(title=title, vertical=True, position_x=0.93 - 0.1 * slot, position_y=0.3, width=0.03,
                height=0.6, color="black", fmt="%.3f", n_labels=5, title_font_size=16, label_font_size=13)


def _camera(pl: pv.Plotter, dim: int, bounds, window_size) -> None:
    """Fit the scene into the left ~80 % of the window (room for the scalar bars on the right)."""
    if dim == 3:
        pl.view_xz()
        pl.camera.azimuth, pl.camera.elevation = -25, 20
        pl.reset_camera(bounds=bounds)
        pl.camera.zoom(1.1)
        return
    lo, hi = np.array(bounds[::2]), np.array(bounds[1::2])
    aspect = window_size[0] / window_size[1]
    height = max((hi - lo)[1] / 0.8, (hi - lo)[0] / (0.76 * aspect))
    center = np.array([lo[0] - 0.03 * height * aspect + 0.5 * height * aspect, 0.5 * (lo[1] + hi[1]), 0.0])
    pl.enable_parallel_projection()
    pl.camera.focal_point = center
    pl.camera.position = center + (0, 0, 10)
    pl.camera.up = (0, 1, 0)
    pl.camera.parallel_scale = 0.5 * height


def _shot(pl: pv.Plotter) -> np.ndarray:
    """Render off-screen and return the RGB pixels; the plotter is closed."""
    with pv.vtk_verbosity("error"):
        image = pl.screenshot(return_img=True)
    pl.close()
    return np.asarray(image)[..., :3].copy()


def _positive(value: float) -> float:
    """A colour-range end that is never zero."""
    return float(value) if value > 0 else 1.0
