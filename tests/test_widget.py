"""The explorer's ipywidgets always show the state that produced the picture, and act on the explorer."""
import io

import numpy as np
import pytest
from conftest import PAPER, ROOT
from PIL import Image
from test_explore import failing_explorer

import ngwear
from ngwear.views.explore import Explorer

pytest.importorskip("ipywidgets")


@pytest.fixture
def explorer():
    ex = Explorer(ngwear.load_scene(PAPER).replace(**{"contact.wear": 0.3}), maxh=0.2, steps=20,
                  window_size=(400, 170))
    yield ex
    ex.close()


def png(widget):
    return np.asarray(Image.open(io.BytesIO(widget.value)).convert("RGB"))


def slider_values(controls, explorer):
    return {s.name: controls[s.name].value for s in explorer.sliders}


def test_sliders_drive_the_explorer(explorer):
    box = explorer.widget()
    controls = explorer.controls
    assert box.children and {"load", "speed", "wear", "friction", "gap", "steps", "time"} <= set(controls)
    assert slider_values(controls, explorer) == pytest.approx(explorer.values)
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


def test_set_from_code_moves_the_sliders(explorer):
    """`explorer.set(speed=2.0)` in a cell shows 2 on the slider, and the next slider move keeps it."""
    explorer.widget()
    controls = explorer.controls
    picture = png(controls["picture"])
    explorer.set(speed=2.0, **{"contact.friction": 0.5})
    assert controls["speed"].value == 2.0 and controls["friction"].value == 0.5
    assert np.abs(png(controls["picture"]).astype(int) - picture).mean() > 0.5
    controls["wear"].value = 1.0
    assert explorer.scene.foundation.velocity == pytest.approx((2.0, 0.0)) and explorer.scene.contact.friction == 0.5
    assert slider_values(controls, explorer) == pytest.approx(explorer.values)
    explorer.set(**{"contact.gap": 0.9})
    assert controls["gap"].value == 0.9 and controls["gap"].max >= 0.9
    explorer.scrub(7)
    assert controls["time"].value == 7


def test_an_invalid_value_shows_the_error_and_keeps_the_picture(explorer):
    explorer.widget()
    controls, result = explorer.controls, explorer.result
    picture = controls["picture"].value
    controls["gap"].min = -1.0
    controls["gap"].value = -0.5
    assert "contact.gap: must be &gt; 0 (got -0.5)" in controls["message"].value
    assert controls["progress"].bar_style == "danger" and explorer.result is result
    assert controls["gap"].value == 0.2 and controls["picture"].value is picture


def test_a_failed_run_shows_the_error_and_keeps_the_picture():
    explorer = failing_explorer()
    explorer.widget()
    controls, result = explorer.controls, explorer.result
    picture = controls["picture"].value
    controls["wear"].value = 5.0
    message = controls["message"].value
    assert "wear = 5: the run stopped at step" in message and "Newton did not converge" in message
    assert controls["wear"].value == 0.0 and explorer.result is result and controls["picture"].value is picture
    controls["wear"].value = 0.05
    assert explorer.result.completed and controls["message"].value == "" and controls["picture"].value != picture
    explorer.close()


def test_buttons_save_scene_picture_and_result(explorer, tmp_path):
    explorer.widget(folder=tmp_path)
    controls = explorer.controls
    controls["load"].value = 0.15
    for _ in range(2):
        controls["save_scene"].click()
    assert ngwear.load_scene(tmp_path / "paper_strip-2.toml") == explorer.scene
    assert f"saved scene: {tmp_path / 'paper_strip-2.toml'}" in controls["message"].value
    controls["save_picture"].click()
    saved = np.asarray(Image.open(tmp_path / "paper_strip-1.png").convert("RGB"))
    assert np.array_equal(saved, png(controls["picture"]))
    controls["save_result"].click()
    assert {"result.npz", "scene.json", "fields.pvd", "fig1_step005.png"} <= {
        p.name for p in (tmp_path / "paper_strip-1").iterdir()}
    controls["folder"].value = str(ROOT / "README.md" / "cannot")
    controls["save_scene"].click()
    assert "save into: cannot write" in controls["message"].value


def test_pin_button_switches_the_plots_to_a_b(explorer):
    explorer.widget()
    controls = explorer.controls
    controls["pin"].click()
    assert explorer.pinned is explorer.result and controls["pin"].description == "unpin A"
    controls["speed"].value = 2.0
    assert "A/B: B differs from A in speed 1 → 2" in controls["status"].value
    controls["pin"].click()
    assert explorer.pinned is None and "A/B" not in controls["status"].value


def test_a_confined_widget_saves_only_inside_its_folder(explorer, tmp_path):
    root, elsewhere = tmp_path / "app", tmp_path / "elsewhere"
    root.mkdir()
    elsewhere.mkdir()
    (root / "link").symlink_to(elsewhere)
    (root / "paper_strip-1.toml").symlink_to(elsewhere / "dangling.toml")
    explorer.widget(folder=root, confined=True)
    controls = explorer.controls
    assert controls["folder"].value == str(root.resolve())
    for spelled in (str(elsewhere), "link", "link/sub", "../elsewhere", f"{root}/x/../../elsewhere", "~", "/"):
        controls["folder"].value = spelled
        controls["save_scene"].click()
        assert f"save into: {spelled} is outside {root.resolve()}, the folder this app saves into" in \
            controls["message"].value, spelled
    for spelled, written in (("", root / "paper_strip-2.toml"), ("sub/deeper", root / "sub/deeper/paper_strip-1.toml"),
                             (f"{root}/x/..", root / "paper_strip-3.toml")):
        controls["folder"].value = spelled
        controls["save_scene"].click()
        assert controls["message"].value.endswith(f"saved scene: {written}</div>") and written.is_file(), spelled
    assert not any(elsewhere.iterdir()), "nothing written through a symlink"
