"""Error-controlled time steps: the tolerance is met against a fine uniform reference, with few steps.

On the paper's scene (coarse mesh) the final wear of an adaptive run is within ``time.tolerance · g``
of a trapezoidal reference with 8000 steps.  On a scene whose wear rate changes a lot — a brake pad
running in, then worn in — the adaptive run needs far fewer steps than a uniform run of the same error.
Frames land exactly on their times, steps on the tables' kinks, the explicit update stays within its
stability limit, rejected steps are counted, and a stopped adaptive run resumes to the same bits.
"""
import threading

import numpy as np
import pytest
from conftest import PAPER

import ngwear
from ngwear.model.compliance import largest_slope
from ngwear.results.recording import Recording
from ngwear.runs.validity import WORN


@pytest.fixture(scope="module")
def paper():
    return ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.2})


@pytest.fixture(scope="module")
def reference(paper):
    return ngwear.simulate(paper.replace(**{"time.steps": 8000, "wear.integrator": "trapezoidal"}), progress=False)


def error(result, reference):
    return np.abs(result.wear[-1] - reference.wear[-1]).max() / result.scene.contact.gap


SPENT = {"explicit": 4, "implicit": 4, "trapezoidal": 20}
"""How far below its tolerance an adaptive run may end on the paper's scene (measured: 1.8–2.5 for the first-order
integrators, 2–13 for the trapezoidal rule).  First order: each point spreads what is left of its tolerance over the
time left, so a point whose wear changes for part of the run only spends part of it (a factor up to about 2), and
local errors of opposite sign cancel.  Trapezoidal: its estimate k³/12 r'' reads the kinks of the wear rate (contact
onset, the layer worn through) as large curvature, whose true contribution is smaller and cancels."""


@pytest.mark.parametrize("integrator", ["explicit", "implicit", "trapezoidal"])
@pytest.mark.parametrize("tolerance", [1e-2, 1e-3])
def test_adaptive_run_meets_its_tolerance(paper, reference, integrator, tolerance):
    """Met, and spent: not beaten by more than :data:`SPENT`."""
    scene = paper.replace(**{"time.adaptive": True, "time.tolerance": tolerance, "wear.integrator": integrator})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed and result.times[-1] == scene.time.T
    assert all(w.startswith(WORN) for w in result.warnings)    # the layer, worn through from t ≈ 0.88: nothing else
    assert tolerance / SPENT[integrator] <= error(result, reference) <= tolerance
    assert np.all(np.diff(result.times) > 0) and np.diff(result.times).max() <= scene.time.max_step * (1 + 1e-12)


def test_adaptive_runs_take_the_trapezoidal_rule_unless_the_scene_names_one(paper):
    """The scene's `wear.integrator` unnamed: explicit (the paper's) for uniform steps, trapezoidal for adaptive ones."""
    assert "integrator" not in paper.to_dict()["wear"] and paper.wear.integrator == "explicit"
    adaptive = paper.replace(**{"time.adaptive": True})
    assert adaptive.wear.integrator == "trapezoidal" and "integrator" not in adaptive.to_dict()["wear"]
    assert ngwear.Scene.from_dict(adaptive.to_dict()) == adaptive
    named = paper.replace(**{"wear.integrator": "explicit"}).replace(**{"time.adaptive": True})
    assert named.wear.integrator == "explicit" and named.to_dict()["wear"]["integrator"] == "explicit"
    full = paper.replace(**{"time.adaptive": True, "solver.method": "full"})   # the full path has explicit wear only
    assert full.wear.integrator == "explicit"
    assert ngwear.Scene.model_fields["wear"].default.integrator is None      # the shared default is left alone
    assert ngwear.load_scene(PAPER).wear.integrator == "explicit"


def test_the_default_adaptive_run_beats_uniform_steps_of_the_same_error(paper, reference):
    """`time.adaptive = true` and nothing else: fewer steps than uniform steps (the default scheme) of the same error.

    Before, the adaptive run took the explicit update too, with more steps than uniform ones (tolerance 1e-3:
    1 459 steps where 800 uniform ones gave the same error, at maxh 0.05).  The explicit update's uniform error
    is first order: ten times the adaptive steps are still less accurate.
    """
    adaptive = ngwear.simulate(paper.replace(**{"time.adaptive": True, "time.tolerance": 1e-3}), progress=False)
    steps = adaptive.steps + adaptive.rejected                                     # every solve counts
    uniform = ngwear.simulate(paper.replace(**{"time.steps": 10 * steps}), progress=False)
    assert error(uniform, reference) > error(adaptive, reference)


