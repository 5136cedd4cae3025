"""The explorer: slider values set from Python re-solve with the physics expected and reuse the factorisation.

The paper's scene at a coarse resolution with κ = 0.3, so that the layer is not worn through and
the maxima respond to every parameter.
"""
import subprocess
import sys
import threading

import numpy as np
import pytest
from conftest import PAPER
from PIL import Image

import ngwear
from ngwear import cli
from ngwear.model.scene import SceneError
from ngwear.views.explore import Explorer, RunError


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
    mesh, operator = explorer.disc.mesh, explorer.disc.elastic.operator
    explorer.set(friction=0.2)
    explorer.set(**{"contact.wear": 1.0}, load=0.15, speed=1.5, gap=0.15, steps=30)
    assert explorer.disc.mesh is mesh and explorer.disc.elastic.operator is operator
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
    assert explorer.updates[-1].picture > 0 and "rebuilds loads; keeps mesh, space, factorisation" in explorer.summary()


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


def failing_explorer():
    """An explorer whose run stops part-way at κ = 5: explicit wear with k·α·L = 2.5e7 (L = 1e8), allowed to run."""
    scene = ngwear.load_scene(PAPER).replace(**{"contact.stiffness": 1e8, "contact.wear": 0.0,
                                                "wear.allow_unstable": True})
    return Explorer(scene, maxh=0.2, steps=20, window_size=(400, 170))


def test_a_failed_run_leaves_the_explorer_as_it_was():
    ex = failing_explorer()
    result, scene, picture = ex.result, ex.scene, ex.picture()
    with pytest.raises(RunError, match=r"step \d+ \(t = .*\): Newton did not converge") as failure:
        ex.set(wear=5.0)
    assert not failure.value.result.completed and failure.value.result.steps < 20
    assert ex.result is result and ex.scene == scene and ex.values["wear"] == 0.0
    assert np.array_equal(ex.picture(), picture) and len(ex.updates) == 1
    ex.close()


def test_saved_scene_reproduces_the_run_with_ngwear_run(explorer, tmp_path, capsys):
    """The TOML scene and the result folder of the explorer are what `ngwear run` makes of that TOML."""
    explorer.set(load=0.15, speed=1.5, friction=0.5, steps=30)
    path = explorer.save_scene(tmp_path / "found.toml")
    assert ngwear.load_scene(path) == explorer.scene
    saved = explorer.save_result(tmp_path / "explorer")
    assert cli.main(["run", str(path), "--out", str(tmp_path / "run"), "--quiet"]) == 0
    capsys.readouterr()
    files = lambda d: sorted(p.name.split("-")[0] for p in d.iterdir())  # noqa: E731   steps-<id>: one each
    assert files(saved) == files(tmp_path / "run") and "fig4_step030.png" in files(saved)
    ours, theirs = np.load(saved / "result.npz"), np.load(tmp_path / "run" / "result.npz")
    for name in ("wear", "normal_displacement", "pressure", "reaction", "fields"):
        assert np.allclose(ours[name], theirs[name], rtol=1e-9, atol=1e-13), name
    assert ours["wear"].max() > 0.05


def test_saved_picture_is_the_picture_on_show(explorer, tmp_path):
    explorer.scrub(5)
    path = explorer.save_picture(tmp_path / "shown.png")
    assert np.array_equal(np.asarray(Image.open(path).convert("RGB")), explorer.picture())


def test_pinned_run_is_compared_with_the_current_one(explorer):
    alone = explorer.plots()
    explorer.pin()
    assert explorer.pinned is explorer.result
    same = explorer.plots()
    assert same.shape == alone.shape and "A/B: B has A's parameters" in explorer.summary()
    a = explorer.result
    b = explorer.set(speed=2.0)
    compared = explorer.plots()
    assert np.abs(compared.astype(int) - same).mean() > 0.1
    difference = explorer.comparison._lines["diff"].get_ydata()
    order = np.argsort(b.contact_points[:, 0])
    assert difference == pytest.approx((b.wear[-1] - a.wear[-1])[order])
    assert difference.max() > 0.01
    assert "B differs from A in speed 1 → 2" in explorer.summary()
    explorer.unpin()
    assert explorer.pinned is None and explorer.plots().shape == alone.shape


def test_views_are_told_of_every_change(explorer):
    seen = []
    explorer.on_change(lambda: seen.append((explorer.values["speed"], explorer.step, explorer.pinned)))
    explorer.set(speed=2.0)
    explorer.set(speed=2.0)
    explorer.scrub(3)
    explorer.pin()
    with pytest.raises(SceneError):
        explorer.set(gap=-1.0)
    assert seen == [(2.0, 20, None), (2.0, 3, None), (2.0, 3, explorer.result)]


@pytest.mark.parametrize("name", ["box3d", "hertz"])
def test_other_scenes_open_and_their_sliders_act(name):
    """The 3D box and the Hertz half-disk at their own resolution: every slider re-solves and redraws."""
    ex = Explorer(ngwear.load_scene(PAPER.with_name(f"{name}.toml")), window_size=(400, 170))
    shown = [(ex.picture(), ex.plots())]
    assert len(np.unique(shown[0][0].reshape(-1, 3), axis=0)) > 50
    for slider in ex.sliders:
        value = slider.maximum if slider.integer else 0.5 * (ex.values[slider.name] + slider.maximum)
        ex.set(**{slider.name: value})
        assert ex.result.completed and ex.values[slider.name] == pytest.approx(value)
        shown.append((ex.picture(), ex.plots()))
        (picture, plots), (old_picture, old_plots) = shown[-1], shown[-2]
        assert (np.abs(picture.astype(int) - old_picture).mean() > 0.05
                or np.abs(plots.astype(int) - old_plots).mean() > 0.05), slider.name
    ex.close()


