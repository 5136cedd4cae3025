"""Off-screen pictures of a result: the deformed body, its soft layer and the moving foundation.

The picture (paper, Figs. 1–4) is described, and its arrays computed, in
:mod:`ngwear.views.picture_data` (no pyvista there); this module turns them into pyvista
objects and draws them: the body coloured by |u| (or plain), the remaining layer coloured by w (or
p), the worn-away part of the layer translucent, the foundation (a block, or a sector of the
rotor) with an arrow or an arc arrow for its motion.  A 3D picture looks from below, through the translucent
foundation, at the worn contact face, turned so that the part's longest extent runs across the window, and the part
fills the window left of the colour bars (:mod:`ngwear.views.camera`).  The colour bars say what they show, with
units in an SI scene, and span the run's data from 0: the wear's up to its largest w, the layer's thickness g noted
under it.  No numerical module imports this one.
A :class:`Canvas` keeps one plotter for many pictures (figures, animations, the explorer).

VTK's OpenGL contexts belong to the thread that created them: a plotter used from another thread
draws garbage and can kill the process (JupyterLab runs widget callbacks on a kernel subshell
thread).  Every plotter is therefore made, drawn and closed on one render thread of this module,
whichever thread asks for the picture.
"""
from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from functools import partial, wraps
from pathlib import Path

import ngsolve as ngs
import numpy as np
import pyvista as pv
from matplotlib import colormaps, font_manager
from matplotlib.colors import ListedColormap, to_hex
from PIL import Image
from vtkmodules.vtkCommonCore import VTK_FONT_FILE

from ..results.folder import replacing
from ..results.units import label, unit
from ..results.vtk import frame_name
from . import video
from .camera import aim
from .picture_data import LAYER_FIELDS, ArcArrow, MeshArrays, PictureData, StraightArrow, xyz

pv.OFF_SCREEN = True

FONT = font_manager.findfont("DejaVu Sans")
"""A font with Greek letters (VTK's own have none): matplotlib's DejaVu Sans."""
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


def foundation(picture: PictureData) -> pv.PolyData:
    """The foundation's surface: the block, or the rotor's sector."""
    if picture.rotor is None:
        return pv.Box(picture.box())
    points = picture.sector()
    return pv.StructuredGrid(*(points[..., k] for k in range(3))).extract_surface(algorithm="dataset_surface")


def arrow(shape: StraightArrow | ArcArrow) -> pv.PolyData:
    """The surface of an arrow of :meth:`PictureData.motion`."""
    if isinstance(shape, StraightArrow):
        return pv.Arrow(start=shape.start, direction=shape.direction, scale=shape.length, shaft_radius=0.04,
                        tip_radius=0.1)
    end, tip = shape.path[-1], shape.tip
    head = pv.Cone(center=0.5 * (end + tip), direction=tip - end, height=np.linalg.norm(tip - end),
                   radius=2.5 * shape.thickness, resolution=24)
    tube = pv.lines_from_points(shape.path).tube(radius=shape.thickness, n_sides=12)
    return tube.merge(head).extract_surface(algorithm="dataset_surface")


