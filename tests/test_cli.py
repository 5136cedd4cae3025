"""The ``ngwear`` console script: bad input → status 2 and one line naming the field; a tiny run works."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "geometries" / "paper_strip.toml"
SCRIPT = Path(sys.executable).with_name("ngwear")
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "ngwear.cli"]


def ngwear(*args, cwd) -> subprocess.CompletedProcess:
    return subprocess.run([*COMMAND, *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=120)


@pytest.fixture
def bad_scene(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(PAPER.read_text().replace("gap = 0.2", "gap = -0.2"))
    return path


def assert_one_line_error(proc, field):
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(f"ngwear: {field}:"), lines[0]
    assert proc.stdout == ""


def test_bad_scene_file(tmp_path, bad_scene):
    proc = ngwear("run", bad_scene, "--quiet", "--no-pictures", cwd=tmp_path)
    assert_one_line_error(proc, "contact.gap")
    assert "> 0" in proc.stderr and "-0.2" in proc.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("scene, sets, field", [
    ("missing.toml", [], "scene file"),
    ("invalid.toml", [], "scene file"),
    (PAPER, ["time.steps=0"], "time.steps"),
    (PAPER, ["mesh.maxh=0.25", "time.steps=2.5"], "time.steps"),
    (PAPER, ["contact.friction=nan"], "contact.friction"),
    (PAPER, ["solver.method=full", "wear.integrator=implicit"], "solver.method"),
    (PAPER, ["loads.traction.left=[0.0, 1.0]"], "loads.traction.left"),
    (PAPER, ["plot.dpi=300"], "plot"),
    (PAPER, ["time.steps"], "--set time.steps"),
], ids=["missing-file", "invalid-toml", "steps-zero", "steps-fraction", "nan", "full-implicit",
        "traction-dirichlet", "unknown-section", "set-without-equals"])
def test_bad_input_exits_2_with_one_line(tmp_path, scene, sets, field):
    (tmp_path / "invalid.toml").write_text("[time]\nsteps = = 3\n")
    args = ["run", scene, "--quiet", "--no-pictures"] + (["--set", *sets] if sets else [])
    proc = ngwear(*args, cwd=tmp_path)
    assert_one_line_error(proc, field)
    if scene == "missing.toml":
        assert "does not exist" in proc.stderr
    if scene == "invalid.toml":
        assert "not valid TOML" in proc.stderr


def test_tiny_run(tmp_path):
    out = tmp_path / "run"
    proc = ngwear("run", PAPER, "--set", "mesh.maxh=0.25", "time.steps=4", "wear.integrator=trapezoidal",
                  "--no-pictures", "--quiet",
                  "--out", out, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    assert "max_wear" in proc.stdout and "newton_iterations" in proc.stdout
    summary = dict(line.split(None, 1) for line in proc.stdout.strip().splitlines())
    assert summary["status"] == "completed" and int(summary["steps"]) == 4
    assert float(summary["max_wear"]) > 0 and int(summary["newton_iterations_total"]) > 0
    for name in ("result.npz", "scene.json", "fields.pvd"):
        assert (out / name).is_file(), name
    scene = json.loads((out / "scene.json").read_text())
    assert scene["time"]["steps"] == 4 and scene["mesh"]["maxh"] == 0.25
    data = np.load(out / "result.npz")
    assert data["wear"].shape[0] == 5 and float(data["wear"].max()) == pytest.approx(float(summary["max_wear"]), rel=1e-3)


def test_brake_pad_run_writes_results_maps_and_plots(tmp_path):
    """The shipped brake pad at a coarse mesh: summary lines of the part, result keys and the pictures."""
    out = tmp_path / "pad"
    proc = ngwear("run", ROOT / "geometries" / "brake_pad.toml", "--set", "mesh.maxh=0.012", "time.steps=20",
                  "--quiet", "--out", out, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = dict(line.split(None, 1) for line in proc.stdout.strip().splitlines())
    assert float(summary["normal_force"]) == pytest.approx(3000, rel=1e-9)
    assert float(summary["torque"]) < 0 and float(summary["plate_displacement"]) > 0
    assert float(summary["contact_area"]) == pytest.approx(np.pi / 6 * (0.15 ** 2 - 0.10 ** 2), rel=0.01)
    data = np.load(out / "result.npz")
    for key in ("torque", "normal_force", "contact_area", "wear_volume", "plate_displacement"):
        assert data[key].shape[0] == 21, key
    assert data["torque"][-1] == pytest.approx(float(summary["torque"]), rel=1e-3)
    pictures = {p.name for p in out.glob("*.png")}
    assert {"contact_maps.png", "history.png", "pressure_radius.png", "fig4_step020.png"} <= pictures
