"""Long runs: nothing lost on an interrupt, checkpoints, and resuming to the last bit.

A run of the paper's scene (coarse mesh, many steps) is stopped by SIGINT, SIGTERM or SIGKILL at
random moments — with a checkpoint every 20 ms, as long as a few steps, a signal often lands during a write — and
resumed with ``ngwear run --resume``; its result must equal, bit for bit, the uninterrupted run's.  So must a
run that a second run into its folder tried to disturb, and a run stopped by a full disk once there is room.
"""
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from conftest import PAPER

import ngwear
from ngwear.results.checkpoint import CHECKPOINT
from ngwear.results.recording import Recording
from ngwear.runs import loop

pytestmark = pytest.mark.hostile

STEPS = 5000
SETTINGS = ["mesh.maxh=0.2", f"time.steps={STEPS}", "output.checkpoint_seconds=0.02",
            "time.T=0.5"]                           # the layer not yet worn through: no warning beside the one line
KEYS = ("times", "wear", "normal_displacement", "pressure", "reaction", "forces", "newton_iterations",
        "newton_residuals", "field_steps", "fields")


def ngwear_cli(*args, **kw):
    return subprocess.Popen([sys.executable, "-m", "ngwear.cli", *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kw)


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    out = tmp_path_factory.mktemp("full") / "run"
    proc = ngwear_cli("run", PAPER, "--out", out, "--set", *SETTINGS, "--quiet", "--no-pictures")
    assert proc.wait(timeout=600) == 0, proc.stderr.read()
    return np.load(out / "result.npz")


def interrupted(out, sig, rng):
    """Start the run, wait until it steps (its first checkpoint), send ``sig`` a random moment later."""
    proc = ngwear_cli("run", "--set", SETTINGS[0], "--set", *SETTINGS[1:], PAPER, "--out", out, "--quiet",
                      "--no-pictures")
    deadline = time.time() + 120
    while not (out / CHECKPOINT).is_file() and proc.poll() is None and time.time() < deadline:
        time.sleep(0.01)
    time.sleep(rng.uniform(0.0, 1.5))
    proc.send_signal(sig)
    proc.wait(timeout=300)
    return proc


def finished(out):
    """The run ended and wrote everything (a signal during the interpreter's exit kills it with −sig)."""
    summary = out / "summary.json"
    return summary.is_file() and json.loads(summary.read_text())["status"] == "completed"


def same(a, b):
    return all(np.array_equal(a[key], b[key]) for key in KEYS)


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["SIGINT", "SIGTERM"])
def test_signal_stops_at_a_step_keeps_every_step_and_resumes_bit_identical(uninterrupted, tmp_path, sig, code):
    rng = np.random.default_rng(int(sig))
    for attempt in range(2):
        out = tmp_path / f"run{attempt}"
        proc = interrupted(out, sig, rng)
        if proc.returncode == 0 or (proc.returncode == -sig and finished(out)):
            continue                           # the run was faster than the signal (which came at the exit)
        assert proc.returncode == code, proc.stderr.read()
        stderr = proc.stderr.read()
        assert f"resume with: ngwear run --resume {out}" in stderr and "Traceback" not in stderr
        summary = json.loads((out / "summary.json").read_text())
        saved = np.load(out / "result.npz")
        assert summary["status"] == "interrupted" and 0 < summary["steps"] < STEPS
        assert len(saved["times"]) == summary["steps"] + 1 and np.isfinite(saved["wear"]).all()
        assert np.array_equal(saved["wear"], uninterrupted["wear"][:len(saved["times"])])
        resumed = ngwear_cli("run", "--resume", out, "--quiet", "--no-pictures")
        assert resumed.wait(timeout=600) == 0, resumed.stderr.read()
        assert same(np.load(out / "result.npz"), uninterrupted)
        return
    pytest.fail("the run always finished before the signal")


def test_killed_run_resumes_from_its_last_checkpoint(uninterrupted, tmp_path):
    out = tmp_path / "killed"
    proc = interrupted(out, signal.SIGKILL, np.random.default_rng(7))
    assert proc.returncode == -signal.SIGKILL
    with np.load(out / CHECKPOINT) as checkpoint:                 # whole: a write cut short left only a temporary
        assert 0 < int(checkpoint["rows"]) <= STEPS + 1
        assert [p.name for p in out.glob("steps-*")] == [str(checkpoint["history"])]
    resumed = ngwear_cli("run", "--resume", out, "--quiet", "--no-pictures")
    assert resumed.wait(timeout=600) == 0, resumed.stderr.read()
    assert same(np.load(out / "result.npz"), uninterrupted)


def small(**changes):
    return ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.2, "time.steps": 40, **changes})


