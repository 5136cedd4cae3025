"""The explorer's sliders come from data: which a scene gets, their ranges, and that each sets what it shows."""
import numpy as np
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


def test_a_field_slider_scales_the_field_and_keeps_its_shape(paper_scene):
    from ngwear.model.coefficients import at_points

    points = np.column_stack([np.linspace(0, 3, 7), np.zeros(7)])
    field = "where(x < 1.5, 0.2, 0.4) + 0.1 * x"
    base = paper_scene.replace(**{"contact.friction": field, "contact.wear": [0.5, 1.0, 1.5]})
    sliders = {s.name: s for s in sliders_for(base)}
    friction, wear = sliders["friction"], sliders["wear"]
    assert friction.label == "friction μ × field" and (friction.minimum, friction.maximum) == (0.0, 2.0)
    assert friction.value(base) == 1.0 and friction.changes(base, 1.0) == {"contact.friction": field}
    scaled = base.replace(**friction.changes(base, 1.5))
    assert friction.value(scaled) == 1.5
    assert at_points(scaled.contact.friction, "friction", points) == pytest.approx(
        1.5 * at_points(field, "friction", points), rel=1e-15)
    assert base.replace(**wear.changes(base, 2.0)).contact.wear == (1.0, 2.0, 3.0)
    assert wear.value(base.replace(**wear.changes(base, 2.0))) == 2.0
    assert np.isnan(friction.value(base.replace(**{"contact.friction": "0.3"})))   # not a scaling of the field


def test_compaction_slider_only_for_the_compaction_law(paper_scene):
    assert "compaction" not in ranges(paper_scene)
    base = paper_scene.replace(**{"material.law": "compaction", "material.compaction_modulus": 2.0,
                                  "material.lame_mu": 0.5})
    assert ranges(base)["compaction"] == (0.0, 10.0, 0.25)                  # η × [0, 20, 0.5]
    slider = next(s for s in sliders_for(base) if s.name == "compaction")
    assert base.replace(**slider.changes(base, 7.5)).material.compaction_modulus == 7.5


def test_backing_slider_adds_and_removes_the_backing_with_its_material():
    base = ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml").replace(**{
        "geometry.backing": 0.004, "material.regions": {"backing": {"young": 2.1e11, "poisson": 0.3}}})
    slider = next(s for s in sliders_for(base) if s.name == "backing")
    assert (slider.minimum, slider.maximum, slider.step) == (0.0, 0.012, 0.0006)   # t × [0, 1, 0.05]
    bare = base.replace(**slider.changes(base, 0.0))
    assert bare.geometry.backing is None and bare.material.regions == {} and slider.value(bare) == 0.0
    again = bare.replace(**slider.changes(base, 0.006))
    assert again.geometry.backing == 0.006 and again.material.regions["backing"].young == 2.1e11