class Canvas:
    """An off-screen picture that is built on the first frame and updated in place afterwards.

    The plotter, its meshes, scalar bars and texts are made once per mesh; later frames (other steps,
    or other results on the same mesh, as in the explorer) only move points and recolour, which
    renders much faster than a new plotter (whose first render compiles its shaders).
    Colour ranges and view are fixed per result over its stored steps and the ``steps`` given with
    its first frame, so that the frames of a run compare.

    Parameters
    ----------
    field : {"displacement", "wear", "pressure", "region"}
        Colour the body by |u| and the layer by w, or only the layer by w or by the pressure p; ``region``: the
        part by its regions (body, backing, a file's solids, with a legend) and the layer by w.
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
        self._mesh: tuple[ngs.Mesh, MeshArrays] | None = None
        self._picture: PictureData | None = None

    @on_render_thread
    def frame(self, result, step: int, steps=()) -> np.ndarray:
        """RGB image (height, width, 3) of the body, layer and foundation of ``result`` at ``step``."""
        step = result.step_index(step)
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

    def _picture_of(self, result, steps) -> PictureData:
        if result.discretization is None:
            raise ValueError("result: has no mesh attached (save it with its mesh.vol to render it)")
        if self._picture is None or self._picture.result is not result:
            ngs_mesh = result.discretization.mesh
            if self._mesh is None or self._mesh[0] is not ngs_mesh:
                self._mesh = ngs_mesh, MeshArrays.of(ngs_mesh)
            self._picture = PictureData(result, steps, self.field, self.magnify, self._mesh[1])
        return self._picture

    def _build(self, picture: PictureData) -> None:
        """A new plotter with every actor; the data are set by :meth:`_update`."""
        self.close()
        self._picture = picture
        with pv.vtk_verbosity("error"):
            pl = pv.Plotter(off_screen=True, window_size=list(self.window_size))
        pl.set_background("white")
        mesh, lit, width = picture.mesh, dict(lighting=picture.dim == 3), self.window_size[0]
        parts, titles = {"mesh": mesh, "lit": lit}, bar_titles(picture.result)
        parts["body"] = _Cells(mesh.points, mesh.body, ("|u|",))
        parts["body"].grid.cell_data["region"] = mesh.regions
        colour = (dict(scalars="|u|", cmap=CMAPS["displacement"],
                       scalar_bar_args=_bar(titles["displacement"], 0, width))
                  if self.field == "displacement" else dict(color=BODY_COLOR))
        if self.field == "region":
            colours = region_colours(len(mesh.names))
            colour = dict(scalars="region", cmap=ListedColormap(colours), clim=(-0.5, len(colours) - 0.5),
                          show_scalar_bar=False)
            pl.add_legend([[name, c] for name, c in zip(mesh.names, colours)], bcolor="white", face="rectangle",
                          loc="lower left", size=(0.16, 0.06 * len(colours)))
        parts["body_actor"] = pl.add_mesh(parts["body"].grid, show_edges=True, edge_color="#404040",
                                          line_width=0.5, **lit, **colour)
        if len(mesh.facets):
            name = LAYER_FIELDS[self.field]
            parts["layer"] = _Layer(mesh.facets, (name,))
            parts["worn"] = _Layer(mesh.facets, ())
            parts["layer_actor"] = pl.add_mesh(
                parts["layer"].grid, scalars=name, cmap=CMAPS[name], show_edges=True, edge_color="#808080",
                line_width=0.5, scalar_bar_args=_bar(titles[name], int(self.field == "displacement"), width),
                lighting=False)                         # its colours as the bar shows them, seen from any side
            pl.add_mesh(parts["worn"].grid, color=WORN_COLOR, opacity=0.5 if picture.dim == 2 else 0.2, **lit)
            if name == "wear":                          # under the wear's bar: g, and how much of it the top is
                x, y = _bar(titles[name], int(self.field == "displacement"), width)["position_x"], BAR_BOTTOM
                parts["gap_note"] = pl.add_text("", position=(round((x - 0.01) * width),
                                                              round((y - 0.1) * self.window_size[1])),
                                                font_size=9, color="black")
        parts["foundation"] = foundation(picture)      # 3D: seen through from below, onto the contact face
        pl.add_mesh(parts["foundation"], color=FOUNDATION_COLOR, opacity=0.15 if picture.dim == 3 else 1.0, **lit)
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
            below = "seen from below through the foundation; " if picture.dim == 3 else ""
            pl.add_text(f"{below}light grey: worn-away part of the layer", position="lower_right", font_size=9,
                        color="black")
        for bar in pl.scalar_bars.values():
            _font(bar.GetTitleTextProperty(), bar.GetLabelTextProperty())
        _font(*(parts[text].GetTextProperty() for text in ("caption", "gap_note") if text in parts))
        self._plotter, self._parts = pl, parts

    def _update(self, picture: PictureData, step: int) -> None:
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
            if name == "wear":
                parts["gap_note"].SetInput(gap_note(picture.result.scene, scales.wear))
        parts["foundation"].copy_from(foundation(picture))
        motion = picture.motion(step)
        parts["arrow_actor"].visibility = parts["label_actor"].visibility = motion is not None
        if motion is not None:
            shape, where, label = motion
            parts["arrow"].copy_from(arrow(shape))
            parts["label"].points = np.asarray(where)[None]
            parts["label"].point_data["label"] = np.array([label])
        parts["caption"].SetInput(picture.caption(step))
        aim(self._plotter, picture, self.window_size)


def frame(result, step: int, *, field: str = "displacement", magnify: float = 1.0,
          window_size=(1200, 500)) -> np.ndarray:
    """RGB image (height, width, 3) of the body, layer and foundation at a step.

    ``field`` colours the body by |u| and the layer by w (``"displacement"``), or only the layer by
    the wear w (``"wear"``) or the compliance pressure p (``"pressure"``); ``"region"`` colours the part by
    its regions and the layer by w.  ``magnify`` scales u and w.
    To draw many pictures of the same mesh, keep a :class:`Canvas` instead.
    """
    with Canvas(field, magnify, window_size) as canvas:
        return canvas.frame(result, step)


def save_frame(result, step: int, path, **kw) -> Path:
    """Write :func:`frame` as a PNG and return its path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as tmp:                    # never through a link planted at the name
        Image.fromarray(frame(result, step, **kw)).save(tmp)
    return path