def test_stop_event_and_resume_in_python(tmp_path, monkeypatch):
    """A stop set after some steps (as the CLI's signal handler does) and simulate(resume=...)."""
    scene = small(**{"output.checkpoint_seconds": 0.0})
    full = ngwear.simulate(scene, progress=False)
    stop = threading.Event()
    calls = []
    original = Recording.append

    def counting(recording, *step):
        original(recording, *step)
        calls.append(1)
        if len(calls) == 17:
            stop.set()

    monkeypatch.setattr(Recording, "append", counting)
    part = ngwear.simulate(scene, progress=False, checkpoint=tmp_path, stop=stop)
    monkeypatch.undo()
    assert part.status == "interrupted" and part.steps == 16 and not part.completed
    assert (tmp_path / CHECKPOINT).is_file() and (tmp_path / "mesh.vol").is_file()
    resumed = ngwear.simulate(None, progress=False, resume=tmp_path)
    assert resumed.completed and resumed.steps == 40
    for name in ("times", "wear", "pressure", "reaction", "normal_displacement"):
        assert np.array_equal(getattr(resumed, name), getattr(full, name)), name
    assert [r.residuals for r in resumed.newton] == [r.residuals for r in full.newton]


def test_ctrl_c_in_a_notebook_keeps_the_completed_steps(monkeypatch):
    scene = small()
    original = loop.advance
    calls = []

    def interrupting(*args):
        calls.append(1)
        if len(calls) == 9:
            raise KeyboardInterrupt
        return original(*args)

    monkeypatch.setattr(loop, "advance", interrupting)
    result = ngwear.simulate(scene, progress=False)
    assert result.status == "interrupted" and result.steps == 7
    assert len(result.newton) == 8 and len(result.wear) == 8


def test_extending_a_finished_run(tmp_path):
    """A finished run goes on to a later T: the same numbers as the longer run from the start."""
    short = ngwear.simulate(small(), progress=False, checkpoint=tmp_path)
    longer = small(**{"time.T": 2.0, "time.steps": 80})
    extended = ngwear.simulate(longer, progress=False, resume=tmp_path)
    direct = ngwear.simulate(longer, progress=False)
    assert short.completed and extended.completed and extended.steps == 80
    assert np.array_equal(extended.wear, direct.wear) and np.array_equal(extended.times, direct.times)


@pytest.mark.parametrize("changes, message", [
    ({"contact.friction": 0.5}, "resume: the scene differs from the checkpoint's in contact.friction"),
    ({"time.T": 2.0}, "time.steps: must be 80 to keep the checkpoint's step k = 0.025"),
    ({"time.T": 0.5, "time.steps": 20}, "time.T: a resumed run may only go on longer"),
])
def test_resume_refuses_another_scene(tmp_path, changes, message):
    ngwear.simulate(small(), progress=False, checkpoint=tmp_path)
    with pytest.raises(ngwear.SceneError, match=f"^{message}"):
        ngwear.simulate(small(**changes), progress=False, resume=tmp_path)


def test_cli_options_in_any_order_and_frames_by_time(tmp_path):
    out = tmp_path / "many"
    proc = ngwear_cli("run", "--set", "mesh.maxh=0.25", "--set", "time.steps=200", "--quiet", PAPER, "--out", out,
                      "--no-pictures")
    assert proc.wait(timeout=300) == 0, proc.stderr.read()
    assert "fields.pvd with 5 frames" in proc.stdout.read()
    assert len(list(out.glob("fields*.vtu"))) == 5                 # t = 0, 0.25, 0.5, 0.75, 1: not 200/25
    bad = ngwear_cli("run", PAPER, "--set", "time.steps=3", "steps")
    assert bad.wait(timeout=60) == 2 and "--set steps: expected KEY=VALUE" in bad.stderr.read()
    resume = ngwear_cli("run", "--resume", tmp_path / "nothing")
    assert resume.wait(timeout=60) == 2 and "holds no checkpoint.npz" in resume.stderr.read()


def one_line(proc, code):
    stderr = proc.stderr.read()
    assert proc.returncode == code and "Traceback" not in stderr, (proc.returncode, stderr)
    [line] = stderr.strip().splitlines()
    return line


def started(out, disk=None):
    """A run of SETTINGS into ``out``, stopped (SIGSTOP) once it has written its first checkpoint."""
    proc = ngwear_cli("run", PAPER, "--out", out, "--set", *SETTINGS, "--quiet", "--no-pictures")
    deadline = time.time() + 120
    while not (out / CHECKPOINT).is_file() and proc.poll() is None and time.time() < deadline:
        time.sleep(0.005)
    proc.send_signal(signal.SIGSTOP)
    assert proc.poll() is None, proc.stderr.read()
    return proc


def test_a_second_run_into_a_folder_in_use_is_refused_and_the_first_goes_on(uninterrupted, tmp_path):
    out = tmp_path / "shared"
    first = started(out)
    try:
        for args, flag in ((["run", PAPER, "--out", out, "--set", *SETTINGS], "--out"),
                           (["run", "--resume", out], "--resume")):
            second = ngwear_cli(*args, "--quiet", "--no-pictures")
            second.wait(timeout=120)
            assert one_line(second, 2) == f"ngwear: {flag}: {out} is in use by ngwear (PID {first.pid})"
        rows = int(np.load(out / CHECKPOINT)["rows"])
    finally:
        first.send_signal(signal.SIGCONT)
    first.send_signal(signal.SIGINT)
    assert first.wait(timeout=300) in (0, 130), first.stderr.read()
    assert [p.name for p in out.glob("steps-*")] == [str(np.load(out / CHECKPOINT)["history"])]
    assert json.loads((out / "summary.json").read_text())["steps"] >= rows - 1
    resumed = ngwear_cli("run", "--resume", out, "--quiet", "--no-pictures")
    assert resumed.wait(timeout=600) == 0, resumed.stderr.read()
    assert same(np.load(out / "result.npz"), uninterrupted)


