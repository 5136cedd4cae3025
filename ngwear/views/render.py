"""Off-screen pictures of a result: the deformed body, its soft layer and the moving foundation.

The picture (paper, Figs. 1–4) in the reference frame with vertical axis e_d (ν = −e_d): the body
is drawn at X + m u(X).  The rigid foundation's surface stays at x_d = −g and moves with v*: a block
with an arrow for v*, or, for a counterface turning about an axis along ν (a brake disc), a sector
of the disc under the part with an arc arrow for ω.  Under a rigid plate the body is coloured by
its elastic displacement |u − δν| (the plate's translation δ moves it rigidly).  The
soft layer is drawn on Γ_C, offset along ν: under a contact point X with displacement u, wear w and
compression r = u_ν − d₀ − w it keeps

    remaining part   from  t = X + m u  to  b = t + ν (g − m w − m r₊)₊,
    worn-away part   from  b  to  b + ν clip(m w, 0, m g),

so the remaining layer is pressed flat on the foundation where r > 0, and the worn part, drawn
translucent, shows the material the foundation has removed.  ``m`` is ``magnify``.  Each facet of
Γ_C becomes one cell of the layer (a quadrilateral in 2D, a prism in 3D), so flat, curved and CAD
contact faces are drawn alike.
The numbers come from the :class:`~ngwear.result.Result`; no numerical module imports this one.
A :class:`Canvas` keeps one plotter for many pictures (figures, animations, the explorer).

VTK's OpenGL contexts belong to the thread that created them: a plotter used from another thread
draws garbage and can kill the process (JupyterLab runs widget callbacks on a kernel subshell
thread).  Every plotter is therefore made, drawn and closed on one render thread of this module,
whichever thread asks for the picture.
"""
from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import cached_property, partial, wraps
from pathlib import Path

import ngsolve as ngs
import numpy as np
import pyvista as pv
from PIL import Image

pv.OFF_SCREEN = True

LAYER_FIELDS = {"displacement": "wear", "wear": "wear", "pressure": "pressure"}
TITLES = {"displacement": "displacement", "wear": "wear w", "pressure": "pressure p"}
CMAPS = {"displacement": "viridis", "wear": "YlOrRd", "pressure": "plasma"}
BODY_COLOR, FOUNDATION_COLOR, WORN_COLOR, ARROW_COLOR = "lightsteelblue", "dimgray", "white", "white"
CELL_TYPES = {(2, 3): pv.CellType.TRIANGLE, (3, 4): pv.CellType.TETRA}
LAYER_CELLS = {2: pv.CellType.QUAD, 3: pv.CellType.WEDGE}
_RENDER_THREAD = ThreadPoolExecutor(max_workers=1, thread_name_prefix="ngwear-render")
_owner = threading.local()


def on_render_thread(method):
    """Run ``method`` on the render thread that owns every OpenGL context (see the module docstring)."""
    def run(*args, **kw):
        _owner.is_render_thread = True
        return method(*args, **kw)

    @wraps(method)
    def call(*args, **kw):
        if getattr(_owner, "is_render_thread", False):
            return method(*args, **kw)
        return _RENDER_THREAD.submit(run, *args, **kw).result()
    return call


