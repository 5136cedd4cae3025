"""Output folders: held by one run at a time, and full disks that stop a run without losing what fits.

A folder is held with an exclusive ``flock`` (re-entrant for its thread, refused to other threads and
processes, taken over from a dead holder).  The rows' room is reserved before it is mapped, so a full disk
is ENOSPC — refused before the first step, or a stop at a step boundary whose checkpoint resumes to the
same bits — never SIGBUS.  (Two real ``ngwear run`` processes into one folder, and a disk that fills during
a run or before its results are written: ``test_long_runs.py``.)
"""
import errno
import os
import re
import subprocess
import sys
import threading

import numpy as np
import pytest
from conftest import PAPER
from test_cli import ngwear

import ngwear as ng
from ngwear.results.folder import LOCK, FolderError, NoSpace, hold
from ngwear.results.recording import History, Recording

pytestmark = pytest.mark.hostile


def small(**changes):
    return ng.load_scene(PAPER).replace(**{"mesh.maxh": 0.2, "time.steps": 40, **changes})


def in_use(key, folder, holder):
    return rf"^{key}: {re.escape(str(folder))} is in use by ngwear \({holder}\)$"


def test_a_folder_is_held_by_one_thread_at_a_time(tmp_path):
    refused = []

    def other():
        try:
            with hold(tmp_path, "checkpoint"):
                refused.append(None)
        except FolderError as err:
            refused.append(str(err))

    with hold(tmp_path, "--out"):
        with hold(tmp_path, "checkpoint"):          # re-entrant: the CLI holds it around simulate, which holds it too
            thread = threading.Thread(target=other)
            thread.start()
            thread.join()
        assert (tmp_path / LOCK).read_text().split()[0] == str(os.getpid())
    assert re.match(in_use("checkpoint", tmp_path, f"PID {os.getpid()}, another thread"), refused[0])
    thread = threading.Thread(target=other)             # released: the other thread takes it
    thread.start()
    thread.join()
    assert refused[1] is None


def test_a_folder_another_process_holds_is_refused_until_it_dies(tmp_path):
    code = ("import sys, time\nfrom ngwear.results.folder import hold\nwith hold(sys.argv[1], 'x'):\n"
            "    print('held', flush=True)\n    time.sleep(600)\n")
    holder = subprocess.Popen([sys.executable, "-c", code, str(tmp_path)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(FolderError, match=in_use("checkpoint", tmp_path, f"PID {holder.pid}")):
            ng.simulate(small(), progress=False, checkpoint=tmp_path)
        with pytest.raises(FolderError, match=in_use("resume", tmp_path, f"PID {holder.pid}")):
            ng.simulate(None, progress=False, resume=tmp_path, checkpoint=tmp_path / "elsewhere")
        assert not list(tmp_path.glob("steps-*"))
    finally:
        holder.kill()
        holder.wait()
    assert (tmp_path / LOCK).read_text().split()[0] == str(holder.pid)      # the dead holder's lock file stays
    assert ng.simulate(small(), progress=False, checkpoint=tmp_path).completed
    assert (tmp_path / LOCK).read_text().split()[0] == str(os.getpid())     # taken over


def test_rows_that_do_not_fit_are_refused_before_the_first_step(small_disk, tmp_path):
    disk = small_disk(2)
    proc = ngwear("run", PAPER, "--out", disk / "run", "--set", "mesh.maxh=0.2", "time.steps=20000", "--quiet",
                  "--no-pictures", cwd=tmp_path)
    size = 20001 * 8 * (3 + (4 + 2) * 16)           # t, s_v, s_F, and w, u_ν, p, λ and 2D forces at 16 contact points
    assert proc.returncode == 1 and proc.stderr.strip().splitlines() == [
        f"ngwear: --out: no space left on device in {disk / 'run'} for the rows of 20001 steps "
        f"({size / 1e6:.4g} MB); nothing was computed"]
    assert not list((disk / "run").glob("steps-*"))


def test_rows_on_a_full_disk_are_enospc_not_sigbus_and_give_back_their_room(small_disk):
    disk = small_disk(1)
    history = History.empty({"times": (), "wear": (4096,)}, 2, disk)        # 32 kB a row: 2 → 6 → 14 → 30 → 62
    with pytest.raises(OSError) as info:
        for j in range(100):
            history.put("times", j, float(j))
            history.put("wear", j, float(j))
    assert info.value.errno == errno.ENOSPC and j == 30
    assert np.array_equal(history.buffers["wear"][:30, -1], np.arange(30.0))
    assert (history.folder / "wear.f64").stat().st_size == 30 * 32768        # the room of 62 rows given back
    (disk / "checkpoint").write_bytes(bytes(32768))                          # so a checkpoint still fits


def test_rows_that_cannot_grow_stop_the_run_and_it_resumes_to_the_same_bits(small_disk):
    """An adaptive run doubles its rows (4 243 explicit steps from room for 101): a full disk stops it, all kept.

    Once there is room it goes on as if it had never stopped.
    """
    scene = small(**{"time.adaptive": True, "time.tolerance": 1e-4, "time.steps": 100, "wear.integrator": "explicit"})
    full = ng.simulate(scene, progress=False)
    disk = small_disk(4)                                # 776 B a row: the rows' doubling past 3 232 does not fit
    with pytest.raises(NoSpace) as info:
        ng.simulate(scene, progress=False, checkpoint=disk / "run")
    part = info.value.result
    assert 0 < part.steps < full.steps and info.value.resumable
    assert str(info.value) == (f"no space left on device in {disk / 'run'}: the run stopped after step {part.steps} "
                               f"(t = {part.times[-1]:.4g}); its checkpoint keeps steps 0-{part.steps} "
                               f"(t <= {part.times[-1]:.4g}): free space, then resume from it")
    assert np.array_equal(part.wear, full.wear[:part.steps + 1])
    small_disk.resize(disk, 64)
    resumed = ng.simulate(scene, progress=False, resume=disk / "run")
    assert np.array_equal(resumed.times, full.times) and np.array_equal(resumed.wear, full.wear)
    assert [r.residuals for r in resumed.newton] == [r.residuals for r in full.newton]


def test_a_new_run_in_a_folder_checkpoints_its_own_mesh(tmp_path, monkeypatch):
    """A run on another mesh into an old run's folder, stopped before it saves its result, resumes on its own mesh."""
    ng.simulate(small(), progress=False, checkpoint=tmp_path)
    other = small(**{"mesh.maxh": 0.25, "output.checkpoint_seconds": 0.0})
    stop, calls, append = threading.Event(), [], Recording.append

    def counting(recording, *step):
        append(recording, *step)
        calls.append(1)
        if len(calls) == 11:
            stop.set()

    monkeypatch.setattr(Recording, "append", counting)
    part = ng.simulate(other, progress=False, checkpoint=tmp_path, stop=stop)
    monkeypatch.undo()
    assert part.status == "interrupted" and part.steps == 10
    resumed = ng.simulate(None, progress=False, resume=tmp_path)
    direct = ng.simulate(other, progress=False)
    assert resumed.weights.size == direct.weights.size != 16 and np.array_equal(resumed.wear, direct.wear)
