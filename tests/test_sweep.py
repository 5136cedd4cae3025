"""Studies on Dask: a local cluster and a CLI-started one agree, failures are recorded, studies resume.

Clusters here are processes on 127.0.0.1 with ports chosen by the OS; every process a test starts is
in its own process group and killed at teardown.
"""
import json
import logging
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import PAPER, ROOT
from threadpoolctl import threadpool_limits

import ngwear
from ngwear.results.history_csv import bare
from ngwear.studies.outputs import OUTPUTS, outputs
from ngwear.studies.study import load_study

DASK = str(Path(sys.executable).with_name("dask"))
GRID = f'''scene = "{PAPER}"
[set]
"mesh.maxh" = 0.2
"time.steps" = 20
[grid]
"contact.friction" = [0.3, 0.9]
"contact.wear" = [0.5, 1.5]
'''
NUMBERS = ["case", "contact.friction", "contact.wear", *OUTPUTS, "status"]


def write(tmp_path, text, name="study.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def local(tmp_path_factory):
    """The grid study on a LocalCluster of 2 worker processes."""
    tmp = tmp_path_factory.mktemp("local")
    path = write(tmp, GRID)
    return path, ngwear.sweep(path, out=tmp / "out", workers=2, progress=False), tmp / "out"


def test_local_cluster_grid_study(local):
    path, table, out = local
    study = load_study(path)
    assert list(table.columns[:3]) == ["case", "contact.friction", "contact.wear"]
    assert (table.status == "completed").all() and table.error.isna().all()
    for case, row in zip(study.cases, table.itertuples()):
        direct = outputs(ngwear.simulate(case.scene, progress=False))
        assert direct["steps"] == 20 and direct["worn_volume"] > 0
        np.testing.assert_allclose([getattr(row, k) for k in direct], list(direct.values()), rtol=1e-12)
        saved = ngwear.load_result(out / "cases" / row.case_id)
        assert saved.wear_volume[-1] == row.worn_volume and np.isclose(saved.weights @ saved.wear[-1], row.worn_volume)
    summary = table.attrs["summary"]
    assert table.worker.nunique() == 2 and summary["workers"] == 2 and summary["groups"] == 1
    assert summary["factorisations"] == table.factorised.sum() == 2, "one per worker for the one mesh/material"
    pd.testing.assert_frame_equal(pd.read_parquet(out / "results.parquet"), table)
    assert pd.read_csv(out / "results.csv").rename(columns=bare).worn_volume.tolist() == table.worn_volume.tolist()
    plots = sorted(p.name for p in (out / "plots").glob("*.png"))
    assert plots == ["contact.friction.png", "contact.wear.png", "heat_map.png"]
    assert json.loads((out / "summary.json").read_text()) == summary


def group(command, log):
    return subprocess.Popen(command, start_new_session=True, stdout=log, stderr=subprocess.STDOUT, cwd=ROOT)


def stop(processes):
    for p in processes:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGTERM)
    deadline = time.monotonic() + 15
    for p in processes:
        try:
            p.wait(timeout=max(0.1, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()


@pytest.fixture
def cli_cluster(tmp_path):
    """``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1; yields the address and processes."""
    file, log = tmp_path / "scheduler.json", (tmp_path / "dask.log").open("w")
    processes = [group([DASK, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                        "--scheduler-file", str(file)], log)]
    try:
        deadline = time.monotonic() + 60
        while not file.is_file() and time.monotonic() < deadline:
            time.sleep(0.1)
        address = json.loads(file.read_text())["address"]
        for name in ("first", "second"):
            processes.append(group([DASK, "worker", address, "--name", name, "--nthreads", "1", "--host", "127.0.0.1",
                                    "--no-dashboard"], log))
        yield address, processes
    finally:
        stop(processes)
        log.close()


def test_cli_cluster_gives_identical_numbers(local, cli_cluster, tmp_path):
    path, table, _ = local
    done = subprocess.run([sys.executable, "-m", "ngwear.cli", "sweep", str(path), "--scheduler", cli_cluster[0],
                           "--workers", "2", "--out", str(tmp_path / "out"), "--quiet"],
                          capture_output=True, text=True, cwd=ROOT, timeout=180)
    assert done.returncode == 0, done.stderr
    remote = pd.read_parquet(tmp_path / "out" / "results.parquet")
    pd.testing.assert_frame_equal(remote[NUMBERS], table[NUMBERS], check_exact=True)
    assert set(remote.worker) != set(table.worker) and remote.worker.nunique() == 2
    assert "4 cases (4 completed); 0 finished earlier, 4 run on 2 workers" in done.stdout


def test_cli_sweep_prints_its_table_and_path_not_dask_logs(tmp_path):
    """A successful `ngwear sweep` on a local cluster: the table and where it is; on stderr only its progress lines."""
    path = write(tmp_path, GRID)
    done = subprocess.run([sys.executable, "-m", "ngwear.cli", "sweep", str(path), "--workers", "2", "--out",
                           str(tmp_path / "out")], capture_output=True, text=True, cwd=tmp_path, timeout=180)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[0].split()[:3] == ["case", "contact.friction", "contact.wear"]
    assert done.stdout.rstrip().endswith(f"results in {tmp_path / 'out'}") and len(done.stdout.splitlines()) == 7
    lines = done.stderr.splitlines()
    assert lines and all(line.startswith("ngwear: study: ") or line.startswith("ngwear: Dask dashboard: ")
                         for line in lines), done.stderr
    assert "\r" not in done.stderr and "Traceback" not in done.stderr and "INFO" not in done.stderr
    one = write(tmp_path, GRID.replace("[0.3, 0.9]", "[0.3]").replace("[0.5, 1.5]", "[0.5]"), "one.toml")
    verbose = subprocess.run([sys.executable, "-m", "ngwear.cli", "sweep", str(one), "--workers", "1", "--out",
                              str(tmp_path / "again"), "--verbose"], capture_output=True, text=True, cwd=tmp_path,
                             timeout=180)
    assert verbose.returncode == 0 and "Scheduler" in verbose.stderr    # Dask's own lines, when asked for


def test_cases_of_a_dead_worker_run_on_the_other(cli_cluster, tmp_path):
    from distributed import Client

    address, processes = cli_cluster
    grid = GRID.replace('"mesh.maxh" = 0.2', '"mesh.maxh" = 0.1').replace("[0.3, 0.9]", "[0.3, 0.6, 0.9, 1.2]")
    path = write(tmp_path, grid)
    with Client(address) as client:
        client.wait_for_workers(2, timeout=60)
        second = next(a for a, w in client.scheduler_info(n_workers=-1)["workers"].items() if w["name"] == "second")
    tables = []
    run = threading.Thread(target=lambda: tables.append(
        ngwear.sweep(path, address, out=tmp_path / "out", workers=2, progress=False)))
    run.start()
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob("out/cases/*/row.json")) and time.monotonic() < deadline:
        time.sleep(0.02)
    finished = len(list(tmp_path.glob("out/cases/*/row.json")))
    stop(processes[2:])  # the second worker (and its nanny) dies with the study under way
    run.join(timeout=120)
    assert not run.is_alive() and tables, "the study finished"
    table = tables[0]
    assert len(table) == 8 and (table.status == "completed").all()
    assert (table.worker == second).sum() <= finished + 1 < 8, "the dead worker's cases ran on the other"


def test_failing_cases_are_recorded_and_do_not_stop_the_study(tmp_path):
    path = write(tmp_path, f'''scene = "{PAPER}"
[set]
"mesh.maxh" = 0.2
"time.steps" = 10
[[cases]]
"contact.wear" = 0.5
[[cases]]
"solver.max_iterations" = 1
[[cases]]
"contact.gap" = -1.0
''')
    table = ngwear.sweep(path, out=tmp_path / "out", workers=1, progress=False)
    study = load_study(path)
    assert table.status.tolist() == ["completed", "stopped", "rejected"]
    stopped = ngwear.simulate(study.cases[1].scene, progress=False)
    assert table.error[1] == stopped.status and table.error[1].startswith(
        "step 1 (t = 0.1): Newton did not converge in 1 iterations")
    assert table.error[2] == "contact.gap: must be > 0 (got -1.0)" and pd.isna(table.worker[2])
    assert table.steps[1] == 0 and table.max_wear[1] == 0 and table.max_wear[0] > 0
    assert table.attrs["summary"]["completed"] == 1 and table.attrs["summary"]["run"] == 2


def test_interrupted_study_resumes(tmp_path):
    path = write(tmp_path, f'''scene = "{PAPER}"
[set]
"mesh.maxh" = 0.1
"time.steps" = 100
[grid]
"contact.wear" = [0.25, 0.5, 0.75, 1.0, 1.25, 1.5]
''')
    out = tmp_path / "out"
    with (tmp_path / "first.log").open("w") as log:
        first = group([sys.executable, "-m", "ngwear.cli", "sweep", str(path), "--workers", "1", "--out", str(out),
                       "--quiet"], log)
        try:
            deadline = time.monotonic() + 120
            while not list(out.glob("cases/*/row.json")) and time.monotonic() < deadline and first.poll() is None:
                time.sleep(0.05)
            sent = time.monotonic()
            first.send_signal(signal.SIGINT)  # to the CLI alone: it stops its local cluster at a case boundary
            status = first.wait(timeout=60)
            took = time.monotonic() - sent
        finally:
            stop([first])
    kept = {p.parent.name: json.loads(p.read_text()) for p in out.glob("cases/*/row.json")}
    assert 1 <= len(kept) < 6 and not (out / "results.parquet").exists()
    assert status == 130 and took < 20
    assert (tmp_path / "first.log").read_text().splitlines()[-1] == (
        f"ngwear: interrupted after {len(kept)} of 6 cases (kept in {out}); resume with: ngwear sweep {path} --out "
        f"{out} --workers 1")
    table = ngwear.sweep(path, out=out, workers=1, progress=False)
    summary = table.attrs["summary"]
    assert (summary["skipped"], summary["run"], summary["completed"]) == (len(kept), 6 - len(kept), 6)
    for row in table.itertuples():
        if row.case_id in kept:
            assert row.wall_time == kept[row.case_id]["wall_time"] and row.worker == kept[row.case_id]["worker"]
    again = ngwear.sweep(path, out=out, workers=1, progress=False)
    assert again.attrs["summary"]["skipped"] == 6 and again.attrs["summary"]["run"] == 0
    pd.testing.assert_frame_equal(again, table)


def test_grouped_study_factorises_once_per_group(tmp_path):
    path = write(tmp_path, f'''scene = "{PAPER}"
[set]
"mesh.maxh" = 0.2
"time.steps" = 10
[grid]
"contact.friction" = [0.2, 0.5, 0.8]
"material.lame_mu" = [1.0, 2.0]
''')
    table = ngwear.sweep(path, out=tmp_path / "out", workers=1, progress=False)
    summary = table.attrs["summary"]
    assert (summary["cases"], summary["groups"], summary["factorisations"]) == (6, 2, 2)
    first = table.sort_values("case").groupby("material.lame_mu").factorised.apply(list)
    assert first.tolist() == [[True, False, False], [True, False, False]]


def test_study_of_regions_laws_and_fields(tmp_path):
    """Region, law and field keys in a grid and cases: text beside numbers, dotted region keys, groups by material."""
    path = write(tmp_path, f'''scene = "{PAPER}"
[set]
"mesh.maxh" = 0.25
"time.steps" = 10
"contact.wear" = 0.3
"geometry.backing" = 0.2
"material.regions.backing.poisson" = 0.3
[grid]
"material.regions.backing.young" = [10.0, 100.0]
"contact.friction" = [0.3, "where(x < 1.5, 0.3, 0.6)"]
[[cases]]
"material.law" = "linear"
[[cases]]
"material.law" = "compaction"
"material.compaction_modulus" = 5.0
''')
    table = ngwear.sweep(path, out=tmp_path / "out", workers=2, progress=False)
    keys = ["material.regions.backing.young", "contact.friction", "material.law", "material.compaction_modulus"]
    assert list(table.columns[:5]) == ["case", *keys]
    assert (table.status == "completed").all()
    assert table["contact.friction"].tolist() == ["0.3", "0.3", "where(x < 1.5, 0.3, 0.6)",
                                                  "where(x < 1.5, 0.3, 0.6)"] * 2
    assert table["material.law"].tolist() == ["linear", "compaction"] * 4
    assert np.isnan(table["material.compaction_modulus"][::2]).all() and (table["material.compaction_modulus"][1::2]
                                                                           == 5.0).all()
    assert table.attrs["summary"]["groups"] == 4
    for case, row in zip(load_study(path).cases, table.itertuples()):
        # Dask's workers run the BLAS on one thread: so does the direct run (on two, its dense algebra rounds
        # otherwise, and the compaction law's branch at an element with tr ε ≈ 0 may cost a Newton iteration more)
        with threadpool_limits(1):
            direct = outputs(ngwear.simulate(case.scene, progress=False))
        np.testing.assert_allclose([getattr(row, k) for k in direct], list(direct.values()), rtol=1e-12)
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "out" / "results.parquet"), table, check_like=False)
    assert {p.name for p in (tmp_path / "out" / "plots").iterdir()} >= {f"{k}.png" for k in keys}
    worn = table.set_index(["material.regions.backing.young", "contact.friction", "material.law"]).max_wear
    assert worn[(10.0, "0.3", "linear")] != worn[(100.0, "0.3", "linear")]     # the backing's stiffness acts