@dataclass(frozen=True)
class _Mesh:
    """Reference vertex coordinates, the vertex numbers of the body's elements and of the Γ_C facets."""

    points: np.ndarray
    body: np.ndarray
    facets: np.ndarray

    @classmethod
    def of(cls, mesh: ngs.Mesh) -> _Mesh:
        body = [[v.nr for v in el.vertices] for el in mesh.Elements(ngs.VOL) if el.mat == "body"]
        facets = [[v.nr for v in el.vertices] for el in mesh.Elements(ngs.BND) if el.mat == "contact"]
        points = np.array([v.point for v in mesh.vertices])
        return cls(points, np.array(body, dtype=int).reshape(-1, mesh.dim + 1),
                   np.array(facets, dtype=int).reshape(-1, mesh.dim))


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
    """One run's geometry, colour ranges and view; the arrays a :class:`Canvas` draws at each step."""

    def __init__(self, result, steps, field: str, magnify: float, mesh: _Mesh):
        self.result, self.field, self.magnify, self.mesh = result, field, magnify, mesh
        shown = {s: _vertex_displacement(result, s) for s in sorted(set(result.stored_steps) | set(steps))}
        self.scales = _Scales.of(result, [_elastic(result, s, u) for s, u in shown.items()])
        moved = np.array([mesh.points + magnify * u for u in shown.values()])
        self.lo, self.hi = moved.min(axis=(0, 1)), moved.max(axis=(0, 1))
        self.at_vertices = result.discretization.points.at_vertices

    @property
    def dim(self) -> int:
        return self.result.scene.dim

    def body(self, step: int) -> tuple[np.ndarray, np.ndarray]:
        """Vertices at X + m u and |u| there (|u − δν| under a plate)."""
        u = _vertex_displacement(self.result, step)
        return self.mesh.points + self.magnify * u, np.linalg.norm(_elastic(self.result, step, u), axis=1)

    def layer(self, step: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Per mesh vertex: the body's surface t, the layer's bottom b, the worn part's bottom, the field (w or p).

        Only the vertices of Γ_C carry meaningful values (see the module docstring).
        """
        result, m, g = self.result, self.magnify, self.result.scene.contact.gap
        at = self.at_vertices
        nu = np.asarray(result.scene.contact.direction)
        top = self.mesh.points + m * _vertex_displacement(result, step)
        wear, squeeze = at @ result.wear[step], np.maximum(at @ result.compression[step], 0.0)
        bottom = top + np.maximum(g - m * wear - m * squeeze, 0.0)[:, None] * nu
        worn = bottom + np.clip(m * wear, 0.0, m * g)[:, None] * nu
        return top, bottom, worn, at @ getattr(result, LAYER_FIELDS[self.field])[step]

    @cached_property
    def disc(self) -> dict | None:
        """The disc sector under the part when the counterface turns about an axis along ν (3D), else None.

        Its radii and angles cover the contact points' with a margin; ``level`` is its surface ν·x.
        """
        scene, slip = self.result.scene, self.result.discretization.slip
        nu = np.asarray(scene.contact.direction)
        if self.dim != 3 or not slip.rotating or abs(abs(slip.axis @ nu) - 1) > 1e-9:
            return None
        first = np.cross(nu, np.eye(3)[np.argmin(np.abs(nu))])
        basis = np.array([first / np.linalg.norm(first), np.cross(nu, first / np.linalg.norm(first))])
        arms = (self.result.contact_points - slip.center) @ basis.T
        radius, angle = np.linalg.norm(arms, axis=1), np.unwrap(np.arctan2(arms[:, 1], arms[:, 0]))
        width = max(np.ptp(radius), 0.05 * radius.max())
        turn = max(np.ptp(angle), 3 * width / max(radius.max(), 1e-300))
        level = float((self.result.contact_points @ nu).max()) + scene.contact.gap
        return {"nu": nu, "basis": basis, "level": level,
                "center": slip.center + (level - slip.center @ nu) * nu,
                "radii": (max(radius.min() - 0.3 * width, 0.0), radius.max() + 0.3 * width),
                "angles": (angle.min() - 0.4 * turn, angle.max() + 0.25 * turn), "depth": 0.08 * width,
                "free": angle.min() - 0.05 * turn}

    def disc_point(self, radius, angle, below=0.0) -> np.ndarray:
        """Points of the disc at polar coordinates about its axis, ``below`` its surface."""
        d = self.disc
        radius, angle, below = (a[..., None] for a in np.broadcast_arrays(radius, angle, below))
        return d["center"] + below * d["nu"] + radius * (np.cos(angle) * d["basis"][0] + np.sin(angle) * d["basis"][1])

    def foundation(self) -> pv.PolyData:
        """The foundation's surface: the disc sector, or the block of :meth:`box`."""
        if self.disc is None:
            return pv.Box(self.box())
        (r0, r1), (a0, a1) = self.disc["radii"], self.disc["angles"]
        r, a, z = np.meshgrid(np.linspace(r0, r1, 8), np.linspace(a0, a1, 64), [0.0, self.disc["depth"]],
                              indexing="ij")
        xyz = self.disc_point(r, a, z)
        return pv.StructuredGrid(*(xyz[..., k] for k in range(3))).extract_surface(algorithm="dataset_surface")

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

    def view(self) -> list:
        """Bounds the camera fits: the foundation up to the highest point of the body."""
        view = list(self.foundation().bounds)[:2 * self.dim]
        view[2 * self.dim - 1] = max(self.hi[-1], view[2 * self.dim - 1])
        return view if self.dim == 3 else [*view, -0.02, -0.01]

    def motion(self, step: int) -> tuple[pv.PolyData, np.ndarray, str] | None:
        """Arrow, label position and label of the foundation's motion at a step (None when it is at rest)."""
        slip, t = self.result.discretization.slip, self.result.times[step]
        factor = slip.factor(t)
        if factor == 0 or not (slip.rotating or np.any(self.result.scene.foundation.velocity)):
            return None
        if self.disc is not None:
            return self._arc(factor * np.asarray(slip.omega))
        # v* where Γ_C is, at its contact point nearest to the centroid (the translation v₀ s_v if no ω)
        nearest = np.argmin(np.linalg.norm(slip.points - slip.points.mean(axis=0), axis=1))
        v = slip.velocity(t)[nearest]
        if not v.any():
            return None
        box, dim = self.box(), self.dim
        size, top, bottom = box[1] - box[0], box[2 * dim - 1], box[2 * dim - 2]
        start = np.array([box[0] + 0.05 * size, box[2] - 1e-3, top + 0.7 * (bottom - top)])
        start = start if dim == 3 else start[[0, 2, 1]] * (1, 1, 0)
        direction = _xyz(v[None])[0] / np.linalg.norm(v)
        arrow = pv.Arrow(start=start, direction=direction, scale=0.2 * size, shaft_radius=0.04, tip_radius=0.1)
        label = "rigid foundation, v* = (" + ", ".join(f"{c:.3g}" for c in v) + ")"
        return arrow, start + 0.22 * size * direction, label

    def _arc(self, omega: np.ndarray) -> tuple[pv.PolyData, np.ndarray, str]:
        """An arc arrow on the disc in front of the part (the free band of angles below it), turning as ω does."""
        d = self.disc
        (r0, r1), (a0, _) = d["radii"], d["angles"]
        sense = np.sign(omega @ d["nu"])     # angles turn from e1 to e2 = ν × e1, i.e. counter-clockwise about ν
        start, end = a0 + 0.1 * (d["free"] - a0), d["free"]
        start, end = (start, end) if sense > 0 else (end, start)
        path = self.disc_point(0.5 * (r0 + r1), np.linspace(start, end, 40), -0.02 * (r1 - r0))
        thickness = 0.02 * (r1 - r0)
        tip = path[-1] + 6 * thickness * (path[-1] - path[-2]) / np.linalg.norm(path[-1] - path[-2])
        head = pv.Cone(center=0.5 * (path[-1] + tip), direction=tip - path[-1], height=np.linalg.norm(tip - path[-1]),
                       radius=2.5 * thickness, resolution=24)
        arrow = pv.lines_from_points(path).tube(radius=thickness, n_sides=12).merge(head)
        arrow = arrow.extract_surface(algorithm="dataset_surface")
        label = f"disc, omega = {np.linalg.norm(omega):.3g} rad/s"
        return arrow, path[len(path) // 2] - 0.15 * (r1 - r0) * d["nu"], label

    def caption(self, step: int) -> str:
        return f"t = {self.result.times[step]:.2f} (step {step})"


class Canvas:
    """An off-screen picture that is built on the first frame and updated in place afterwards.

    The plotter, its meshes, scalar bars and texts are made once per mesh; later frames (other steps,
    or other results on the same mesh, as in the explorer) only move points and recolour, which
    renders about four times faster than a new plotter (whose first render compiles its shaders).
    Colour ranges and view are fixed per result over its stored steps and the ``steps`` given with
    its first frame, so that the frames of a run compare.

    Parameters
    ----------
    field : {"displacement", "wear", "pressure"}
        Colour the body by |u| and the layer by w, or only the layer by w or by the pressure p.
    magnify : float
        Scale of u and w in the picture.
    window_size : (int, int)
        Width and height of the image in pixels.
    """

    def __init__(self, field: str = "displacement", magnify: float = 1.0, window_size=(1200, 500)):
        if field not in LAYER_FIELDS:
            raise ValueError(f"field: must be one of {', '.join(LAYER_FIELDS)} (got {field!r})")
        self.field, self.magnify, self.window_size = field, magnify, tuple(window_size)
        self._plotter: pv.Plotter | None = None
        self._parts: dict = {}
        self._mesh: tuple[ngs.Mesh, _Mesh] | None = None
        self._picture: _Picture | None = None

    @on_render_thread
    def frame(self, result, step: int, steps=()) -> np.ndarray:
        """RGB image (height, width, 3) of the body, layer and foundation of ``result`` at ``step``."""
        step = range(result.steps + 1)[step]
        picture = self._picture_of(result, [step, *steps])
        if self._plotter is None or self._parts["mesh"] is not picture.mesh:
            self._build(picture)
        self._update(picture, step)
        with pv.vtk_verbosity("error"):
            self._plotter.render()
            image = self._plotter.screenshot(return_img=True)
        return np.asarray(image)[..., :3].copy()

    @on_render_thread
    def close(self) -> None:
        """Release the plotter (its render window)."""
        if self._plotter is not None:
            self._plotter.close()
        self._plotter, self._parts, self._picture = None, {}, None

    def __enter__(self) -> Canvas:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _picture_of(self, result, steps) -> _Picture:
        if result.discretization is None:
            raise ValueError("result: has no mesh attached (save it with its mesh.vol to render it)")
        if self._picture is None or self._picture.result is not result:
            ngs_mesh = result.discretization.mesh
            if self._mesh is None or self._mesh[0] is not ngs_mesh:
                self._mesh = ngs_mesh, _Mesh.of(ngs_mesh)
            self._picture = _Picture(result, steps, self.field, self.magnify, self._mesh[1])
        return self._picture

    def _build(self, picture: _Picture) -> None:
        """A new plotter with every actor; the data are set by :meth:`_update`."""
        self.close()
        self._picture = picture
        with pv.vtk_verbosity("error"):
            pl = pv.Plotter(off_screen=True, window_size=list(self.window_size))
        pl.set_background("white")
        mesh, lit, width = picture.mesh, dict(lighting=picture.dim == 3), self.window_size[0]
        parts = {"mesh": mesh, "lit": lit}
        parts["body"] = _Cells(mesh.points, mesh.body, ("|u|",))
        colour = (dict(scalars="|u|", cmap=CMAPS["displacement"],
                       scalar_bar_args=_bar(TITLES["displacement"], 0, width))
                  if self.field == "displacement" else dict(color=BODY_COLOR))
        parts["body_actor"] = pl.add_mesh(parts["body"].grid, show_edges=True, edge_color="#404040",
                                          line_width=0.5, **lit, **colour)
        if len(mesh.facets):
            name = LAYER_FIELDS[self.field]
            parts["layer"] = _Layer(mesh.facets, (name,))
            parts["worn"] = _Layer(mesh.facets, ())
            parts["layer_actor"] = pl.add_mesh(
                parts["layer"].grid, scalars=name, cmap=CMAPS[name], show_edges=True, edge_color="#808080",
                line_width=0.5, scalar_bar_args=_bar(TITLES[name], int(self.field == "displacement"), width),
                **lit)
            pl.add_mesh(parts["worn"].grid, color=WORN_COLOR, opacity=0.5, **lit)
        parts["foundation"] = picture.foundation()
        pl.add_mesh(parts["foundation"], color=FOUNDATION_COLOR, **lit)
        parts["arrow"] = pv.Arrow()
        parts["arrow_actor"] = pl.add_mesh(parts["arrow"], color=ARROW_COLOR, **lit)
        parts["label"] = pv.PolyData(np.zeros((1, 3)))
        parts["label"].point_data["label"] = np.array([""])
        parts["label_actor"] = pl.add_point_labels(
            parts["label"], "label", show_points=False, shape="rect", shape_color="white",
            shape_opacity=0.8, font_size=13, text_color="black", always_visible=True)
        parts["caption"] = pl.add_text("", position=(12, self.window_size[1] - 36), font_size=12,
                                       color="black")
        if len(mesh.facets):
            pl.add_text("light grey: worn-away part of the layer", position="lower_right", font_size=9,
                        color="black")
        self._plotter, self._parts = pl, parts

    def _update(self, picture: _Picture, step: int) -> None:
        """Move and recolour every actor to ``step`` of the picture's result."""
        parts, scales = self._parts, picture.scales
        points, speed = picture.body(step)
        parts["body"].update(points, {"|u|": speed})
        if self.field == "displacement":
            parts["body_actor"].mapper.scalar_range = (0, scales.displacement)
        if "layer" in parts:
            name = LAYER_FIELDS[self.field]
            top, bottom, worn, values = picture.layer(step)
            parts["layer"].update(top, bottom, {name: values})
            parts["worn"].update(bottom, worn, {})
            parts["layer_actor"].mapper.scalar_range = (0, getattr(scales, name))
        parts["foundation"].copy_from(picture.foundation())
        motion = picture.motion(step)
        parts["arrow_actor"].visibility = parts["label_actor"].visibility = motion is not None
        if motion is not None:
            arrow, where, label = motion
            parts["arrow"].copy_from(arrow)
            parts["label"].points = np.asarray(where)[None]
            parts["label"].point_data["label"] = np.array([label])
        parts["caption"].SetInput(picture.caption(step))
        _camera(self._plotter, picture.dim, picture.view(), self.window_size, picture.disc is not None)


def frame(result, step: int, *, field: str = "displacement", magnify: float = 1.0,
          window_size=(1200, 500)) -> np.ndarray:
    """RGB image (height, width, 3) of the body, layer and foundation at a step.

    ``field`` colours the body by |u| and the layer by w (``"displacement"``), or only the layer by
    the wear w (``"wear"``) or the compliance pressure p (``"pressure"``).  ``magnify`` scales u and w.
    To draw many pictures of the same mesh, keep a :class:`Canvas` instead.
    """
    with Canvas(field, magnify, window_size) as canvas:
        return canvas.frame(result, step)


def save_frame(result, step: int, path, **kw) -> Path:
    """Write :func:`frame` as a PNG and return its path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(frame(result, step, **kw)).save(path)
    return path


def paper_figures(result, out_dir, steps=None, **kw) -> list[Path]:
    """The paper's Figs. 1–4: ``figK_stepNNN.png`` at 25, 50, 75 and 100 % of the run (or ``steps``)."""
    steps = quartile_steps(result) if steps is None else [range(result.steps + 1)[s] for s in steps]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    with Canvas(**kw) as canvas:
        for k, step in enumerate(steps, start=1):
            paths.append(out / f"fig{k}_step{step:03d}.png")
            Image.fromarray(canvas.frame(result, step, steps)).save(paths[-1])
    return paths


def animation(result, path, fps: float = 10, steps=None, **kw) -> Path:
    """Animation of the run, one frame per step (or per entry of ``steps``), colour ranges fixed.

    A ``.gif`` path writes a looping GIF (Pillow); ``.mp4`` writes H.264 video through the optional
    package imageio-ffmpeg (``pip install imageio-ffmpeg``), which is not a dependency of ngwear.
    Keyword arguments go to :class:`Canvas`.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"path: animations are .gif or .mp4 (got {path.name!r})")
    write = partial(_write_mp4, _ffmpeg()) if suffix == ".mp4" else _write_gif
    steps = list(range(result.steps + 1) if steps is None else steps)
    path.parent.mkdir(parents=True, exist_ok=True)
    with Canvas(**kw) as canvas:
        write((canvas.frame(result, s, steps) for s in steps), path, fps)
    return path


def _ffmpeg():
    """The optional module imageio_ffmpeg, or an error saying how to get it."""
    try:
        import imageio_ffmpeg
    except ImportError as err:
        raise ModuleNotFoundError("MP4 animations need the optional package imageio-ffmpeg "
                                  "(pip install imageio-ffmpeg); write a .gif instead") from err
    return imageio_ffmpeg


def _write_gif(frames, path: Path, fps: float) -> None:
    first, *rest = (Image.fromarray(f) for f in frames)
    first.save(path, save_all=True, append_images=rest, duration=round(1000 / fps), loop=0)


def _write_mp4(ffmpeg, frames, path: Path, fps: float) -> None:
    """H.264 in yuv420p through imageio-ffmpeg; frames are padded to even width and height."""
    writer = None
    for image in frames:
        h, w = image.shape[:2]
        image = np.pad(image, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
        if writer is None:
            writer = ffmpeg.write_frames(str(path), (image.shape[1], image.shape[0]), fps=fps,
                                         macro_block_size=1, pix_fmt_out="yuv420p")
            writer.send(None)
        writer.send(np.ascontiguousarray(image))
    writer.close()


def quartile_steps(result) -> list[int]:
    """Steps at 25, 50, 75 and 100 % of the completed run (the paper's 25, 50, 75, 100 of 100)."""
    return sorted({round(q * result.steps) for q in (0.25, 0.5, 0.75, 1.0)})


# ---------------------------------------------------------------- fields on the picture's points


def _elastic(result, step: int, u: np.ndarray) -> np.ndarray:
    """The displacement without the plate's translation, u − δν (u itself without a plate)."""
    if not result.plate_displacement.shape[1]:
        return u
    return u - result.plate_displacement[step, 0] * np.asarray(result.scene.contact.direction)


def _vertex_displacement(result, step: int) -> np.ndarray:
    """Displacement at every mesh vertex, shape (nv, d): each component's vertex DOFs (0 off the body)."""
    gf = result.discretization.gridfunction(result.displacement(step))
    nv = result.discretization.mesh.nv
    return np.column_stack([c.vec.FV().NumPy()[:nv] for c in gf.components])


# ---------------------------------------------------------------- pyvista plumbing


class _Cells:
    """An unstructured grid of some cells on only the vertices they use; ``update`` moves and recolours."""

    def __init__(self, points: np.ndarray, cells: np.ndarray, names):
        self.used, inverse = np.unique(cells, return_inverse=True)
        conn = np.column_stack([np.full(len(cells), cells.shape[1]), inverse.reshape(cells.shape)])
        kind = CELL_TYPES[points.shape[1], cells.shape[1]]
        self.grid = pv.UnstructuredGrid(conn.ravel(), np.full(len(cells), kind), _xyz(points[self.used]))
        for name in names:
            self.grid.point_data[name] = np.zeros(len(self.used))

    def update(self, points: np.ndarray, data: dict) -> None:
        """Vertex positions and point data given on every mesh vertex."""
        self.grid.points = _xyz(points[self.used])
        for name, values in data.items():
            self.grid.point_data[name][:] = values[self.used]
        self.grid.Modified()


class _Layer:
    """Cells between two copies of the Γ_C facets (quadrilaterals in 2D, prisms in 3D); ``update`` moves both."""

    def __init__(self, facets: np.ndarray, names):
        self.used, inverse = np.unique(facets, return_inverse=True)
        local, count, dim = inverse.reshape(facets.shape), len(self.used), facets.shape[1]
        cells = np.hstack([local, (local[:, ::-1] if dim == 2 else local) + count])
        conn = np.column_stack([np.full(len(cells), cells.shape[1]), cells])
        self.grid = pv.UnstructuredGrid(conn.ravel(), np.full(len(cells), LAYER_CELLS[dim]), np.zeros((2 * count, 3)))
        for name in names:
            self.grid.point_data[name] = np.zeros(2 * count)

    def update(self, top: np.ndarray, bottom: np.ndarray, data: dict) -> None:
        """Both surfaces' positions and point data, given on every mesh vertex."""
        self.grid.points = _xyz(np.vstack([top[self.used], bottom[self.used]]))
        for name, values in data.items():
            self.grid.point_data[name][:] = np.tile(values[self.used], 2)
        self.grid.Modified()


def _xyz(points: np.ndarray) -> np.ndarray:
    """Points padded with z = 0 (2D) for VTK."""
    return np.column_stack([points, np.zeros((len(points), 3 - points.shape[1]))])


def _bar(title: str, slot: int, width: int) -> dict:
    """A vertical scalar bar at the right edge of a window ``width`` pixels wide; slot 0 outermost."""
    scale = min(1.0, width / 1200)
    return dict(title=title, vertical=True, position_x=0.93 - 0.1 * slot, position_y=0.3, width=0.03,
                height=0.6, color="black", fmt="%.3g", n_labels=5, title_font_size=round(16 * scale),
                label_font_size=round(13 * scale))


def _camera(pl: pv.Plotter, dim: int, bounds, window_size, disc: bool = False) -> None:
    """Fit the scene into the left ~80 % of the window (room for the scalar bars on the right).

    A part on a disc is seen from higher up, so that the disc's arc arrow shows.
    """
    if dim == 3:
        pl.view_xz()
        pl.camera.azimuth, pl.camera.elevation = -25, 35 if disc else 20
        pl.reset_camera(bounds=bounds)
        pl.camera.zoom(1.25 if disc else 1.1)
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


def _positive(value: float) -> float:
    """A colour-range end that is never zero."""
    return float(value) if value > 0 else 1.0
