"""An SI scene whose numbers no engineer means is warned of: moduli, contact stiffness, wear, friction, temperatures, loads.

Each warning names the key and its value, before the run (which goes on) and in ``summary.json``; the shipped SI
scenes and dimensionless scenes get none; a run that then fails names the implausible key as its likeliest cause.
"""
import json

import pytest

import ngwear
from ngwear.model.plausibility import load_warnings, warnings

pytestmark = pytest.mark.hostile

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
    """The paper's numbers read as SI: λ = η = 1 Pa, L g = 2 Pa and tractions of 0.1 Pa are named (κ = 0: no wear)."""
    scene = paper_scene.replace(**{"units": "SI", "contact.wear": 0.0, "mesh.maxh": 0.5, "time.steps": 2})
    result = ngwear.simulate(scene, progress=False)
    said = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    named = [w.split(" = ")[0] for w in result.warnings]
    assert named == ["material.lame_lambda", "material.lame_mu", "contact.stiffness", "loads.traction.top",
                     "loads.traction.right"]
    assert said[:5] == result.warnings and result.summary()["status"] == "completed"


@pytest.mark.parametrize("sets, start", [
    ({"contact.friction": 4.0}, "contact.friction = 4: outside the [0, 1.5] of engineering pairs' μ"),
    ({"heat.ambient": 293.15}, "heat.ambient = 293.15 °C looks like a temperature in kelvin (20 °C; ngwear's "
                               "temperatures are °C)"),
    ({"heat.initial": 300.0}, "heat.initial = 300 °C looks like a temperature in kelvin (26.85 °C"),
])
def test_friction_and_temperatures_no_engineer_means_are_named(sets, start):
    found = warnings(ngwear.load_scene("brake_pad_heat").replace(**sets))
    assert any(w.startswith(start) for w in found), found


def test_hot_and_cold_temperatures_in_celsius_are_not_taken_for_kelvin():
    for ambient in (20.0, -30.0, 180.0, 400.0):
        assert warnings(ngwear.load_scene("brake_pad_heat").replace(**{"heat.ambient": ambient})) == []


@pytest.mark.parametrize("force, side", [(1.5, "below"), (3e9, "above")])
def test_a_plate_force_whose_mean_pressure_no_engineer_means_is_named(force, side):
    """1.5 N on the pad (an MPa meant, N typed): 229 Pa of mean pressure; 3 GN: 458 GPa."""
    scene = ngwear.load_scene("brake_pad").replace(**{"loads.plate.force": [0.0, 0.0, -force]})
    disc = ngwear.Discretization(scene)
    area = float(disc.points.weights.sum())
    found = load_warnings(scene, area)
    assert found == [f"loads.plate.force = [0.0, 0.0, {-force}] (a mean contact pressure of {force / area:.3g} Pa over "
                     f"Γ_C): far {side} contact pressures in engineering (10 kPa to 100 MPa)"
                     + ("; is it in kN? (units = \"SI\": Pa, m, N, s)" if side == "below" else "")]
    assert load_warnings(ngwear.load_scene("brake_pad"), area) == []


def test_a_failure_in_a_scene_with_an_implausible_number_names_it_not_the_solver(tmp_path, capsys):
    """The pad's moduli typed in GPa: the last line blames material.young_plane, not solver.tolerance."""
    from ngwear.cli import main

    code = main(["run", "brake_pad", "--out", str(tmp_path / "out"), "--quiet", "--no-pictures", "--no-check",
                 "--set", "material.young_plane=2", "material.young_axis=1"])
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert code == 1 and last.startswith("ngwear: run stopped early: step 0 (t = 0): Newton did not converge")
    assert last.endswith("; the likeliest cause: material.young_plane = 2 Pa: far below the moduli of engineering "
                         "materials (1e5 Pa, foams, to 1.2e12 Pa, diamond); is it in GPa or MPa? (units = \"SI\": Pa, "
                         "m, N, s)") and "solver.tolerance" not in last


def test_every_warning_printed_is_in_summary_json(tmp_path, capsys):
    """The paper strip wears through its layer: the warning ngwear run prints is in summary.json's warnings."""
    from ngwear.cli import main

    assert main(["run", "paper_strip", "--out", str(tmp_path / "out"), "--no-pictures", "--no-check", "--set",
                 "mesh.maxh=0.2"]) == 0
    printed = [line.split("  ", 1)[1].strip() for line in capsys.readouterr().out.splitlines()
               if line.startswith("warning ")]
    saved = json.loads((tmp_path / "out" / "summary.json").read_text())["warnings"]
    assert printed and printed == saved and "worn through" in saved[0]
