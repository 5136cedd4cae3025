"""An SI scene whose moduli, contact stiffness or wear coefficient lie far from engineering materials' is warned of.

Each warning names the key, before the run (which goes on); the shipped SI scenes and dimensionless scenes get none.
"""
import pytest

import ngwear
from ngwear.model.plausibility import warnings

SHIPPED_SI = ["brake_pad", "brake_pad_compaction", "pin_on_disc"]   # the CAD pads: the same numbers


@pytest.mark.parametrize("name", SHIPPED_SI)
def test_the_shipped_si_scenes_are_plausible(name):
    assert warnings(ngwear.load_scene(name)) == []


def test_a_modulus_in_gpa_given_as_pa_is_named():
    """A unit slip: the steel backing's E = 210 (GPa meant) ran to an 8.9 m plate displacement unwarned."""
    scene = ngwear.load_scene("brake_pad").replace(**{"material.regions.backing.young": 210.0})
    assert warnings(scene) == [
        "material.regions.backing.young = 210 Pa: far below the moduli of engineering materials (1e5 Pa, foams, to "
        "1.2e12 Pa, diamond); is it in GPa or MPa? (units = \"SI\": Pa, m, N, s)"]


@pytest.mark.parametrize("sets, start", [
    ({"material.young_axis": 1e15, "material.young_plane": 2e15, "material.shear_axis": 5e14},
     "material.young_plane = 2e+15 Pa: far above the moduli"),
    ({"contact.stiffness": 1e5}, "contact.stiffness = 100000 Pa/m^1 (L g^e = 100 Pa, the layer compressed through): "
                                 "far below the moduli of engineering materials"),
    ({"contact.wear": 8e-4}, "contact.wear = 0.0008 1/Pa: far above Archard's wear coefficients of engineering pairs"),
    ({"contact.wear": 1e-22}, "contact.wear = 1e-22 1/Pa: far below Archard's"),
])
def test_stiffness_and_wear_far_from_engineering_values_are_named(sets, start):
    found = warnings(ngwear.load_scene("brake_pad").replace(**sets))
    assert any(w.startswith(start) for w in found), found


def test_dimensionless_scenes_and_zero_constants_are_not_warned_of(paper_scene):
    assert warnings(paper_scene) == []
    compaction = ngwear.load_scene("brake_pad_compaction")
    assert warnings(compaction.replace(**{"material.compaction_modulus": 0.0, "contact.wear": 0.0})) == []


def test_a_run_says_them_before_its_first_step_and_in_its_summary(paper_scene, caplog):
    """The paper's numbers read as SI: λ = η = 1 Pa and L g = 2 Pa are named (κ = 0: no wear, nothing to say)."""
    scene = paper_scene.replace(**{"units": "SI", "contact.wear": 0.0, "mesh.maxh": 0.5, "time.steps": 2})
    result = ngwear.simulate(scene, progress=False)
    said = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    named = [w.split(" = ")[0] for w in result.warnings]
    assert named == ["material.lame_lambda", "material.lame_mu", "contact.stiffness"]
    assert said[:3] == result.warnings and result.summary()["status"] == "completed"
