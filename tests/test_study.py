"""Study files: cases from grids, lists and samples; invalid studies refused up front naming the field."""
import os
import subprocess
import sys

import numpy as np
import pytest
from conftest import PAPER, ROOT

from ngwear.model.scene import Scene, SceneError
from ngwear.studies import study as study_module
from ngwear.studies.outputs import OUTPUTS
from ngwear.studies.study import StudyError, load_study, study_from_dict

BASE = {"scene": str(PAPER), "set": {"mesh.maxh": 0.2, "time.steps": 10}}


def study(**blocks):
    return study_from_dict({**BASE, **blocks})


def test_grid_is_the_cartesian_product_in_order():
    s = study(grid={"contact.friction": [0.2, 0.4, 0.6], "contact": {"wear": [0.5, 1.5]}})
    assert s.varied == s.grid == ("contact.friction", "contact.wear")
    assert [tuple(c.params.values()) for c in s.cases] == [(m, k) for m in (0.2, 0.4, 0.6) for k in (0.5, 1.5)]
    assert all(c.scene.contact.friction == c.params["contact.friction"] and c.scene.mesh.maxh == 0.2 for c in s.cases)
    assert len({c.id for c in s.cases}) == 6 and len({c.group for c in s.cases}) == 1
    assert s.outputs == tuple(OUTPUTS)


def test_cases_at_every_grid_point_and_groups_by_material():
    s = study(grid={"material.lame_mu": [1.0, 2.0]},
              cases=[{"contact.friction": 0.1}, {"contact.friction": 0.3, "loads.traction.top": [0.0, -0.2]}])
    assert len(s.cases) == 4 and s.grid == ("material.lame_mu",)
    assert s.cases[3].scene.loads.traction == {"top": (0.0, -0.2), "right": (0.0, -0.1)}
    assert len({c.group for c in s.cases}) == 2


def test_latin_hypercube_has_one_point_per_stratum_and_is_seeded():
    sample = {"count": 8, "seed": 3, "ranges": {"contact.gap": [0.1, 0.3], "time.steps": [10, 17]}}
    s = study(sample=sample, set={"mesh.maxh": 0.2})
    gaps = np.array([c.params["contact.gap"] for c in s.cases])
    assert sorted(np.floor((gaps - 0.1) / 0.2 * 8).astype(int)) == list(range(8))
    assert sorted(c.params["time.steps"] for c in s.cases) == list(range(10, 18))
    assert [c.params for c in study(sample=sample, set={"mesh.maxh": 0.2}).cases] == [c.params for c in s.cases]
    assert [c.params for c in study(sample=dict(sample, seed=4), set={"mesh.maxh": 0.2}).cases] != [
        c.params for c in s.cases]
    random = study(sample=dict(sample, method="random", count=50), set={"mesh.maxh": 0.2}).cases
    assert all(0.1 <= c.params["contact.gap"] <= 0.3 and isinstance(c.params["time.steps"], int) for c in random)


def test_a_value_invalid_alone_is_a_rejected_case():
    s = study(grid={"contact.gap": [0.2, -1.0]})
    assert s.cases[0].error is None and s.cases[1].scene is None
    assert s.cases[1].error == "contact.gap: must be > 0 (got -1.0)"


