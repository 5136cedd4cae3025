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


@pytest.mark.hostile
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
@pytest.mark.hostile
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
    units = {key: value.split(None, 1)[1] for key, value in summary.items() if key in (
        "normal_force", "torque", "friction_force", "contact_area", "wear_volume", "max_wear", "plate_displacement")}
    assert units == {"normal_force": "N", "torque": "N·m", "friction_force": "N", "contact_area": "m²",
                     "wear_volume": "m³", "max_wear": "m", "plate_displacement": "m"}      # a scene in SI
    value = {key: float(text.split()[0]) for key, text in summary.items() if key in units}
    assert value["normal_force"] == pytest.approx(3000, rel=1e-9)
    assert value["torque"] < 0 and value["plate_displacement"] > 0
    assert value["contact_area"] == pytest.approx(np.pi / 6 * (0.15 ** 2 - 0.10 ** 2), rel=0.01)
    data = np.load(out / "result.npz")
    for key in ("torque", "normal_force", "contact_area", "wear_volume", "plate_displacement", "friction_force"):
        assert data[key].shape[0] == 21, key
    assert data["torque"][-1] == pytest.approx(value["torque"], rel=1e-3)
    pictures = {p.name for p in out.glob("*.png")}
    assert {"contact_maps.png", "history.png", "pressure_radius.png"} <= pictures
    frames = [int(s) for s in data["field_steps"]]               # t = 0, 50, 100, 150 of 20 steps to T = 150
    assert frames == [0, 7, 13, 20]
    assert sorted(p.name for p in out.glob("fields_step*.vtu")) == [f"fields_step{s:03d}.vtu" for s in frames]
    assert sorted(p for p in pictures if p.startswith("fig")) == [f"fig{k}_step{s:03d}.png"
                                                                   for k, s in enumerate(frames[1:], start=1)]