def fill(folder):
    """Write zeros into ``folder/filler`` until the disk is full."""
    with open(folder / "filler", "wb") as file:
        try:
            while True:
                file.write(bytes(1 << 16))
                file.flush()
        except OSError as err:
            assert err.errno == 28
    os.sync()


def test_a_disk_that_fills_during_a_run_stops_it_with_one_line_and_it_resumes(uninterrupted, small_disk, tmp_path):
    disk = small_disk(6)                       # 3.9 MB of rows (reserved at the start), mesh and checkpoints
    out = disk / "run"
    proc = started(out)
    try:
        fill(disk)                             # another program fills the disk: the next checkpoint fails
    finally:
        proc.send_signal(signal.SIGCONT)
    proc.wait(timeout=300)
    line = one_line(proc, 1)
    kept = int(np.load(out / CHECKPOINT)["rows"])
    assert re.fullmatch(rf"ngwear: --out: no space left on device in {re.escape(str(out))}: the run stopped after step "
                        rf"\d+ \(t = [0-9.e-]+\); its checkpoint keeps steps 0-{kept - 1} \(t <= [0-9.e-]+\): free "
                        rf"space, then resume from it: ngwear run --resume {re.escape(str(out))}", line), line
    assert not (out / "result.npz").exists() and not list(out.glob(".*tmp*"))
    (disk / "filler").unlink()
    small_disk.resize(disk, 64)                # room for result.npz too (the rows again)
    resumed = ngwear_cli("run", "--resume", out, "--quiet", "--no-pictures")
    assert resumed.wait(timeout=600) == 0, resumed.stderr.read()
    assert same(np.load(out / "result.npz"), uninterrupted)


def test_results_that_do_not_fit_are_written_by_a_resume_once_there_is_room(uninterrupted, small_disk, tmp_path):
    disk = small_disk(8)                       # the rows (3.9 MB) and the checkpoint fit; result.npz (6 MB) not
    out = disk / "run"
    proc = ngwear_cli("run", PAPER, "--out", out, "--set", *SETTINGS, "--quiet", "--no-pictures")
    proc.wait(timeout=600)
    assert one_line(proc, 1) == (f"ngwear: --out: no space left on device in {out} for the results; the checkpoint "
                                 f"keeps all {STEPS + 1} steps: free space, then write them with: ngwear run --resume {out}")
    assert int(np.load(out / CHECKPOINT)["rows"]) == STEPS + 1 and not (out / "result.npz").exists()
    small_disk.resize(disk, 64)
    resumed = ngwear_cli("run", "--resume", out, "--quiet", "--no-pictures")
    assert resumed.wait(timeout=600) == 0, resumed.stderr.read()
    assert same(np.load(out / "result.npz"), uninterrupted)


def ended_by(proc, sig, after):
    """Send ``sig`` ``after`` seconds from the start; (exit status, stderr, seconds from the signal to the exit)."""
    time.sleep(after)
    sent = time.monotonic()
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    return proc.returncode, err, time.monotonic() - sent


@pytest.mark.parametrize("after", [0.05, 0.3])
@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["SIGINT", "SIGTERM"])
def test_a_signal_while_the_command_starts_ends_it_at_once_in_one_line(tmp_path, sig, code, after):
    """From its first instant (the libraries still loading) the command ends on a signal: 128 + it, one line."""
    proc = ngwear_cli("run", PAPER, "--out", tmp_path / "run", "--quiet", "--no-pictures")
    status, err, took = ended_by(proc, sig, after)
    assert (status, err) == (code, "ngwear: interrupted\n") and took < 2.0


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["SIGINT", "SIGTERM"])
def test_a_signal_while_a_long_programme_is_read_ends_the_command_within_a_second(tmp_path, sig, code):
    """A programme of 200,000 blocks takes seconds to read and check: a signal then ends the command within a second."""
    rows = "".join(f"{1 + i % 3},0.5,\"[1.0, 0.0]\",1.0,0.5\n" for i in range(200_000))
    (tmp_path / "blocks.csv").write_text("count,duration,speed,load,dwell\n" + rows)
    (tmp_path / "long.toml").write_text(PAPER.read_text().split("[time]")[0]
                                        + '[programme]\nfile = "blocks.csv"\nsteps_per_stop = 1\n')
    proc = ngwear_cli("run", tmp_path / "long.toml", "--out", tmp_path / "run", "--quiet", "--no-pictures")
    status, err, took = ended_by(proc, sig, 1.5)
    assert status == code and err.splitlines()[-1] == "ngwear: interrupted" and "Traceback" not in err
    assert took < 1.0 + 0.5, "within a second (and a margin for a busy machine)"
