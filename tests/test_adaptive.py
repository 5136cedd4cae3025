"""Error-controlled time steps: the tolerance is met against a fine uniform reference, with few steps.

On the paper's scene (coarse mesh) the final wear of an adaptive run is within ``time.tolerance · g``
of a trapezoidal reference with 8000 steps.  On a scene whose wear rate changes a lot — the disc stops
for most of the run — the adaptive run needs far fewer steps than a uniform run of the same error.
Frames land exactly on their times, steps on the tables' kinks, the explicit update stays within its
stability limit, rejected steps are counted, and a stopped adaptive run resumes to the same bits.
"""
import threading

import numpy as np
import pytest
from conftest import PAPER

import ngwear
from ngwear.numerics.wear import largest_slope

QUIET = [[0, 1], [1, 1], [1.2, 0], [8.8, 0], [9, 1], [10, 1]]


@pytest.fixture(scope="module")
def paper():
    return ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.2})


@pytest.fixture(scope="module")
def reference(paper):
    return ngwear.simulate(paper.replace(**{"time.steps": 8000, "wear.integrator": "trapezoidal"}), progress=False)


def error(result, reference):
    return np.abs(result.wear[-1] - reference.wear[-1]).max() / result.scene.contact.gap


@pytest.mark.parametrize("integrator", ["explicit", "implicit", "trapezoidal"])
@pytest.mark.parametrize("tolerance", [1e-2, 1e-3])
def test_adaptive_run_meets_its_tolerance(paper, reference, integrator, tolerance):
    scene = paper.replace(**{"time.adaptive": True, "time.tolerance": tolerance, "wear.integrator": integrator})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed and result.times[-1] == scene.time.T and not result.warnings
    assert error(result, reference) <= tolerance
    assert np.all(np.diff(result.times) > 0) and np.diff(result.times).max() <= scene.time.max_step * (1 + 1e-12)


def test_far_fewer_steps_than_a_uniform_run_of_the_same_error(paper):
    """The disc stops between t = 1.2 and 8.8: the adaptive steps go there in a few strides."""
    scene = paper.replace(**{"time.T": 10.0, "contact.wear": 0.3, "foundation.speed_table": QUIET,
                             "output.every": 2.5, "wear.integrator": "implicit"})
    reference = ngwear.simulate(scene.replace(**{"time.steps": 20000, "wear.integrator": "trapezoidal"}),
                                progress=False)
    adaptive = ngwear.simulate(scene.replace(**{"time.adaptive": True, "time.tolerance": 1e-3}), progress=False)
    target = error(adaptive, reference)
    assert target <= 1e-3
    uniform = {n: error(ngwear.simulate(scene.replace(**{"time.steps": n}), progress=False), reference)
               for n in (500, 1000, 2000)}
    same = min(n for n, e in uniform.items() if e <= target) if any(e <= target for e in uniform.values()) else 4000
    assert same >= 4 * adaptive.steps, (adaptive.steps, uniform)
    quiet = (adaptive.times > 1.2) & (adaptive.times < 8.8)
    assert quiet.sum() <= 0.1 * adaptive.steps                    # few steps where nothing wears
    assert {1.0, 1.2, 8.8, 9.0} <= set(adaptive.times.round(12))   # steps end on the speed table's kinks


def test_frames_land_on_their_times(paper):
    scene = paper.replace(**{"time.adaptive": True, "output.times": [0.0, 0.137, 0.5, 0.9]})
    result = ngwear.simulate(scene, progress=False)
    assert [result.times[j] for j in result.stored_steps] == [0.0, 0.137, 0.5, 0.9, 1.0]


def test_explicit_steps_stay_below_the_stability_limit(paper):
    scene = paper.replace(**{"time.adaptive": True, "time.tolerance": 0.2, "time.max_step": 1.0})
    result = ngwear.simulate(scene, progress=False)
    alpha = result.discretization.largest_alpha()
    assert np.diff(result.times).max() * alpha * largest_slope(scene.contact) <= 1 + 1e-12
    assert result.wear.max() <= scene.contact.gap * (1 + 1e-12)


def test_too_large_a_first_step_is_rejected_and_redone(paper):
    scene = paper.replace(**{"time.adaptive": True, "time.steps": 2, "time.max_step": 0.5,
                             "wear.integrator": "implicit"})
    result = ngwear.simulate(scene, progress=False)
    assert result.rejected >= 1 and result.times[1] < 0.5 and result.summary()["rejected_steps"] == result.rejected


def test_min_step_above_the_stability_limit_is_refused(paper):
    scene = paper.replace(**{"time.adaptive": True, "time.min_step": 0.5, "time.max_step": 1.0})
    with pytest.raises(ngwear.SceneError, match=r"^time\.min_step: 0\.5 is above the explicit update's stability"):
        ngwear.simulate(scene, progress=False)


def test_stopped_adaptive_run_resumes_bit_identical(paper, tmp_path, monkeypatch):
    scene = paper.replace(**{"time.adaptive": True, "wear.integrator": "trapezoidal", "time.tolerance": 1e-4})
    full = ngwear.simulate(scene, progress=False)
    stop, original, count = threading.Event(), ngwear.Result.append, []

    def counting(result, *args):
        original(result, *args)
        count.append(1)
        if len(count) == 11:
            stop.set()

    monkeypatch.setattr(ngwear.Result, "append", counting)
    part = ngwear.simulate(scene, progress=False, checkpoint=tmp_path, stop=stop)
    monkeypatch.undo()
    assert part.status == "interrupted" and part.steps == 10
    resumed = ngwear.simulate(scene, progress=False, resume=tmp_path)
    assert np.array_equal(resumed.times, full.times) and np.array_equal(resumed.wear, full.wear)
    assert resumed.rejected == full.rejected
