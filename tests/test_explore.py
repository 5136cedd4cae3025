"""The explorer: slider values set from Python re-solve with the physics expected and reuse the factorisation.

The paper's scene at a coarse resolution with κ = 0.3, so that the layer is not worn through and
the maxima respond to every parameter.
"""
import io
import statistics
import subprocess
import sys
import threading

import numpy as np
import pytest
from conftest import PAPER
from PIL import Image

import ngwear
from ngwear.model.scene import SceneError
from ngwear.views.explore import Explorer


@pytest.fixture
def explorer():
    ex = Explorer(ngwear.load_scene(PAPER).replace(**{"contact.wear": 0.3}), maxh=0.2, steps=20,
                  window_size=(400, 170))
    yield ex
    ex.close()


def maxima(result, step=-1):
    penetration = result.normal_displacement[step] - result.d0
    return result.wear[step].max(), penetration.max()


def test_initial_state(explorer):
    assert explorer.values == pytest.approx({"load": 0.1, "speed": 1.0, "wear": 0.3, "friction": 1.0,
                                             "gap": 0.2, "steps": 20})
    assert explorer.result.completed and explorer.step == 20 and len(explorer.updates) == 1
    assert explorer.updates[0].refactorised and explorer.updates[0].changes == {}


def test_more_load_more_wear_and_penetration(explorer):
    before = maxima(explorer.result)
    after = maxima(explorer.set(load=0.2))
    assert after[0] > 1.5 * before[0] and after[1] > 1.5 * before[1]
    traction = dict(explorer.scene.loads.traction)
    assert traction == {"top": pytest.approx((0.0, -0.2)), "right": pytest.approx((0.0, -0.2))}
    assert explorer.values["load"] == pytest.approx(0.2)


def test_no_wear_without_kappa(explorer):
    assert explorer.result.wear.max() > 0
    assert not explorer.set(wear=0.0).wear.any()


def test_faster_foundation_wears_faster(explorer):
    slow = maxima(explorer.result, step=10)[0]
    fast = maxima(explorer.set(speed=2.0), step=10)[0]
    assert fast > 1.5 * slow
    assert explorer.scene.foundation.velocity == pytest.approx((2.0, 0.0))


def test_friction_change_reuses_mesh_and_factorisation(explorer):
    mesh, operator = explorer.disc.mesh, explorer.disc.operator
    explorer.set(friction=0.2)
    explorer.set(**{"contact.wear": 1.0}, load=0.15, speed=1.5, gap=0.15, steps=30)
    assert explorer.disc.mesh is mesh and explorer.disc.operator is operator
    assert [u.refactorised for u in explorer.updates] == [True, False, False]
    assert explorer.scene.contact.friction == 0.2 and explorer.result.steps == 30


def test_smaller_gap_bounds_the_normal_displacement(explorer):
    explorer.set(load=0.3)
    assert explorer.result.normal_displacement.max() > 0.1
    result = explorer.set(gap=0.1)
    assert result.normal_displacement.max() <= 0.1 + 1e-10
    assert result.reaction.max() > 0


def test_steps_change_keeps_the_time_on_show(explorer):
    explorer.scrub(10)
    explorer.set(steps=40)
    assert explorer.step == 20 and explorer.result.times[explorer.step] == pytest.approx(0.5)
    explorer.scrub(-1)
    assert explorer.step == 40


def test_invalid_values_leave_the_explorer_as_it_was(explorer):
    result = explorer.result
    with pytest.raises(SceneError, match="contact.gap"):
        explorer.set(gap=-1.0)
    with pytest.raises(SceneError, match="colour: not a parameter"):
        explorer.set(colour="red")
    assert explorer.result is result and len(explorer.updates) == 1
    assert explorer.set(wear=0.3) is result and len(explorer.updates) == 1


def test_pictures_follow_the_parameters_and_record_their_time(explorer):
    picture, plots = explorer.picture(), explorer.plots()
    assert picture.shape == (170, 400, 3) and plots.shape[1] == 400
    first = explorer.updates[0]
    assert first.solve > 0 and first.picture > 0 and first.plots > 0
    assert first.total == pytest.approx(first.solve + first.picture + first.plots)
    explorer.set(load=0.3)
    assert explorer.updates[-1].picture is None
    assert np.abs(explorer.picture().astype(int) - picture).mean() > 0.5
    assert np.abs(explorer.plots().astype(int) - plots).mean() > 0.1
    assert explorer.updates[-1].picture > 0 and "factorisation reused" in explorer.summary()


def test_pictures_from_any_thread_are_the_same(explorer):
    """JupyterLab runs widget callbacks on a subshell thread: pictures must not depend on the calling thread."""
    pictures = [explorer.picture()]

    def draw():
        pictures.append(explorer.picture())

    for _ in range(3):
        worker = threading.Thread(target=draw)
        worker.start()
        worker.join()
        pictures.append(explorer.picture())
    assert len(pictures) == 7
    assert all(np.array_equal(pictures[0], p) for p in pictures[1:])
    colours = np.unique(pictures[0].reshape(-1, 3), axis=0)
    assert len(colours) > 50 and pictures[0].std() > 20, "a real picture, not blank or uniform"


def test_module_does_not_import_ipywidgets():
    code = "import sys, ngwear.views.explore; assert 'ipywidgets' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


def png(widget):
    return np.asarray(Image.open(io.BytesIO(widget.value)).convert("RGB"))


def test_widget_sliders_drive_the_explorer(explorer):
    pytest.importorskip("ipywidgets")
    box = explorer.widget()
    controls = explorer.controls
    assert box.children and {"load", "speed", "wear", "friction", "gap", "steps", "time"} <= set(controls)
    assert controls["wear"].value == pytest.approx(0.3) and controls["time"].max == 20
    before = png(controls["picture"])
    assert before.shape == (170, 400, 3)

    controls["wear"].value = 0.0
    assert explorer.scene.contact.wear == 0.0 and not explorer.result.wear.any()
    assert np.abs(png(controls["picture"]).astype(int) - before).mean() > 0.5
    assert controls["progress"].value == 3 and "max wear 0," in controls["status"].value

    controls["steps"].value = 40
    assert explorer.result.steps == 40 and controls["time"].max == 40 and controls["time"].value == 40
    controls["time"].value = 10
    assert explorer.step == 10 and "t = 0.25" in explorer.canvas._parts["caption"].GetInput()

    controls["speed"].value = 0.1
    controls["gap"].value = 0.02
    assert explorer.result.normal_displacement.max() <= 0.02 + 1e-10


def test_widget_shows_an_invalid_value_instead_of_failing(explorer):
    pytest.importorskip("ipywidgets")
    explorer.widget()
    controls, result = explorer.controls, explorer.result
    controls["gap"].min = -1.0
    controls["gap"].value = -0.5
    assert "contact.gap: must be > 0" in controls["status"].value
    assert controls["progress"].bar_style == "danger" and explorer.result is result


@pytest.mark.slow
def test_default_resolution_updates_quickly():
    """At the paper's resolution a slider change gives a new picture in ≤ 0.5 s (here ≤ 1 s, CI noise)."""
    ex = Explorer(ngwear.load_scene(PAPER))
    ex.picture()
    totals = []
    for value in (0.12, 0.08, 0.1):
        ex.set(load=value)
        ex.picture()
        totals.append(ex.updates[-1].solve + ex.updates[-1].picture)
    ex.close()
    assert ex.disc.free.sum() > 2500 and statistics.median(totals) < 1.0