def paper_figures(result, out_dir, steps=None, **kw) -> list[Path]:
    """The paper's Figs. 1–4: ``figK_stepNNN.png`` at the frames after t = 0 (or at ``steps``).

    The frames are the steps whose VTU files are written (``fields_stepNNN.vtu``, ``output.every``: a quarter
    of the run by default, as the paper's figures at 25, 50, 75 and 100 of 100 steps).
    """
    steps = picture_steps(result) if steps is None else [result.step_index(s) for s in steps]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    with Canvas(**kw) as canvas:
        for k, step in enumerate(steps, start=1):
            paths.append(out / f"fig{k}_{frame_name(step)}.png")
            with replacing(paths[-1]) as tmp:
                Image.fromarray(canvas.frame(result, step, steps)).save(tmp)
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
    write = partial(video.write_mp4, video.ffmpeg()) if suffix == ".mp4" else video.write_gif
    steps = list(range(result.steps + 1) if steps is None else steps)
    path.parent.mkdir(parents=True, exist_ok=True)
    with Canvas(**kw) as canvas:
        write((canvas.frame(result, s, steps) for s in steps), path, fps)
    return path


def picture_steps(result) -> list[int]:
    """The frames of the result (:attr:`~ngwear.results.result.Result.stored_steps`) but step 0, if it has others."""
    return [step for step in result.stored_steps if step > 0] or result.stored_steps


# ---------------------------------------------------------------- pyvista plumbing


class _Cells:
    """An unstructured grid of some cells on only the vertices they use; ``update`` moves and recolours."""

    def __init__(self, points: np.ndarray, cells: np.ndarray, names):
        self.used, inverse = np.unique(cells, return_inverse=True)
        conn = np.column_stack([np.full(len(cells), cells.shape[1]), inverse.reshape(cells.shape)])
        kind = CELL_TYPES[points.shape[1], cells.shape[1]]
        self.grid = pv.UnstructuredGrid(conn.ravel(), np.full(len(cells), kind), xyz(points[self.used]))
        for name in names:
            self.grid.point_data[name] = np.zeros(len(self.used))

    def update(self, points: np.ndarray, data: dict) -> None:
        """Vertex positions and point data given on every mesh vertex."""
        self.grid.points = xyz(points[self.used])
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
        self.grid.points = xyz(np.vstack([top[self.used], bottom[self.used]]))
        for name, values in data.items():
            self.grid.point_data[name][:] = np.tile(values[self.used], 2)
        self.grid.Modified()


def region_colours(count: int) -> list[str]:
    """A colour for each of ``count`` regions (matplotlib's tab10: body blue, backing orange, …)."""
    palette = colormaps["tab10"].colors
    return [to_hex(palette[k % len(palette)]) for k in range(count)]


def bar_titles(result) -> dict[str, str]:
    """The colour bars' titles: what each colours, with its unit in an SI scene (‖u − δν‖ under a plate)."""
    scene, plate = result.scene, result.plate_displacement.shape[1] > 0
    return {"displacement": label(scene, "‖u − δν‖" if plate else "‖u‖", "length"),
            "wear": label(scene, "wear w", "length"), "pressure": label(scene, "pressure p", "pressure")}


def gap_note(scene, top: float) -> str:
    """The note under the wear's colour bar, which spans 0 … max w: the layer's thickness g and the top's share of it."""
    gap, metres = scene.contact.gap, unit(scene, "length")
    return f"g = {gap:.3g}{f' {metres}' if metres else ''}\ntop: {top / gap:.0%} of g"


def _font(*properties) -> None:
    """Draw text with :data:`FONT` (VTK drops Greek letters and '|' from its own fonts)."""
    for prop in properties:
        prop.SetFontFamily(VTK_FONT_FILE)
        prop.SetFontFile(FONT)


BAR_BOTTOM = 0.3
"""Where the colour bars start, as a fraction of the window's height."""


def _bar(title: str, slot: int, width: int) -> dict:
    """A vertical scalar bar at the right edge of a window ``width`` pixels wide; slot 0 outermost."""
    scale = min(1.0, width / 1200)
    return dict(title=title, vertical=True, position_x=0.93 - 0.1 * slot, position_y=BAR_BOTTOM, width=0.03,
                height=0.6, color="black", fmt="%.3g", n_labels=5, title_font_size=round(16 * scale),
                label_font_size=round(13 * scale))
