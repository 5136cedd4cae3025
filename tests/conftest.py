"""Shared fixtures: the paper's scene and a run of it (computed once per session), the docs site, a small disk.

The slow and browser tests run first: on the two workers of ``scripts/test.sh`` the long ones then overlap from the
start, and the run does not end with one worker idle while the other finishes a long test.
"""
import fcntl
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

import ngwear

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "geometries" / "paper_strip.toml"


def pytest_collection_modifyitems(items):
    items.sort(key=lambda item: not (item.get_closest_marker("slow") or item.get_closest_marker("browser")))


@pytest.fixture(scope="session")
def paper_scene():
    return ngwear.load_scene(PAPER)


@pytest.fixture(scope="session")
def paper_result(paper_scene):
    return ngwear.simulate(paper_scene, progress=False)


@pytest.fixture(scope="session")
def site(tmp_path_factory, worker_id):
    """(html folder, build record): the site built once for all workers of the session (``sphinx-build -W``).

    Every gallery example runs in the build, and its check (tests/demo_checks.py) after it: the record's
    ``checks`` holds them by example name, for tests/test_demos.py.
    """
    base = tmp_path_factory.getbasetemp()
    root = base if worker_id == "master" else base.parent
    folder = root / "docs-site"
    with open(root / "docs-site.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (folder / "build.json").is_file():
            folder.mkdir(exist_ok=True)
            checks = folder / "checks.jsonl"
            start = time.monotonic()
            done = subprocess.run([sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-q",
                                   str(ROOT / "docs"), str(folder / "html")], capture_output=True, text=True,
                                  cwd=ROOT, env={**os.environ, "NGWEAR_DEMO_CHECKS": str(checks)})
            lines = checks.read_text().splitlines() if checks.is_file() else []
            (folder / "build.json").write_text(json.dumps({
                "returncode": done.returncode, "seconds": round(time.monotonic() - start, 1), "worker": worker_id,
                "log": (done.stdout[-4000:] + "\n" + done.stderr[-20000:]).strip(),
                "checks": {check["name"]: check for check in map(json.loads, lines)}}))
    record = json.loads((folder / "build.json").read_text())
    if record["returncode"] != 0:
        pytest.fail(f"the docs build failed:\n{record['log']}")
    return folder / "html", record


@pytest.fixture
def small_disk(tmp_path):
    """``small_disk(megabytes)``: a new folder on a tmpfs of that size, unmounted after the test.

    ``small_disk.resize(folder, megabytes)`` grows it.  Skips where mounting is not allowed (not root, no
    ``mount``, a container without CAP_SYS_ADMIN).
    """
    mounts = []

    def run(*args):
        try:
            return subprocess.run(args, capture_output=True, text=True, timeout=60)
        except OSError as err:
            pytest.skip(f"cannot mount a tmpfs here ({err})")

    def mount(megabytes):
        folder = tmp_path / f"disk{len(mounts)}"
        folder.mkdir()
        done = run("mount", "-t", "tmpfs", "-o", f"size={megabytes}m", "tmpfs", str(folder))
        if done.returncode:
            pytest.skip(f"cannot mount a tmpfs here ({done.stderr.strip() or done.returncode})")
        mounts.append(folder)
        return folder

    mount.resize = lambda folder, megabytes: run("mount", "-o", f"remount,size={megabytes}m", str(folder))
    yield mount
    for folder in mounts:
        run("umount", "-l", str(folder))