def test_set_that_needs_the_varied_keys_is_applied_with_each_case():
    """[material.regions.backing] names a region that only the cases' geometry.backing creates, and vice versa."""
    s = study(set={"mesh.maxh": 0.2, "time.steps": 10, "geometry.backing": 0.2,
                   "material.regions.backing.poisson": 0.3},
              grid={"material.regions.backing.young": [10.0, 100.0], "contact.friction": ["0.2 + 0.1*x", 0.4]},
              cases=[{"material.law": "linear"}, {"material.law": "compaction", "material.compaction_modulus": 5.0}])
    assert s.varied == ("material.regions.backing.young", "contact.friction", "material.law",
                        "material.compaction_modulus")
    assert all(c.error is None for c in s.cases) and len(s.cases) == 8
    backing = [(c.scene.material.regions["backing"].young, c.scene.material.regions["backing"].poisson)
               for c in s.cases]
    assert backing == [(young, 0.3) for young in (10.0, 100.0) for _ in range(4)]
    assert [c.scene.contact.friction for c in s.cases[:4]] == ["0.2 + 0.1*x"] * 2 + [0.4] * 2
    assert [c.scene.material.kind for c in s.cases[:2]] == ["linear", "compaction"]
    assert len({c.group for c in s.cases}) == 4           # μ does not touch the factorisation: young × law
    with pytest.raises(StudyError, match=r"^set\.material\.regions\.backing: unknown region"):
        study(set={"material.regions.backing.young": 1.0, "material.regions.backing.poisson": 0.3},
              grid={"contact.friction": [0.1, 0.2]})


@pytest.mark.parametrize("data, message", [
    ({"grid": {"contact.frictoin": [0.2, 0.4]}},
     "grid.contact.frictoin: unknown key (allowed: law, stiffness, exponent, wear_law, wear_exponents, gap, friction, "
     "wear, direction)"),
    ({"grid": {"contactt.friction": [0.2]}}, "grid.contactt.friction: contactt: unknown section (allowed:"),
    ({"grid": {"contact.friction": [-1.0, -2.0]}}, "grid.contact.friction: must be >= 0 (got -1.0)"),
    ({"grid": {"contact.friction": 0.2}}, "grid.contact.friction: must be a non-empty list of values (got 0.2)"),
    ({"grid": {"contact.friction": []}}, "grid.contact.friction: must be a non-empty list of values (got [])"),
    ({"cases": [{"contact.wear": 1.0}], "grid": {"contact.wear": [1.0]}}, "grid.contact.wear: also varied by cases"),
    ({"cases": {"contact.wear": 1.0}}, "cases: must be a non-empty list of tables ([[cases]])"),
    ({"sample": {"count": 4, "method": "sobol", "ranges": {"contact.gap": [0.1, 0.2]}}},
     "sample.method: must be one of latin_hypercube, random (got 'sobol')"),
    ({"sample": {"count": 0, "ranges": {"contact.gap": [0.1, 0.2]}}}, "sample.count: must be a whole number >= 1"),
    ({"sample": {"count": 4, "ranges": {"contact.gap": [0.3, 0.2]}}},
     "sample.ranges.contact.gap: must be [low, high] with low < high (got [0.3, 0.2])"),
    ({"grid": {"contact.gap": [0.2]}, "outputs": ["heat"]}, "outputs: unknown output 'heat' (allowed: max_wear,"),
    ({"grid": {"contact.gap": [0.2]}, "sweeps": 3}, "sweeps: unknown study field (allowed: name, scene,"),
    ({}, "grid: nothing to vary (give a [grid], [[cases]] or [sample])"),
    ({"grid": {"contact.gap": [0.2]}, "set": {"mesh.maxh": -1}}, "set.mesh.maxh: must be in (0, 3.0] (got -1.0)"),
    ({"grid": {"contact.wear": [1.0], "foundation.velocity": [[0.0, 0.0]]}},
     "grid.foundation.velocity: must have a non-zero part tangential to contact.direction"),
    ({"cases": [{"contact.gap": -1.0}, {"contact.friction": -1.0}]},
     "cases: no valid case; case 0: contact.gap: must be > 0 (got -1.0)"),
    # each case once: a value or a case given twice, or two cases with one scene
    ({"grid": {"contact.friction": [0.5, 0.7, 0.5]}}, "grid.contact.friction: 0.5 is listed twice (give each value once)"),
    ({"grid": {"contact.wear": [0.5, 1, 1.0]}}, "grid.contact.wear: cases 1 (contact.wear = 1) and 2 "
     "(contact.wear = 1.0) give the same scene (give each case once)"),
    ({"cases": [{"contact.gap": 0.1}, {"contact.gap": 0.3}, {"contact": {"gap": 0.1}}]},
     "cases[2]: same as cases[0] (give each case once)"),
    ({"cases": [{"contact.gap": 0.2}, {"contact.wear": 1.5}]},       # both are the paper's scene
     "cases: cases 0 (contact.gap = 0.2) and 1 (contact.wear = 1.5) give the same scene (give each case once)"),
    ({"grid": {"contact.gap": [0.1, 0.3]}, "cases": [{"contact.wear": 0.5}, {"contact.wear": 0.5}]},
     "cases[1]: same as cases[0] (give each case once)"),
    ({"set": {"mesh.maxh": 0.2}, "sample": {"count": 6, "ranges": {"time.steps": [10, 12]}}},
     "sample.ranges: draws "),
    # one scene key given twice: two spellings in a block, or in two blocks, or a key inside another
    ({"grid": {"contact.friction": [0.1], "contact": {"friction": [0.2]}}},
     'grid.contact.friction: given twice, as grid."contact.friction" and grid.contact.friction (give it once)'),
    ({"cases": [{"contact.gap": 0.1}, {"contact.gap": 0.3, "contact": {"gap": 0.4}}]},
     'cases[1].contact.gap: given twice, as cases[1]."contact.gap" and cases[1].contact.gap (give it once)'),
    ({"set": {"mesh.maxh": 0.2, "contact.friction": 0.3}, "grid": {"contact": {"friction": [0.1, 0.2]}}},
     "set.contact.friction: also varied by grid"),
    ({"set": {"mesh": {"maxh": 0.2}}, "sample": {"count": 2, "ranges": {"mesh.maxh": [0.1, 0.3]}}},
     "set.mesh.maxh: also varied by sample.ranges"),
    ({"grid": {"loads.traction": [{"top": [0.0, -0.1]}, {"top": [0.0, -0.2]}]},
      "cases": [{"loads.traction.right": [0.0, -0.3]}]},
     "grid.loads.traction: also varied by cases.loads.traction.right"),
    # more cases than max_cases (default: see the test below)
    ({"max_cases": 5, "grid": {"contact.gap": [0.1, 0.2, 0.3]}, "cases": [{"contact.wear": 1.0}, {"contact.wear": 2.0}]},
     "grid/cases: 3 × 2 = 6 cases, more than max_cases = 5 (give max_cases = 6 in the study to run them all)"),
    ({"max_cases": 0, "grid": {"contact.gap": [0.2]}}, "max_cases: must be a whole number >= 1 (got 0)"),
    ({"max_cases": 1e6, "grid": {"contact.gap": [0.2]}}, "max_cases: must be a whole number >= 1 (got 1000000.0)"),
    ({"name": "../../escaped", "grid": {"contact.gap": [0.2]}},
     "name: must be a plain name of at most 100 letters, digits, '.', '_', '-' or spaces, not a path "
     "(got '../../escaped')"),
])
def test_invalid_study_is_refused_naming_the_field(data, message):
    with pytest.raises(StudyError) as err:
        study_from_dict({**BASE, **data})
    assert "\n" not in str(err.value) and str(err.value).startswith(message), str(err.value)


