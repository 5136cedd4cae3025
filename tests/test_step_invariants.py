"""A run whose invariants break is a failure: the time loop checks every step before recording it.

The wear update is broken on purpose (a monkeypatched integrator whose sixth wear values come out 1e-3 lower
than the scheme's): the run must stop at that step naming the invariant, keep the five steps before it bit for
bit, and ``ngwear run`` must exit with status 1.
"""
import json
import subprocess
import sys

import numpy as np
import pytest
from conftest import PAPER

import ngwear
from ngwear.numerics.contact import Instant
from ngwear.numerics.wear import WearStep
from ngwear.runs.checks import Checker, StepCheck, allowances, invariants
from ngwear.runs.step import State

BREAK = """
import sys
from ngwear.numerics.wear import WearStep
solved, wear_at = [0], WearStep.wear_at
def broken(self, z):
    solved[0] += 1
    return wear_at(self, z) - (1e-3 if solved[0] == 6 else 0.0)
WearStep.wear_at = broken
from ngwear.cli import main
sys.exit(main())
"""


def small(paper_scene):
    return paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 20})


def test_a_broken_step_stops_the_run_and_keeps_the_steps_before_it(paper_scene, monkeypatch):
    good = ngwear.simulate(small(paper_scene), progress=False)
    solved, wear_at = [0], WearStep.wear_at

    def broken(self, z):
        solved[0] += 1
        return wear_at(self, z) - (1e-3 if solved[0] == 6 else 0.0)

    monkeypatch.setattr(WearStep, "wear_at", broken)
    result = ngwear.simulate(small(paper_scene), progress=False)
    assert not result.completed and result.steps == 4
    name = result.status.removeprefix("step 5 (t = 0.25): invariant ").split()[0]
    assert name in ("wear_monotone", "archard", "pressure_law") and " broken by " in result.status, result.status
    assert "try " in result.status                                              # a remedy
    for name in ("times", "wear", "normal_displacement", "pressure", "reaction"):
        assert np.array_equal(getattr(result, name), getattr(good, name)[:5]), name
    allowed = allowances(result.scene)
    assert all(v <= allowed[k] for k, v in invariants(result).items())


def test_the_cli_exits_1_and_writes_the_kept_steps(tmp_path):
    proc = subprocess.run([sys.executable, "-c", BREAK, "run", str(PAPER), "--set", "mesh.maxh=0.2", "time.steps=20",
                           "--quiet", "--no-pictures", "--out", str(tmp_path / "out")],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 1, proc.stderr
    assert "ngwear: run stopped early: step 5 (t = 0.25): invariant " in proc.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["steps"] == 4 and summary["status"].startswith("step 5 ")
    assert ngwear.load_result(tmp_path / "out").wear.shape[0] == 5


@pytest.mark.parametrize("integrator, steps", [("explicit", 20), ("implicit", 5), ("trapezoidal", 8)])
def test_valid_runs_keep_every_invariant_at_every_step(paper_scene, integrator, steps):
    """The monotone updates (explicit k·α·L ≤ 1, trapezoidal ≤ 2, implicit always) never pass the penetration.

    k·α·L = 0.75, 3, 1.875: the check of w ≤ max (u_ν − d₀)₊ applies to each and holds; a resumed check (from
    the kept rows) gives the same verdicts as the one that saw every step.
    """
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": steps, "wear.integrator": integrator})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed
    checker = Checker(scene, result.discretization)
    assert checker.bounded
    values = invariants(result)
    assert "wear_le_penetration" in values and checker.broken(values) is None
    later = StepCheck(type("Rows", (), {"scene": scene, **{k: getattr(result, k)[:3] for k in (
        "times", "wear", "normal_displacement", "pressure", "reaction", "speed_factor")}})(), result.discretization)
    for j in range(3, result.steps + 1):
        state = State(None, result.reaction[j], result.discretization.contact.coefficients, result.wear[j],
                      Instant(result.times[j], result.speed_factor[j], result.load_factor[j]),
                      normal=result.normal_displacement[j], pressure=result.pressure[j])
        assert later(state) is None


def test_an_allowed_unstable_run_is_not_held_to_the_monotone_bound(paper_scene):
    """Explicit at k·α·L = 3 (allowed): the wear passes the penetration, which this update does not promise."""
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 10, "contact.wear": 3.0,
                                   "wear.allow_unstable": True})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed and not Checker(scene, result.discretization).bounded
    reached = np.maximum.accumulate(np.maximum(result.normal_displacement - result.d0, 0), axis=0)
    assert (result.wear - reached).max() > 0.1 * scene.contact.gap



@pytest.fixture(scope="module")
def soft(paper_scene):
    """The paper's strip made very soft (λ = η = 1e-8): the loads alone would move Γ_C by ~10⁹ g."""
    scene = small(paper_scene).replace(**{"material.lame_lambda": 1e-8, "material.lame_mu": 1e-8})
    return ngwear.simulate(scene, progress=False)


def test_a_very_soft_body_keeps_the_layer_in_absolute_terms(soft):
    """A merit relative to the loads' displacements let z pass g by 3.5 % here (and the wear pass g).

    The solver measures the overshoot (z − g)₊ against g: the constraint holds to g·tolerance at every step, and
    the wear, bounded by the penetration (k·α·L = 0.75), stays below g.
    """
    scene, g = soft.scene, soft.scene.contact.gap
    assert soft.completed, soft.status
    assert (soft.normal_displacement - soft.d0).max() - g <= scene.solver.tolerance * g
    assert soft.wear.max() <= g
    assert (soft.reaction > 0).any(), "the soft body reaches the rigid foundation"


def test_the_gap_check_is_absolute(soft):
    """A row whose z passes g by 10⁻⁶ g breaks ``gap``, however large the loads' displacements S are."""
    scene, last = soft.scene, slice(-1, None)
    checker = Checker(scene, soft.discretization)
    assert checker.scale(soft.load_factor).min() > 1e6 * scene.contact.gap
    s = soft.normal_displacement[last].copy()
    rows = (soft.times[last], soft.wear[last], s, soft.pressure[last], soft.reaction[last], soft.speed_factor[last],
            soft.load_factor[last])
    assert checker.violations(*rows)["gap"] == 0
    s[0, np.argmax(s[0] - soft.d0)] += 1e-6 * scene.contact.gap
    values = checker.violations(*rows)
    assert values["gap"] == pytest.approx(1e-6, rel=1e-3)
    assert checker.broken(values)[0] == "gap"