def test_brake_pad_sliders_force_omega_kappa_mu():
    """The pad gets the sliders a brake engineer turns: force, ω, κ, μ; each acts as physics says."""
    ex = Explorer(ngwear.load_scene(PAPER.with_name("brake_pad.toml")), maxh=0.012, steps=20,
                  window_size=(400, 170))
    assert [s.name for s in ex.sliders] == ["force", "omega", "kappa", "friction", "backing"]
    before = ex.result
    doubled = ex.set(force=6000.0)
    assert doubled.normal_force[-1] == pytest.approx(6000.0, rel=1e-9)
    assert ex.scene.loads.plate.force == pytest.approx((0.0, 0.0, -6000.0))
    faster = ex.set(omega=100.0)
    assert ex.scene.foundation.angular_velocity == pytest.approx((0.0, 0.0, 100.0))
    assert faster.wear_volume[1] == pytest.approx(2 * doubled.wear_volume[1], rel=1e-6)   # Archard: ∝ ω at step 1
    ex.set(friction=0.8)
    assert ex.result.torque[-1] == pytest.approx(2 * faster.torque[-1], rel=0.02)
    ex.set(kappa=0.0)
    assert not ex.result.wear.any() and before.wear.any()
    assert ex.disc.elastic.operator is before.discretization.elastic.operator          # no new factorisation for any of them
    ex.close()


def test_pad_of_compaction_material_with_fields_and_a_backing():
    """β re-solves with the law's new L_F; μ, κ sliders scale their fields; the backing comes and goes."""
    scene = ngwear.load_scene(PAPER.with_name("brake_pad.toml")).replace(**{
        "material": {"law": "compaction", "young": 1.0e9, "poisson": 0.25, "compaction_modulus": 1.0e9},
        "contact.friction": "where(hypot(x, y) < 0.125, 0.3, 0.45)", "contact.wear": "8e-13 * 0.12 / hypot(x, y)"})
    ex = Explorer(scene, maxh=0.012, steps=10, window_size=(400, 170))
    sliders = {s.name: s for s in ex.sliders}
    assert list(sliders) == ["force", "omega", "kappa", "friction", "compaction", "backing"]
    assert sliders["friction"].label == "friction μ × field" and ex.values["friction"] == 1.0
    lam, eta = scene.material.lame
    assert (sliders["compaction"].minimum, sliders["compaction"].maximum) == (0.0, pytest.approx(20 * eta))
    first = ex.result
    ex.set(friction=0.5, kappa=2.0)
    assert ex.scene.contact.friction == "0.5 * (where(hypot(x, y) < 0.125, 0.3, 0.45))"
    assert ex.result.friction_coefficient == pytest.approx(0.5 * first.friction_coefficient, rel=1e-15)
    assert ex.result.wear_coefficient == pytest.approx(2.0 * first.wear_coefficient, rel=1e-15)
    assert ex.values["friction"] == 0.5 and ex.values["kappa"] == 2.0
    ex.set(compaction=4 * eta)
    body = ex.result.summary()["materials"]["body"]
    assert body["compaction_modulus"] == pytest.approx(4 * eta)
    assert body["L_F"] == pytest.approx(2 * eta + 3 * (lam + 4 * eta), rel=1e-12)
    before = ex.picture()
    ex.set(backing=0.004)
    assert ex.disc.mesh.GetMaterials() == ("body", "backing") and ex.values["backing"] == 0.004
    assert np.abs(ex.picture().astype(int) - before).mean() > 0.05
    ex.set(backing=0.0)
    assert ex.scene.geometry.backing is None and ex.disc.mesh.GetMaterials() == ("body",)
    ex.close()


def test_a_result_is_not_saved_into_a_folder_a_run_holds(explorer, tmp_path):
    from ngwear.results.folder import hold

    held, done = threading.Event(), threading.Event()

    def run():
        with hold(tmp_path / "busy", "checkpoint"):
            held.set()
            done.wait(60)

    thread = threading.Thread(target=run)
    thread.start()
    held.wait(60)
    try:
        with pytest.raises(SceneError, match=r"^save into: .*busy is in use by ngwear \(PID \d+, another thread\)$"):
            explorer.save_result(tmp_path / "busy")
    finally:
        done.set()
        thread.join()
    assert not (tmp_path / "busy" / "result.npz").exists()
    assert (explorer.save_result(tmp_path / "busy") / "result.npz").is_file()


@pytest.mark.hostile
def test_a_programme_scene_opens_and_its_sliders_act():
    """A strip under a braking programme: the steps slider sets programme.steps_per_stop (the programme sets the time)."""
    scene = ngwear.load_scene(PAPER).replace(**{"programme.stops": [{"count": 2, "duration": 0.5, "speed": [1, 0],
                                                                     "dwell": 0.5}], "output.every": 0.5})
    ex = Explorer(scene, maxh=0.2, window_size=(400, 170))
    steps = next(s for s in ex.sliders if s.name == "steps")
    assert steps.key == "programme.steps_per_stop" and steps.label == "steps per stop"
    ex.set(steps=steps.maximum)
    assert ex.result.completed and ex.scene.programme.steps_per_stop == steps.maximum
    assert len(ex.result.times) == 2 * (steps.maximum + 1) + 1    # two stops (starts and m steps each), the last dwell
    assert ex.picture().size and ex.plots().size
    ex.close()
