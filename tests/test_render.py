"""Off-screen pictures and line plots: checks that fail on a blank or wrong picture.

The 2D pictures are drawn unlit, so the flat colours are exact: the foundation is dimgray, the body
with ``field="wear"`` is lightsteelblue, the worn-away layer is white at opacity 0.5 over dimgray, and
the remaining layer takes YlOrRd colours of w / g.  At the end of the paper's run the layer is worn
through near x = 3 and untouched at the clamped end x = 0.
"""
import sys

import numpy as np
import pytest
from conftest import PAPER
from matplotlib import colormaps
from PIL import Image

import ngwear
from ngwear.views import camera, plots, render

FOUNDATION = (105, 105, 105)
BODY = (176, 196, 222)
WORN = (180, 180, 180)


@pytest.fixture(scope="module")
def strip():
    scene = ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.1, "time.steps": 20})
    return ngwear.simulate(scene, progress=False)


@pytest.fixture(scope="module")
def box():
    scene = ngwear.Scene.from_dict({
        "name": "box", "geometry": {"kind": "box", "size": [1.0, 0.5, 0.5]}, "mesh": {"maxh": 0.2},
        "material": {"lame_lambda": 1.0, "lame_mu": 1.0},
        "contact": {"gap": 0.1, "friction": 0.5, "wear": 1.5, "direction": [0, 0, -1]},
        "foundation": {"velocity": [1, 0, 0]}, "loads": {"traction": {"top": [0, 0, -0.2]}},
        "time": {"steps": 16}})
    return ngwear.simulate(scene, progress=False)


@pytest.fixture(scope="module")
def first_last(strip):
    """Pictures at step 0 and at the last step, body plain so that it has one exact colour."""
    return render.frame(strip, 0, field="wear"), render.frame(strip, -1, field="wear")


def mask(image, colour, tol=3):
    return np.abs(image.astype(int) - colour).max(axis=-1) <= tol


def near_cmap(image, name, lo, hi, tol=12):
    """Pixels within ``tol`` of the colour map's colours between lo and hi (fractions of the range)."""
    codes, inverse = np.unique(image.astype(np.int32) @ (65536, 256, 1), return_inverse=True)
    rgb = np.column_stack([codes >> 16, (codes >> 8) & 255, codes & 255])
    colours = colormaps[name](np.linspace(lo, hi, 64))[:, :3] * 255
    near = (np.abs(rgb[:, None] - colours[None]).max(axis=-1) <= tol).any(axis=1)
    return near[inverse].reshape(image.shape[:2])


def rows(m, fraction=0.3):
    """Rows in which the mask covers more than ``fraction`` of the width (text and edges do not)."""
    return np.flatnonzero(m.mean(axis=1) > fraction)


def layer_band(image):
    """The part of the picture around the foundation's surface, and the body's first/last column."""
    top = rows(mask(image, FOUNDATION)).min()
    body = mask(image, BODY)
    x = np.flatnonzero(body.mean(axis=0) > 0.2)
    return image[top - 70:top + 40], x[0], x[-1]


def test_frame_is_an_rgb_picture_with_body_above_foundation(first_last):
    image = first_last[1]
    assert image.shape == (500, 1200, 3) and image.dtype == np.uint8
    assert image.std() > 20
    body, ground = rows(mask(image, BODY)), rows(mask(image, FOUNDATION))
    assert len(body) > 0.4 * image.shape[0] and len(ground) > 0.1 * image.shape[0]
    assert body.max() < ground.min() < ground.max() and ground.min() > 0.5 * image.shape[0]