def test_shipped_scene_by_name_from_any_folder(tmp_path):
    """`ngwear run paper_strip` in an empty folder; an unknown name: one line listing the shipped scenes."""
    proc = ngwear("run", "paper_strip", "--set", "mesh.maxh=0.25", "time.steps=4", "wear.integrator=implicit",
                  "--no-pictures", "--quiet", "--out", "o", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert json.loads((tmp_path / "o" / "scene.json").read_text())["name"] == "paper_strip"
    proc = ngwear("run", "paper_strp", "--quiet", cwd=tmp_path)
    assert_one_line_error(proc, "scene file")
    from ngwear.model import examples
    assert f"(shipped: {', '.join(examples.names())};" in proc.stderr and "brake_pad, brake_pad_compaction" in proc.stderr


def test_examples_listed_copied_and_run(tmp_path):
    """`ngwear examples` lists each scene in one line; --copy DIR copies them (refusing to overwrite) and they run."""
    from ngwear.model import examples
    listed = ngwear("examples", cwd=tmp_path)
    assert listed.returncode == 0 and listed.stderr == ""
    lines = listed.stdout.splitlines()
    assert [line.split()[0] for line in lines] == examples.names() == sorted(p.stem for p in PAPER.parent.glob("*.toml"))
    assert all(len(line.split(None, 1)[1]) > 20 and len(line) < 120 for line in lines)
    copied = ngwear("examples", "--copy", "mine", cwd=tmp_path)
    assert copied.returncode == 0, copied.stderr
    files = {p.relative_to(tmp_path / "mine").as_posix() for p in (tmp_path / "mine").rglob("*") if p.is_file()}
    assert files == {p.as_posix() for p in examples.shipped_files()}
    assert {"cad_pad.step", "scene.schema.json", "studies/friction_wear.toml"} <= files
    (tmp_path / "mine" / "paper_strip.toml").write_text((tmp_path / "mine" / "paper_strip.toml").read_text()
                                                        .replace("steps = 100", "steps = 5"))
    proc = ngwear("run", "mine/paper_strip.toml", "--set", "mesh.maxh=0.25", "wear.integrator=implicit",
                  "--no-pictures", "--quiet", "--out", "o", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["steps"] == 5       # the copy, edited, ran
    assert ngwear("run", "mine/cad_pad.toml", "--set", "time.steps=0", cwd=tmp_path).stderr.startswith(
        "ngwear: time.steps:")                                    # its CAD part is found beside it
    again = ngwear("examples", "--copy", "mine", cwd=tmp_path)
    assert_one_line_error(again, "--copy")
    assert "exists" in again.stderr and "steps = 5" in (tmp_path / "mine" / "paper_strip.toml").read_text()


def test_every_command_takes_quiet_and_verbose():
    from ngwear.cli.commands import _parser
    parser = _parser()
    commands = {"run": ["x.toml"], "verify": [], "schema": [], "sweep": ["s.toml"], "explore": [], "examples": [],
                "stress": []}
    assert set(commands) == set(parser._subparsers._group_actions[0].choices)
    for command, rest in commands.items():
        for flag in ("--quiet", "--verbose", "-q", "-v"):
            args = parser.parse_args([command, flag, *rest])
            assert (args.quiet, args.verbose) == (flag in ("--quiet", "-q"), flag in ("--verbose", "-v")), command


def test_help_is_plain_text(capsys):
    """`ngwear --help` and every command's: no reST (``…``, :func:), read in a terminal as it is."""
    from ngwear.cli.commands import _parser
    parser = _parser()
    commands = parser._subparsers._group_actions[0].choices
    texts = [parser.format_help(), *(command.format_help() for command in commands.values())]
    assert all("``" not in text and ":func:" not in text and ":mod:" not in text for text in texts), texts
    assert "ngwear COMMAND --help" in texts[0] and "tcp://host:8786" in commands["sweep"].format_help()


def test_progress_without_a_terminal_is_one_line_per_stage(tmp_path):
    """With stderr a pipe (CI, a batch job): stage lines and the count at each tenth, no carriage return; --quiet: none."""
    args = ["run", PAPER, "--set", "mesh.maxh=0.25", "time.steps=20", "time.T=0.5", "--no-pictures", "--no-check",
            "--out"]                                # to t = 0.5: the layer is not worn through (a warning)
    proc = ngwear(*args, tmp_path / "a", cwd=tmp_path)
    assert proc.returncode == 0 and "\r" not in proc.stderr, proc.stderr
    lines = proc.stderr.splitlines()
    assert all(line.startswith("ngwear: paper_strip: ") for line in lines), lines
    assert any("factorising K" in line for line in lines) and any("contact compliance" in line for line in lines)
    counts = [line.split(": ")[2].split(" [")[0] for line in lines if " of 20 steps" in line]
    assert counts == [f"{n} of 20 steps" for n in range(0, 21, 2)]
    quiet = ngwear(*args, tmp_path / "b", "--quiet", cwd=tmp_path)
    assert quiet.returncode == 0 and quiet.stderr == ""


def test_progress_in_a_terminal_is_a_bar(tmp_path):
    """With stderr a terminal: tqdm's bar, redrawn with carriage returns."""
    import fcntl
    import os
    import pty
    import struct
    import termios
    import threading
    main, child = pty.openpty()
    fcntl.ioctl(child, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))     # 100 columns wide
    drawn = []

    def read():                         # while the run writes: a terminal's buffer is small
        while True:
            try:
                chunk = os.read(main, 65536)
            except OSError:             # the run ended and closed its end
                return
            if not chunk:
                return
            drawn.append(chunk)

    reader = threading.Thread(target=read)
    reader.start()
    proc = subprocess.run([*COMMAND, "run", str(PAPER), "--set", "mesh.maxh=0.25", "time.steps=20", "--no-pictures",
                           "--no-check", "--out", str(tmp_path / "a")], cwd=tmp_path, stdout=subprocess.PIPE,
                          stderr=child, timeout=120)
    os.close(child)
    reader.join(timeout=10)
    os.close(main)
    drawn = b"".join(drawn)
    assert proc.returncode == 0
    assert b"\r" in drawn and b"| 0 of 20 steps [" in drawn and b"factorising K" in drawn       # the bar's format
    assert b"ngwear: paper_strip: 0 of 20 steps" not in drawn                                      # not log lines