def test_scene_file_and_inline_scene(tmp_path):
    (tmp_path / "s.toml").write_text('scene = "missing.toml"\n[grid]\n"contact.gap" = [0.2]\n')
    with pytest.raises(StudyError, match=r"^scene: scene file: .*missing.toml does not exist$"):
        load_study(tmp_path / "s.toml")
    (tmp_path / "s.toml").write_text('[scene]\nname = "inline"\n[scene.geometry]\nkind = "strip"\n'
                                     '[grid]\n"contact.gap" = [0.1, 0.2]\n')
    s = load_study(tmp_path / "s.toml")
    assert s.name == "s" and s.base.name == "inline" and [c.scene.contact.gap for c in s.cases] == [0.1, 0.2]


def test_cli_refuses_invalid_study_before_running(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(f'scene = "{PAPER}"\n[grid]\n"contact.frictoin" = [0.2, 0.4]\n')
    done = subprocess.run([sys.executable, "-m", "ngwear.cli", "sweep", str(path), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert done.returncode == 2 and not (tmp_path / "out").exists()
    assert done.stderr.strip().splitlines() == [
        "ngwear: grid.contact.frictoin: unknown key (allowed: law, stiffness, exponent, wear_law, wear_exponents, gap, "
        "friction, wear, direction)"]


def test_shipped_studies_are_valid():
    for path in sorted((ROOT / "geometries" / "studies").glob("*.toml")):
        s = load_study(path)
        assert s.cases and all(c.error is None for c in s.cases), path


@pytest.mark.parametrize("name", ["../../x", "/tmp/x", "a/b", "..", ".hidden", "", "x" * 101, 3, "friction wear.v2_1"])
def test_study_name_follows_the_scene_name_rule(name):
    try:
        Scene.from_dict({"name": name})
        expected = None
    except SceneError as err:
        expected = str(err)
    if expected is None:
        assert study(name=name, grid={"contact.gap": [0.2]}).name == name
    else:
        with pytest.raises(StudyError) as err:
            study(name=name, grid={"contact.gap": [0.2]})
        assert str(err.value) == expected and expected.startswith("name: must be a plain name")


def test_a_study_larger_than_max_cases_is_refused_before_a_case_is_built(monkeypatch):
    def build(*args):
        raise AssertionError("a case was built")

    monkeypatch.setattr(study_module, "_case", build)
    grid = {"contact.friction": [i / 1000 for i in range(1000)], "contact.wear": [1 + i / 100 for i in range(101)]}
    with pytest.raises(StudyError) as err:
        study(grid=grid)
    assert str(err.value) == ("grid: 1000 × 101 = 101000 cases, more than max_cases = 100000 "
                              "(give max_cases = 101000 in the study to run them all)")
    with pytest.raises(AssertionError, match="a case was built"):
        study(grid=grid, max_cases=101_000)


def test_a_larger_study_is_allowed_by_max_cases_and_overrides_win_over_set():
    s = study(max_cases=6, grid={"contact.gap": [0.1, 0.2, 0.3]}, cases=[{"contact.wear": 1.0}, {"contact.wear": 2.0}])
    assert len(s.cases) == 6 and len({c.id for c in s.cases}) == 6
    s = study_from_dict({**BASE, "grid": {"contact.gap": [0.1]}}, overrides={"mesh.maxh": 0.4})
    assert s.base.mesh.maxh == 0.4 == s.cases[0].scene.mesh.maxh, "--set overrides the study's [set]"
    with pytest.raises(StudyError, match=r"^grid\.contact\.gap: also fixed by --set contact\.gap$"):
        study_from_dict({**BASE, "grid": {"contact.gap": [0.1, 0.3]}}, overrides={"contact.gap": 0.2})


@pytest.mark.parametrize("text, message", [
    ('name = "../../escaped"\n[grid]\n"contact.gap" = [0.2]',
     "name: must be a plain name of at most 100 letters, digits, '.', '_', '-' or spaces, not a path "
     "(got '../../escaped')"),
    ('[grid]\n"contact.friction" = [0.5, 0.5]', "grid.contact.friction: 0.5 is listed twice (give each value once)"),
    ('max_cases = 3\n[grid]\n"contact.friction" = [0.1, 0.2]\n"contact.wear" = [1.0, 2.0]',
     "grid: 2 × 2 = 4 cases, more than max_cases = 3 (give max_cases = 4 in the study to run them all)"),
])
def test_cli_refuses_a_bad_study_in_one_line_and_writes_nothing(tmp_path, text, message):
    folder = tmp_path / "a" / "b"
    folder.mkdir(parents=True)
    (folder / "study.toml").write_text(f'scene = "{PAPER}"\n{text}\n')
    done = subprocess.run([sys.executable, "-m", "ngwear.cli", "sweep", "study.toml"], capture_output=True, text=True,
                          cwd=folder, timeout=120, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 2 and done.stderr.strip().splitlines() == [f"ngwear: {message}"]
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == ["a", "a/b", "a/b/study.toml"]
