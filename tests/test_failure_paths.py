"""The failure paths of a part's life: every step computed is kept, and the last line says when, where and why.

A run that stops part-way — at the worn mesh's quality bound, on a broken invariant, a Newton failure, a full disk
just after a geometry update, inside its first stop — writes its result, checkpoint, summary, history and
``stops.csv`` for the steps it computed and exits 1 with one line (130 on Ctrl-C); a full disk leaves a
checkpoint whose every file is consistent with it, so the run resumes to the bit once there is room.
"""
import errno
import json

import numpy as np
import pandas as pd
import pytest
from conftest import PAPER
from test_life import SURFACE_ROWS, taper_scene

import ngwear
from ngwear.cli import main
from ngwear.model.programme import Schedule
from ngwear.results import checkpoint as checkpoints
from ngwear.results.folder import NoSpace
from ngwear.results.history_csv import bare
from ngwear.runs.surface import Surface

pytestmark = pytest.mark.hostile

STOPS = "programme.stops=[{count=400, duration=1.0, dwell=0.1}]"
HEATED = ("material.conductivity=1.0", "material.heat_capacity=1.0", "material.density=1.0",
          "heat.model=conduction", "heat.partition=0.5")


def run(tmp_path, capsys, *settings, scene=PAPER):
    """``ngwear run`` in this process: its exit code, its last line and its output folder."""
    out = tmp_path / "out"
    code = main(["run", str(scene), "--out", str(out), "--quiet", "--no-pictures", "--no-check",
                 *[a for s in settings for a in ("--set", s)]])
    return code, capsys.readouterr().err.strip().splitlines()[-1], out


def assert_kept(out, status_line):
    """Every file of a stopped run, each with every computed step, the summary's status the line's.

    ``stops.csv`` holds the stops completed (none for a run that ended inside its first); no checkpoint before
    step 0 (nothing to go on from).
    """
    saved = ngwear.load_result(out)
    rows = len(saved.times)
    assert saved.status in status_line
    assert len(pd.read_csv(out / "history.csv")) == rows
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == saved.status and summary["steps"] == saved.steps == rows - 1
    if rows:
        with np.load(out / "checkpoint.npz") as data:
            assert int(data["rows"]) == rows
    if saved.scene.programme is not None:
        stops = pd.read_csv(out / "stops.csv").rename(columns=bare)
        assert stops.columns[0] == "stop" and len(stops) == len(saved.stops)
        done = saved.stops["simulated"].sum()
        assert summary["stops_simulated"] == done
        if done:                            # the stops completed, each ending at its last step
            ends = Schedule.of(saved.scene.programme).ends(rows)
            assert len(ends) == done and ends[-1] <= rows - 1
            assert np.array_equal(stops["worn_volume"], saved.stops["worn_volume"])
    return saved


def test_the_mesh_quality_bound_stops_the_run_with_every_step(tmp_path, capsys):
    code, line, out = run(tmp_path, capsys, "wear.geometry=surface", "contact.wear=1.0", STOPS)
    assert code == 1
    assert line.startswith("ngwear: run stopped early: step ") and "wear.geometry = 'surface': the worn mesh's " \
        "worst element (at (" in line and "has the mean ratio" in line and "< 0.1" in line
    saved = assert_kept(out, line)
    assert saved.geometry_updates > 10 and saved.status.startswith(f"step {saved.steps} ")


@pytest.mark.parametrize("settings, says", [
    ((*HEATED, 'contact.wear="0.05*exp(1000*T)"'), "invariant wear_le_penetration broken"),
    ((*HEATED, "material.expansion=1e12"), "wear.geometry = 'surface': the worn mesh has"),
], ids=["kappa_exp_1000T", "expansion_1e12"])
def test_a_heated_surface_life_that_breaks_down_keeps_its_steps(tmp_path, capsys, settings, says):
    code, line, out = run(tmp_path, capsys, "wear.geometry=surface", STOPS, *settings)
    assert code == 1 and line.startswith("ngwear: run stopped early: step ") and says in line
    assert_kept(out, line)


