"""The set-up scripts recover from what a machine does to them: a docs build interrupted, apt's lock held."""
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.hostile

ROOT = Path(__file__).resolve().parents[1]

CONF = '''import os, pathlib, time
project = "tiny"
def slow(app):                          # the search index half written when the build is interrupted
    if os.environ.get("HALFWAY"):
        def dump():
            pathlib.Path(app.outdir, "searchindex.js").write_text("Search.setIndex({")
            pathlib.Path(os.environ["HALFWAY"]).touch()
            time.sleep(60)
        app.builder.dump_search_index = dump
def setup(app):
    app.connect("builder-inited", slow)
'''


@pytest.fixture
def tiny_checkout(tmp_path):
    """A checkout whose docs are two pages: the real scripts/docs.sh, bootstrap done, this interpreter's Sphinx."""
    pytest.importorskip("sphinx", reason="the docs build needs the docs extra (pip install 'ngwear[docs]')")
    (tmp_path / "scripts").mkdir()
    shutil.copy(ROOT / "scripts" / "docs.sh", tmp_path / "scripts")
    (tmp_path / "scripts" / "bootstrap.sh").write_text("true\n")
    python = tmp_path / ".venv" / "bin" / "python"
    python.parent.mkdir(parents=True)
    python.write_text(f'#!/bin/sh\nexec "{sys.executable}" "$@"\n')
    python.chmod(0o755)
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "conf.py").write_text(CONF)
    (tmp_path / "docs" / "index.rst").write_text("Tiny\n====\n\n.. toctree::\n\n   page\n")
    (tmp_path / "docs" / "page.rst").write_text("Page\n====\n\nA word to index.\n")
    return tmp_path


def test_a_docs_build_after_an_interrupted_one_builds_anew(tiny_checkout):
    """Ctrl-C while the search index is written: the next build, which would fail on it, starts afresh."""
    halfway = tiny_checkout / "halfway"
    first = subprocess.Popen(["bash", "scripts/docs.sh"], cwd=tiny_checkout, start_new_session=True,
                             env={**os.environ, "HALFWAY": str(halfway)}, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while not halfway.exists() and first.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert halfway.exists(), "the first build reached its search index"
    os.killpg(first.pid, signal.SIGINT)                                          # as Ctrl-C in its terminal
    assert first.wait(timeout=60) != 0
    again = subprocess.run(["bash", "scripts/docs.sh"], cwd=tiny_checkout, capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stdout[-2000:] + again.stderr[-2000:]
    assert "the last docs build was interrupted: building anew" in again.stderr
    assert "Search.setIndex" in (tiny_checkout / "docs/_build/html/searchindex.js").read_text()
    third = subprocess.run(["bash", "scripts/docs.sh"], cwd=tiny_checkout, capture_output=True, text=True, timeout=120)
    assert third.returncode == 0 and "building anew" not in third.stderr, "a finished build is continued"


def held(path, seconds):
    """A process holding ``path``'s fcntl lock (as apt and dpkg take theirs) for ``seconds``."""
    code = (f"import fcntl, time; f = open({str(path)!r}, 'a'); fcntl.lockf(f, fcntl.LOCK_EX); print(flush=True); "
            f"time.sleep({seconds})")
    holder = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    holder.stdout.readline()
    return holder


APT_LOCK = Path("/var/cache/apt/archives/lock")


@pytest.mark.skipif(os.geteuid() != 0 or shutil.which("apt-get") is None or not APT_LOCK.exists(),
                    reason="apt's locks are root's, on a machine with apt")
def test_apt_waits_while_another_package_manager_holds_its_lock_then_goes_on():
    """``apt-get clean`` fails at once on the archives' lock; scripts/apt_get.sh waits for it (bounded) and goes on."""
    holder = held(APT_LOCK, 3)
    plain = subprocess.run(["apt-get", "clean"], capture_output=True, text=True)
    start = time.monotonic()
    waited = subprocess.run(["bash", ROOT / "scripts" / "apt_get.sh", "clean"], capture_output=True, text=True,
                            timeout=120)
    holder.wait()
    assert plain.returncode != 0 and "Could not get lock" in plain.stderr
    assert waited.returncode == 0 and time.monotonic() - start >= 2.0, waited.stderr
    assert waited.stderr.splitlines() == ["ngwear: another package manager holds apt's lock: waiting for it"]
    holder = held(APT_LOCK, 30)
    bounded = subprocess.run(["bash", ROOT / "scripts" / "apt_get.sh", "clean"], capture_output=True, text=True,
                             env={**os.environ, "NGWEAR_APT_WAIT": "2"}, timeout=120)
    holder.kill()
    assert bounded.returncode == 1 and "Could not get lock" in bounded.stderr, "it waits no longer than it is told"
