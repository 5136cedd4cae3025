"""The explorer's sliders come from data: which a scene gets, their ranges, and that each sets what it shows."""
import pytest
from conftest import ROOT

import ngwear
from ngwear.views.sliders import sliders_for

SCENES = sorted((ROOT / "geometries").glob("*.toml"))


def ranges(scene):
    return {s.name: (s.minimum, s.maximum, s.step) for s in sliders_for(scene)}


def test_paper_scene_sliders():
    assert ranges(ngwear.load_scene(ROOT / "geometries" / "paper_strip.toml")) == {
        "load": (0.0, 0.3, 0.005), "speed": (0.1, 3.0, 0.05), "wear": (0.0, 5.0, 0.05),
        "friction": (0.0, 2.0, 0.05), "gap": (0.02, 0.5, 0.01), "steps": (10, 200, 10)}


def test_ranges_follow_the_scene():
    box = ranges(ngwear.load_scene(ROOT / "geometries" / "box3d.toml"))
    assert box["gap"] == (0.01, 0.25, 0.005) and box["steps"] == (4, 80, 4)
    hertz = ranges(ngwear.load_scene(ROOT / "geometries" / "hertz.toml"))
    assert list(hertz) == ["load"] and hertz["load"] == (0.0, 0.03, 0.0005)


def test_nothing_to_scale_means_no_slider(paper_scene):
    unloaded = paper_scene.replace(**{"loads.traction": {}})
    assert "load" not in ranges(unloaded) and "speed" in ranges(unloaded)


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_every_slider_sets_the_value_it_shows(path):
    base = ngwear.load_scene(path)
    for slider in sliders_for(base):
        value = slider.maximum if slider.integer else 0.5 * (slider.minimum + slider.maximum)
        scene = base.replace(**slider.changes(base, value))
        assert slider.value(scene) == pytest.approx(value), slider.name
        others = [s for s in sliders_for(base) if s.name != slider.name]
        assert all(s.value(scene) == pytest.approx(s.value(base)) for s in others), slider.name
