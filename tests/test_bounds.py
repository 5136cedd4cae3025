"""Inputs are bounded before they cost memory or time: frames, tables, nesting, expressions.

Each case is refused with one line naming the key (exit 2 from the CLI), or runs in memory that does not
grow with the number it gives.
"""
import dataclasses
import os
import signal
import subprocess
import sys
import time
import tracemalloc

import numpy as np
import psutil
import pytest
from conftest import PAPER

import ngwear
from ngwear.cli import main
from ngwear.model.coefficients import Coefficients
from ngwear.model.kinds import KINDS
from ngwear.model.netgen_meshing import estimate
from ngwear.model.rules import frame_count
from ngwear.model.scene import SceneError
from ngwear.model.scene_mesh import build_mesh

pytestmark = pytest.mark.hostile


def cli(capsys, *args) -> tuple[int, str]:
    """``ngwear ARGS`` in this process: its status and its stderr, checked to be one line."""
    status = main([str(a) for a in args])
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return status, lines[0]


# ---------------------------------------------------------------- frames


def brute_force_frames(times, every, end):
    """The frames as ``Result.stored_steps`` found them before: every output time k·every, its nearest step."""
    wanted = np.arange(0.0, end + 0.5 * every, every)
    wanted = wanted[wanted <= end * (1 + 1e-12)]
    return sorted({int(j) for j in np.abs(times[None, :] - wanted[:, None]).argmin(axis=1)} | {len(times) - 1})


def test_the_frames_are_those_of_every_output_time_without_listing_them(paper_result):
    """Random step grids and output intervals: the same frames as the list of all output times gives."""
    rng = np.random.default_rng(28)
    for _ in range(200):
        times = np.concatenate([[0.0], np.cumsum(rng.exponential(1.0, rng.integers(1, 40)))])
        every = times[-1] * 10 ** rng.uniform(-3, 0.3)
        scene = paper_result.scene.replace(**{"time.T": float(times[-1]), "output.every": min(every, times[-1])})
        kept = dataclasses.replace(paper_result, scene=scene, rows={**paper_result.rows, "times": times})
        assert kept.stored_steps == brute_force_frames(times, scene.output.every, times[-1])


def test_a_tiny_output_interval_costs_no_memory_after_the_run(paper_result):
    """output.every = 1e-12 T: every one of the 101 steps is a frame, found in kilobytes (not 7 TiB)."""
    scene = paper_result.scene.replace(**{"output.every": 1e-12})
    result = dataclasses.replace(paper_result, scene=scene)
    tracemalloc.start()
    try:
        frames = result.stored_steps
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert frames == list(range(101))
    assert peak < 1e6


def test_frames_beyond_max_frames_are_refused_before_the_run(paper_scene, tmp_path, capsys):
    """Frames are counted as the run would write them: one per step at most, one per output time adaptively."""
    assert frame_count(paper_scene.replace(**{"output.every": 1e-9})) == 101
    assert frame_count(paper_scene.replace(**{"time.adaptive": True, "output.every": 1e-3})) == 1001
    with pytest.raises(SceneError, match=r"^output\.every: 1e-05 gives 100001 frames, more than output\.max_frames "
                                         r"= 10000 .*output\.every >= 0\.0001"):
        paper_scene.replace(**{"time.adaptive": True, "output.every": 1e-5})
    assert paper_scene.replace(**{"time.adaptive": True, "output.every": 1e-5, "output.max_frames": 100_001})
    status, line = cli(capsys, "run", PAPER, "--out", tmp_path / "out", "--set", "time.steps=20000", "output.every=1e-9")
    assert status == 2
    assert line.startswith("ngwear: output.every: 1e-09 gives 20001 frames, more than output.max_frames")
    assert not (tmp_path / "out").exists()


# ---------------------------------------------------------------- nesting, tables, expressions


@pytest.mark.parametrize("where", ["file", "set"])
def test_deeply_nested_toml_is_one_line(tmp_path, capsys, where):
    """500 levels of '[' (past tomllib's recursion) and 50 (past the scene's nesting) end in one line, exit 2."""
    for depth, expected in ((500, "nested too deeply to read"), (50, "loads.time_table: nested deeper than 10 levels")):
        value = "[" * depth + "]" * depth
        if where == "file":
            scene = tmp_path / "deep.toml"
            scene.write_text(f'name = "deep"\n[loads]\ntime_table = {value}\n')
            status, line = cli(capsys, "run", scene, "--out", tmp_path / "out")
        else:
            status, line = cli(capsys, "run", PAPER, "--out", tmp_path / "out", "--set", f"loads.time_table={value}")
        assert status == 2 and expected in line
        assert not (tmp_path / "out").exists()


