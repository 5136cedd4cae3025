"""Shared fixtures: the paper's scene and a run of it (computed once per session)."""
import subprocess
from pathlib import Path

import pytest

import ngwear

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "geometries" / "paper_strip.toml"


@pytest.fixture(scope="session")
def paper_scene():
    return ngwear.load_scene(PAPER)


@pytest.fixture(scope="session")
def paper_result(paper_scene):
    return ngwear.simulate(paper_scene, progress=False)


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