def test_far_fewer_steps_than_a_uniform_run_of_the_same_error():
    """A brake pad running in (T = 40 τ): fast wear first, then the worn-in steady state, whose rate is constant.

    Uniform steps must resolve the running-in all the way; adaptive ones grow to the stability limit
    once it is over.  Errors: the largest wear error at the frames t = 0.25 … 10 against 16000 steps.
    """
    area = np.pi / 3 * (1.0 - 0.09) / 2
    pad = ngwear.Scene.from_dict({
        "name": "running_in", "geometry": {"kind": "pad", "size": [0.3, 1.0, 60.0, 0.1], "dirichlet": []},
        "mesh": {"maxh": 0.15}, "material": {"young": 1000.0, "poisson": 0.3},
        "contact": {"stiffness": 50.0, "gap": 2.0, "friction": 0.3, "wear": 0.15},
        "foundation": {"velocity": [0, 0, 0], "angular_velocity": [0, 0, 1.0]},
        "loads": {"plate": {"boundary": "back", "force": [0, 0, -area]}}, "wear": {"integrator": "trapezoidal"},
        "time": {"T": 10.0, "steps": 100}, "output": {"times": [0.25, 0.5, 1.0, 2.0, 5.0, 10.0]}})
    reference = ngwear.simulate(pad.replace(**{"time.steps": 16000}), progress=False)

    def frames_error(result):
        return max(np.abs(result.wear[j] - reference.wear[np.abs(reference.times - result.times[j]).argmin()]).max()
                   for j in result.stored_steps) / pad.contact.gap

    adaptive = ngwear.simulate(pad.replace(**{"time.adaptive": True, "time.tolerance": 1e-4}), progress=False)
    target = frames_error(adaptive)
    assert target <= 1e-4 and adaptive.completed
    uniform = {n: frames_error(ngwear.simulate(pad.replace(**{"time.steps": n}), progress=False))
               for n in (100, 200, 400)}
    assert all(error > target for error in uniform.values()), (adaptive.steps, uniform)   # 400 not yet enough
    assert 400 >= 4 * adaptive.steps
    steps = np.diff(adaptive.times)
    assert steps[-1] > 100 * steps[1]                  # small during the running-in, large once worn in


def test_frames_land_on_their_times(paper):
    scene = paper.replace(**{"time.adaptive": True, "output.times": [0.0, 0.137, 0.5, 0.9]})
    result = ngwear.simulate(scene, progress=False)
    assert [result.times[j] for j in result.stored_steps] == [0.0, 0.137, 0.5, 0.9, 1.0]


def test_explicit_steps_stay_below_the_stability_limit(paper):
    scene = paper.replace(**{"time.adaptive": True, "time.tolerance": 0.2, "time.max_step": 1.0,
                             "wear.integrator": "explicit"})
    result = ngwear.simulate(scene, progress=False)
    contact = result.discretization.contact
    alpha = contact.alpha(contact.coefficients, contact.motion.largest_speed).max()
    assert np.diff(result.times).max() * alpha * largest_slope(scene.contact) <= 1 + 1e-12
    assert result.wear.max() <= scene.contact.gap * (1 + 1e-12)


def test_too_large_a_first_step_is_rejected_and_redone(paper):
    scene = paper.replace(**{"time.adaptive": True, "time.steps": 2, "time.max_step": 0.5,
                             "wear.integrator": "implicit"})
    result = ngwear.simulate(scene, progress=False)
    assert result.rejected >= 1 and result.times[1] < 0.5 and result.summary()["rejected_steps"] == result.rejected


def test_min_step_above_the_stability_limit_is_refused(paper):
    scene = paper.replace(**{"time.adaptive": True, "time.min_step": 0.5, "time.max_step": 1.0,
                             "wear.integrator": "explicit"})
    with pytest.raises(ngwear.SceneError, match=r"^time\.min_step: 0\.5 is above the explicit update's stability"):
        ngwear.simulate(scene, progress=False)


def test_stopped_adaptive_run_resumes_bit_identical(paper, tmp_path, monkeypatch):
    scene = paper.replace(**{"time.adaptive": True, "wear.integrator": "trapezoidal", "time.tolerance": 1e-4})
    full = ngwear.simulate(scene, progress=False)
    stop, original, count = threading.Event(), Recording.append, []

    def counting(recording, *step):
        original(recording, *step)
        count.append(1)
        if len(count) == 11:
            stop.set()

    monkeypatch.setattr(Recording, "append", counting)
    part = ngwear.simulate(scene, progress=False, checkpoint=tmp_path, stop=stop)
    monkeypatch.undo()
    assert part.status == "interrupted" and part.steps == 10
    resumed = ngwear.simulate(scene, progress=False, resume=tmp_path)
    assert np.array_equal(resumed.times, full.times) and np.array_equal(resumed.wear, full.wear)
    assert resumed.rejected == full.rejected