def test_tables_are_capped(paper_scene, tmp_path, capsys):
    """A table of more than 10 000 rows is refused naming its key; a 40 MB scene file before it is parsed."""
    rows = [[t, 1.0] for t in np.linspace(0.0, 1.0, 10_001)]
    with pytest.raises(SceneError, match=r"^loads\.time_table: at most 10000 rows \(got 10001\)$"):
        paper_scene.replace(**{"loads.time_table": rows})
    with pytest.raises(SceneError, match=r"^foundation\.speed_table: at most 10000 rows \(got 10001\)$"):
        paper_scene.replace(**{"foundation.speed_table": rows})
    rows = [[t, 1.0] for t in np.linspace(0.0, 1.0, 10_000)]
    assert len(paper_scene.replace(**{"loads.time_table": rows}).loads.time_table) == 10_000
    big = tmp_path / "big.toml"
    big.write_text('name = "big"\n[loads]\ntime_table = [' + "[0.5, 1.0], " * 2_000_000 + "]\n")     # 2 M rows
    status, line = cli(capsys, "run", big, "--out", tmp_path / "out")
    assert status == 2
    assert line.startswith(f"ngwear: scene file: {big} is 22.9 MB, more than a scene file's 1 MB")


def test_a_hash_in_an_expression_is_refused_and_line_breaks_are_spaces(paper_scene):
    with pytest.raises(SceneError, match=r"^contact\.friction: '#' at position 5 in \"0\.3 # c  \+ 5\" \(an expression "
                                         r"has no comments\)$"):
        paper_scene.replace(**{"contact.friction": "0.3 # c\n + 5"})
    scene = paper_scene.replace(**{"contact.friction": "0.3\n + 5"})
    assert Coefficients.of(scene.contact, np.array([[1.0, 0.0]])).friction == pytest.approx([5.3])


# ---------------------------------------------------------------- meshes


@pytest.mark.parametrize("name, sets", [("paper_strip", {}), ("paper_strip", {"mesh.maxh": 0.2, "mesh.contact_maxh": 0.01}),
                                        ("box3d", {}), ("box3d", {"mesh.maxh": 0.25, "mesh.contact_maxh": 0.06})])
def test_the_element_estimate_is_within_a_factor_two(name, sets):
    scene = ngwear.load_scene(name).replace(**sets)
    shape = KINDS[scene.geometry.kind].build(scene.geometry, scene.mesh)
    count, _ = estimate(shape, scene.dim, scene.mesh.maxh, scene.mesh.grading)
    assert 0.5 < count / build_mesh(scene).ne < 2


def test_a_mesh_beyond_max_elements_is_refused_before_meshing(paper_scene, tmp_path, capsys):
    status, line = cli(capsys, "run", PAPER, "--out", tmp_path / "out", "--quiet", "--set", "mesh.maxh=1e-6")
    assert status == 2
    assert line == ("ngwear: mesh.maxh: 1e-06 gives about 6.9e+12 elements, more than mesh.max_elements = 2000000 "
                    "(Netgen's memory and time grow with them); give a larger mesh.maxh, or raise mesh.max_elements")
    assert not (tmp_path / "out").exists()
    with pytest.raises(SceneError, match=r"^mesh\.contact_maxh: 0\.0001 gives about 2\.32e\+05 elements, more than "
                                         r"mesh\.max_elements = 100000 "):
        build_mesh(paper_scene.replace(**{"mesh.contact_maxh": 1e-4, "mesh.max_elements": 100_000}), use_cache=False)


def test_a_signal_ends_a_run_that_meshes_within_seconds(tmp_path):
    """Netgen meshing 430 000 elements (minutes) in its child: SIGINT kills it, the run ends at once, clean.

    (SIGTERM takes the same way: ``ngwear.cli.signals.on_signals``.)
    """
    proc = subprocess.Popen([sys.executable, "-m", "ngwear", "run", str(PAPER), "--out", str(tmp_path / "out"),
                             "--set", "mesh.maxh=0.004"], stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "NGWEAR_CACHE": str(tmp_path / "cache")})
    try:
        assert "mesh (Netgen" in proc.stderr.readline()
        deadline = time.monotonic() + 30
        while not psutil.Process(proc.pid).children() and time.monotonic() < deadline:
            time.sleep(0.05)
        children = psutil.Process(proc.pid).children(recursive=True)
        assert children, "the mesh is made in a child process"
        time.sleep(0.5)
        sent = time.monotonic()
        proc.send_signal(signal.SIGINT)
        status = proc.wait(timeout=10)
        took = time.monotonic() - sent
    finally:
        proc.kill()
    assert status == 128 + signal.SIGINT
    assert took < 5
    assert proc.stderr.read().strip() == "ngwear: interrupted during the set-up (meshing (Netgen)); nothing was computed"
    psutil.wait_procs(children, timeout=5)
    assert not any(child.is_running() for child in children)
    assert not (tmp_path / "out").exists()
    assert not list((tmp_path / "cache" / "meshes").glob("*"))