@pytest.mark.slow
def test_a_case_that_kills_its_process_fails_alone(tmp_path, monkeypatch):
    """Cases die by a segfault, os._exit and SIGKILL on a one-worker cluster: only they crash.

    Their neighbours complete on the same worker (never restarted) with the numbers of direct runs.
    """
    from crashing import Deaths
    from distributed import Client, LocalCluster

    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(ROOT / "tests"), str(ROOT), os.environ.get("PYTHONPATH", "")]))
    path = write(tmp_path, GRID.replace('"contact.wear" = [0.5, 1.5]', "").replace(
        "[0.3, 0.9]", "[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]"))
    deaths = {0.2: "segfault", 0.4: "exit", 0.6: "kill"}
    with (LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0",
                       silence_logs=logging.CRITICAL) as cluster, Client(cluster) as client):
        client.register_plugin(Deaths(deaths))
        table = ngwear.sweep(path, client, out=tmp_path / "out", progress=False)
        workers = list(client.scheduler_info(n_workers=-1)["workers"])
    culprits = table["contact.friction"].isin(deaths)
    assert table.status[culprits].eq("crashed").all() and table.status[~culprits].eq("completed").all()
    assert table.error[culprits].tolist() == ["the process running it died of SIGSEGV (Segmentation fault)",
                                              "the process running it exited with status 3",
                                              "the process running it died of SIGKILL (Killed; out of memory?)"]
    assert len(workers) == 1 and table.worker[~culprits].eq(workers[0]).all(), "one worker, never restarted"
    for case, row in zip(load_study(path).cases, table.itertuples()):
        if row.status == "completed":
            direct = outputs(ngwear.simulate(case.scene, progress=False))
            np.testing.assert_allclose([getattr(row, k) for k in direct], list(direct.values()), rtol=1e-12)
    assert not any((tmp_path / "out" / "cases" / c).exists() for c in table.case_id[culprits])
    assert (table.attrs["summary"]["crashed"], table.attrs["summary"]["completed"]) == (3, 4)


@pytest.mark.parametrize("address, reason", [
    ("not a url", "missing port number in address 'not a url'"),
    ("foo://host:1", "unknown address scheme 'foo'"),
])
def test_cli_refuses_a_scheduler_that_is_no_address(tmp_path, address, reason):
    path = write(tmp_path, GRID)
    done = subprocess.run([sys.executable, "-m", "ngwear.cli", "sweep", str(path), "--scheduler", address,
                           "--out", str(tmp_path / "out")], capture_output=True, text=True, cwd=ROOT, timeout=120)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and not (tmp_path / "out").exists()
    assert lines[0].startswith(f"ngwear: scheduler: {address!r} is not a scheduler address such as "
                               f"tcp://host:8786 ({reason}"), lines