def test_layer_is_worn_at_the_right_end_not_at_the_clamped_end(first_last):
    band, x0, x1 = layer_band(first_last[1])
    left, right = band[:, x0:x0 + (x1 - x0) // 25], band[:, (x0 + x1) // 2:x1]
    assert near_cmap(left, "YlOrRd", 0.0, 0.1).sum() > 100 and not near_cmap(left, "YlOrRd", 0.5, 1.0).any()
    assert near_cmap(right, "YlOrRd", 0.5, 1.0).sum() > 50
    worn_thickness = [mask(part, WORN).sum(axis=0).mean() for part in (left, right)]
    assert worn_thickness[0] < 2 < 20 < worn_thickness[1]


def test_wear_changes_the_layer_between_first_and_last_step(first_last):
    (first, *_), (last, *_) = map(layer_band, first_last)
    assert mask(first, WORN).sum() < 20 and mask(last, WORN).sum() > 5000
    assert np.abs(first.astype(int) - last).mean() > 10


def test_displacement_field_colours_the_body(strip):
    image = render.frame(strip, -1, window_size=(600, 250))
    assert image.shape == (250, 600, 3)
    assert near_cmap(image, "viridis", 0.05, 1.0).mean() > 0.1
    assert not mask(image, BODY).any()


def test_unknown_field_is_rejected(strip):
    with pytest.raises(ValueError, match="field"):
        render.frame(strip, 0, field="temperature")


def test_paper_figures_in_3d(box, tmp_path):
    paths = render.paper_figures(box, tmp_path)
    assert [p.name for p in paths] == ["fig1_step004.png", "fig2_step008.png", "fig3_step012.png",
                                       "fig4_step016.png"]
    images = [np.asarray(Image.open(p).convert("RGB")) for p in paths]
    assert all(im.std() > 20 for im in images)
    assert np.abs(images[0].astype(int) - images[-1]).mean() > 1


def test_animation_and_saved_frame(strip, tmp_path):
    gif = render.animation(strip, tmp_path / "run.gif", fps=5, steps=[0, 10, 20], window_size=(300, 130))
    with Image.open(gif) as im:
        assert im.n_frames == 3
    png = render.save_frame(strip, 10, tmp_path / "sub" / "f.png", field="pressure", magnify=2.0)
    assert np.asarray(Image.open(png)).std() > 20
    with pytest.raises(ValueError, match=r"\.gif or \.mp4"):
        render.animation(strip, tmp_path / "run.avi")


def test_mp4_animation(strip, tmp_path):
    ffmpeg = pytest.importorskip("imageio_ffmpeg", reason="MP4 needs the optional package imageio-ffmpeg")
    mp4 = render.animation(strip, tmp_path / "run.mp4", fps=5, steps=range(0, 21, 5), window_size=(301, 131))
    assert mp4.read_bytes()[4:8] == b"ftyp"
    assert ffmpeg.count_frames_and_secs(str(mp4))[0] == 5


def test_mp4_without_imageio_ffmpeg_says_what_to_install(strip, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)
    with pytest.raises(ModuleNotFoundError, match="pip install imageio-ffmpeg"):
        render.animation(strip, tmp_path / "run.mp4")
    assert not (tmp_path / "run.mp4").exists()


def test_canvas_updated_in_place_draws_what_a_new_plotter_draws(strip):
    """One canvas across steps and across runs on the same mesh (as the explorer uses it)."""
    other = ngwear.simulate(strip.scene.replace(**{"contact.wear": 0.3, "foundation.velocity": [2.0, 0.0]}),
                            discretization=strip.discretization, progress=False)
    at_rest = ngwear.simulate(strip.scene.replace(**{"foundation.velocity": [0.0, 0.0], "contact.wear": 0.0,
                                                     "contact.friction": 0.0}),
                              discretization=strip.discretization, progress=False)
    with render.Canvas(window_size=(400, 170)) as canvas:
        for result, step in [(strip, 20), (strip, 0), (other, 20), (at_rest, 10), (strip, 20)]:
            reused = canvas.frame(result, step)
            assert np.array_equal(reused, render.frame(result, step, window_size=(400, 170)))


def test_layer_fills_the_gap_for_any_g_on_a_reused_mesh(strip):
    """A larger g on the same mesh: the layer is drawn with the new g and reaches down to the foundation."""
    thick = ngwear.simulate(strip.scene.replace(**{"contact.gap": 0.35, "contact.wear": 0.0}),
                            discretization=strip.discretization, progress=False)
    assert thick.discretization.mesh is strip.discretization.mesh
    image = render.frame(thick, -1, field="wear")
    column = image[:, np.flatnonzero(mask(image, BODY).mean(axis=0) > 0.2).mean().astype(int)]
    body = np.flatnonzero(mask(column[None], BODY)[0])
    ground = np.flatnonzero(mask(column[None], FOUNDATION)[0])
    between = column[body.max() + 1:ground.min()]
    assert len(between) > 20 and not mask(between[None], (255, 255, 255))[0].any()


@pytest.mark.parametrize("result", ["strip", "box"])
def test_dashboard_redraws_in_place(result, request):
    result = request.getfixturevalue(result)
    board = plots.Dashboard(size=(8, 2.5), dpi=80)
    first, last = board.image(result, 0), board.image(result, -1)
    assert first.shape == last.shape == (200, 640, 3)
    assert (first.mean(axis=-1) < 128).mean() > 0.005 and np.abs(first.astype(int) - last).mean() > 0.1
    assert np.array_equal(board.image(result, 0), first)


@pytest.mark.parametrize("plot", [plots.wear_profiles, plots.pressure_history])
@pytest.mark.parametrize("result", ["strip", "box"])
def test_plots_are_nontrivial_pngs(plot, result, request, tmp_path):
    path = plot(request.getfixturevalue(result), tmp_path / "plot.png")
    image = np.asarray(Image.open(path).convert("L"))
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and image.shape[1] > 600
    assert (image < 128).mean() > 0.005 and image.std() > 20


@pytest.fixture(scope="module")
def pad():
    """The shipped brake pad, coarse and short: a part under a plate on a disc turning about z."""
    scene = ngwear.load_scene(PAPER.parent / "brake_pad.toml").replace(**{"mesh.maxh": 0.012, "time.steps": 12})
    return ngwear.simulate(scene, progress=False)


def test_part_on_a_disc_sector_with_an_arc_arrow(pad):
    picture = render.frame(pad, -1, window_size=(600, 300)).astype(int)
    grey = (np.ptp(picture, axis=-1) < 10) & (picture[..., 0] > 150) & (picture[..., 0] < 235)   # the disc, seen
    assert picture.std() > 20 and grey.mean() > 0.05                                               # through
    with render.Canvas(window_size=(600, 300)) as canvas:
        canvas.frame(pad, -1)
        drawn = canvas._picture
        camera = np.array(canvas._plotter.camera.position)       # below the disc, looking up at the contact face
        assert camera[2] < -pad.scene.contact.gap and canvas._plotter.camera.direction[2] > 0.5
        assert set(canvas._plotter.scalar_bars.keys()) == {"wear w (m)", "‖u − δν‖ (m)"}
        rotor = drawn.rotor
        radii = np.linalg.norm(pad.contact_points[:, :2], axis=1)
        assert rotor["radii"][0] < radii.min() < radii.max() < rotor["radii"][1]
        assert np.allclose(render.foundation(drawn).bounds[5], -pad.scene.contact.gap, atol=1e-12)   # top at −g
        shape, _, label = drawn.motion(len(pad.times) - 1)
        assert label == "disc, omega = 50 rad/s" and render.arrow(shape).n_points > 100
        assert "|u − δν|" in drawn.body.__doc__


def on_screen(plotter, points) -> np.ndarray:
    """Pixel coordinates (x right, y up) of 3D points in the plotter's window."""
    from vtkmodules.vtkRenderingCore import vtkCoordinate
    where = vtkCoordinate()
    where.SetCoordinateSystemToWorld()
    seen = []
    for point in points:
        where.SetValue(*point)
        seen.append(where.GetComputedDoubleDisplayValue(plotter.renderer))
    return np.array(seen)


@pytest.mark.parametrize("name", ["pad", "box"])
def test_a_3d_part_fills_the_frame(name, request):
    """The part, its layer and the motion's arrow fill the frame left of the colour bars (before: a quarter of it)."""
    result = request.getfixturevalue(name)
    size = (1200, 500)
    with render.Canvas(window_size=size) as canvas:
        image = canvas.frame(result, -1).astype(int)
        seen = on_screen(canvas._plotter, canvas._picture.framed())
    left, right, bottom, top = camera.FRAME
    assert seen[:, 0].min() >= left * size[0] - 1 and seen[:, 0].max() <= right * size[0] + 1
    assert seen[:, 1].min() >= bottom * size[1] - 1 and seen[:, 1].max() <= top * size[1] + 1
    assert max(np.ptp(seen[:, 0]) / ((right - left) * size[0]), np.ptp(seen[:, 1]) / ((top - bottom) * size[1])) > 0.99
    coloured = np.ptp(image, axis=-1) > 25                       # the part, its layer, the colour bars
    assert coloured.mean() > 0.15, coloured.mean()              # the pad before: 0.05


def test_the_wear_bar_spans_the_wear_and_marks_g(pad):
    """0 … max w (2e-5 of a 1e-3 layer shows), with g and the top's share of it noted under the bar."""
    assert pad.wear.max() < 0.5 * pad.scene.contact.gap
    with render.Canvas(window_size=(600, 300)) as canvas:
        canvas.frame(pad, -1)
        parts = canvas._parts
        assert parts["layer_actor"].mapper.scalar_range == pytest.approx((0.0, pad.wear.max()))
        share = pad.wear.max() / pad.scene.contact.gap
        assert parts["gap_note"].GetInput() == f"g = 0.001 m\ntop: {share:.0%} of g"
    assert render.gap_note(ngwear.load_scene(PAPER), 0.2) == "g = 0.2\ntop: 100% of g"


@pytest.mark.parametrize("order", [1, 2], ids=["P1", "P2"])
def test_part_plots(pad, tmp_path, order):
    from ngwear.views import part_plots
    if order == 2:
        pad = ngwear.simulate(pad.scene.replace(**{"mesh.order": 2}), progress=False)
        assert render.frame(pad, -1, window_size=(300, 150)).std() > 20
    paths = [part_plots.contact_maps(pad, tmp_path / "maps.png", steps=[0, -1]),
             part_plots.history(pad, tmp_path / "history.png"),
             part_plots.pressure_radius(pad, tmp_path / "pr.png")]
    images = [np.asarray(Image.open(p).convert("RGB")) for p in paths]
    assert all(im.std() > 20 for im in images)
    maps = images[0]
    assert near_cmap(maps, "plasma", 0.5, 1.0).sum() > 1000 and near_cmap(maps, "YlOrRd", 0.5, 1.0).sum() > 1000
    with pytest.raises(ValueError, match="3D"):
        part_plots.contact_maps(ngwear.simulate(ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.5,
                                                                                   "time.steps": 2,
                                                                                   "wear.integrator": "implicit"}),
                                                progress=False), tmp_path / "2d.png")