@pytest.mark.parametrize("failing", ["the mesh", "the checkpoint"])
def test_a_full_disk_just_after_a_geometry_update_resumes_to_the_bit(tmp_path, monkeypatch, failing):
    """The first checkpoint on a moved mesh finds no room: the one before stays whole, with the mesh it refers to."""
    scene = taper_scene(T=3.0, steps=30).replace(**{"output.every": 0.5, "output.checkpoint_seconds": 1e-9})
    whole = ngwear.simulate(scene, progress=False)
    moved, update = [], Surface.update

    def updating(self, *args):
        moved.append(True)
        return update(self, *args)

    def full(path, *args, **kwargs):
        if moved and (failing == "the mesh") == (path.name == "mesh.next.vol") and "result" not in path.name:
            moved.clear()
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return replacing(path, *args, **kwargs)

    from ngwear.results import mesh_file
    replacing = checkpoints.replacing
    with monkeypatch.context() as patched:
        patched.setattr(Surface, "update", updating)
        patched.setattr(mesh_file if failing == "the mesh" else checkpoints, "replacing", full)
        with pytest.raises(NoSpace, match=r"its checkpoint keeps steps 0-\d+ .*: free space, then resume from it$"):
            ngwear.simulate(scene, progress=False, checkpoint=tmp_path)
    assert not (tmp_path / "mesh.next.vol").exists()
    resumed = ngwear.simulate(None, progress=False, resume=tmp_path)
    assert resumed.completed and resumed.geometry_updates == whole.geometry_updates == 4
    for name in SURFACE_ROWS:
        assert np.array_equal(getattr(resumed, name), getattr(whole, name)), name


def test_a_run_killed_between_the_checkpoint_and_its_mesh_resumes(tmp_path, monkeypatch):
    """Killed after checkpoint.npz names the new mesh and before mesh.next.vol is renamed: the resume completes it."""
    scene = taper_scene(T=3.0, steps=30).replace(**{"output.every": 0.5})
    whole = ngwear.simulate(scene, progress=False)
    first = ngwear.simulate(scene.replace(**{"time.T": 1.5, "time.steps": 15}), progress=False, checkpoint=tmp_path)
    assert first.geometry_updates >= 1
    (tmp_path / "mesh.vol").rename(tmp_path / "mesh.next.vol")
    (tmp_path / "mesh.vol").write_bytes(b"the mesh as built")           # the mesh before the update
    resumed = ngwear.simulate(scene, progress=False, resume=tmp_path)
    assert not (tmp_path / "mesh.next.vol").exists() and resumed.completed
    for name in SURFACE_ROWS:
        assert np.array_equal(getattr(resumed, name), getattr(whole, name)), name


FIRST_STOP = "programme.stops=[{count=3, duration=1.0, dwell=0.1}]"


@pytest.mark.parametrize("setting, says, rows", [
    ("solver.max_iterations=1", "run stopped early: step 0 (t = 0): Newton did not converge in 1 iterations "
                                "(merit 2.40e-04 > 1e-10); try solver.max_iterations > 1, a smaller contact.friction", 0),
    ('contact.friction="0.5-4*p"', "run stopped early: step 1: contact.friction: must be >= 0 at every contact "
                                   "point (got -0.0130354 at (2.15, 0) with p = 0.128259, v = 1 at t = 0)", 1),
], ids=["newton", "negative_friction"])
def test_a_programme_that_ends_inside_its_first_stop_writes_its_steps(tmp_path, capsys, setting, says, rows):
    code, line, out = run(tmp_path, capsys, FIRST_STOP, setting)
    assert code == 1 and line.startswith(f"ngwear: {says}"), line
    saved = assert_kept(out, line)
    assert len(saved.times) == rows and saved.stops.empty


def test_a_programme_failing_in_its_first_stop_has_a_summary_in_python():
    scene = ngwear.load_scene(PAPER).replace(**{"programme.stops": [{"count": 3, "duration": 1.0, "dwell": 0.1}],
                                                "solver.max_iterations": 1})
    result = ngwear.simulate(scene, progress=False)
    summary = result.summary()
    assert not result.completed and summary["status"] == result.status and summary["steps"] == -1
    assert result.stops.empty and summary["stops_simulated"] == 0 and summary["blocks"] == []
    assert "normal_force" not in summary and "max_wear" not in summary      # no step: nothing to report
