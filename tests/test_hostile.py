"""The hostile suite: inputs no engineer means and files no run wrote, each refused in one line or run as meant.

Every declared scene key given values no engineer means (NaN, ±inf, a word, a nested list, a boolean, a table), a
programme's blocks and its CSV files as spreadsheets and accidents write them, files that are not files, command
lines typed wrong, and every key of a checkpoint dropped, made non-finite, cut short or set out of range.  Each
case holds when it is refused with one line naming the key, file or flag (never a traceback, never a NaN in a
scene), or, where the input is meant (a spreadsheet's byte-order mark, CRLF lines, units in a header), when it reads
as the clean input does.  ``pytest -m hostile`` runs this suite with the other files' failure paths, damaged files,
signals and plausibility checks, which are marked so too.
"""
import contextlib
import io
import math
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import PAPER

import ngwear
from ngwear.cli import main
from ngwear.model.scene import SceneError
from ngwear.model.sections import SECTIONS
from ngwear.results.checkpoint import CHECKPOINT

pytestmark = pytest.mark.hostile

STRIP = ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.2})
_DATA = STRIP.to_dict()
_DATA.pop("time")
_DATA["output"].pop("every")
PROGRAMME = ngwear.Scene.from_dict({**_DATA, "programme": {"stops": [{"count": 2, "duration": 0.5, "dwell": 0.5}],
                                                           "steps_per_stop": 2}})
HEATED = STRIP.replace(**{"heat.model": "conduction", "heat.partition": 0.5, "material.conductivity": 1.0,
                          "material.density": 1.0, "material.heat_capacity": 1.0})
THERMAL = {"material.conductivity", "material.density", "material.heat_capacity", "material.expansion",
           "foundation.temperature", "foundation.thermal_mass", "foundation.cooling", "foundation.conductivity",
           "foundation.density", "foundation.heat_capacity"}
TABLES = {"name", "material.regions", "loads.traction", "loads.plate", "programme.stops", "programme.file"}
"""Keys with tables of their own (their hostile values below), or the name (any text is a name)."""

NOT_MEANT = {"nan": math.nan, "inf": math.inf, "-inf": -math.inf, "word": "fast", "nested": [[1.0]],
             "boolean": True, "table": {"a": 1}}


def finite(value) -> bool:
    """No NaN or infinity anywhere in a scene's value."""
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, (list, tuple)):
        return all(map(finite, value))
    if isinstance(value, dict):
        return all(map(finite, value.values()))
    return True


def refusal(make) -> str | None:
    """The one line of ``make()``'s SceneError, or None where it made a scene (checked to hold finite numbers)."""
    try:
        scene = make()
    except SceneError as err:
        message = str(err)
        assert "\n" not in message and message, message
        return message
    assert finite(scene.to_dict()), "a scene holds a number that is not finite"
    return None


def base_of(dotted: str) -> ngwear.Scene:
    section = dotted.split(".")[0]
    return PROGRAMME if section == "programme" else HEATED if section == "heat" or dotted in THERMAL else STRIP


KEYS = [f"{section}.{name}" for section, table in SECTIONS.items() for name in table.model_fields
        if f"{section}.{name}" not in TABLES]


@pytest.mark.parametrize("value", NOT_MEANT.values(), ids=NOT_MEANT)
@pytest.mark.parametrize("dotted", KEYS)
def test_a_key_given_what_no_engineer_means_is_refused_naming_it(dotted, value):
    """Refused in one line that starts with the key, or (a text that is an expression, a number kept) finite."""
    message = refusal(lambda: base_of(dotted).replace(**{dotted: value}))
    if message is not None:
        assert message.startswith((f"{dotted}:", f"{dotted}[")), message


BLOCK_VALUES = {"nan": math.nan, "inf": math.inf, "negative": -1.0, "zero": 0.0, "word": "fast", "three": [1, 2, 3],
                "nan-pair": [math.nan, 1.0], "boolean": True, "huge": 1e300}


@pytest.mark.parametrize("value", BLOCK_VALUES.values(), ids=BLOCK_VALUES)
@pytest.mark.parametrize("name", ["count", "duration", "speed", "load", "dwell"])
def test_a_block_given_what_no_engineer_means_is_refused_naming_it(name, value):
    """A block's count, duration, factors or dwell: refused naming the block and the key, or a finite programme."""
    block = {"count": 2, "duration": 0.5, name: value}
    message = refusal(lambda: ngwear.Scene.from_dict({**_DATA, "programme": {"stops": [block]}}))
    if message is not None:
        assert message.startswith((f"programme.stops: block 1: {name}:", "programme.steps_per_stop:",
                                   "contact.wear:", "loads.")), message


GOOD_CSV = 'count,duration,speed,load,dwell\n3,5.0,"[1.0, 0.0]",,2.0\n2,4,,"[0.5, 1.5]",\n'
GOOD_BLOCKS = [(3, 5.0, (1.0, 0.0), (1.0, 1.0), 2.0), (2, 4.0, (1.0, 1.0), (0.5, 1.5), 0.0)]
READ_AS_MEANT = {
    "byte-order-mark": b"\xef\xbb\xbf" + GOOD_CSV.encode(),
    "crlf": GOOD_CSV.replace("\n", "\r\n").encode(),
    "blank-lines": GOOD_CSV.replace("2.0\n", "2.0\n\n").encode() + b"\n\n",
    "spaces": b'count, duration , speed, load, dwell\n 3, 5.0 , "[1.0, 0.0]", , 2.0\n2 ,4, , "[0.5, 1.5]",\n',
    "units-in-header": GOOD_CSV.replace("duration", "duration [s]").replace("dwell", "dwell [s]").encode(),
    "trailing-separators": GOOD_CSV.replace("\n", ",,\n").encode(),
    "quoted-numbers": GOOD_CSV.replace("3,5.0", '"3","5.0"').encode(),
}
REFUSED_CSV = {
    "semicolons": (b"count;duration\n3;5.0\n", "separated by semicolons?"),
    "tabs": (b"count\tduration\n3\t5.0\n", "separated by tabs?"),
    "utf-16": (GOOD_CSV.encode("utf-16"), "cannot read"),
    "latin-1": (b"count,duration\n3,5.0\xe9\n", "cannot read"),
    "random-bytes": (np.random.default_rng(3).bytes(2000), "cannot read"),
    "nul-byte": (b"count,duration\n3,5\x00.0\n", "line 2: duration"),
    "empty": (b"", "has no column 'count'"),
    "header-only": (b"count,duration\n", "has no blocks"),
    "comment-line": (b"# my stops\ncount,duration\n3,5.0\n", "has no column 'count'"),
    "capitals": (b"Count,Duration\n3,5.0\n", "has no column 'count'"),
    "wrong-unit": (b"count,duration [min]\n3,5.0\n", "its unit must be [s]"),
    "unit-on-a-factor": (b"count,duration,speed [m/s]\n3,5.0,1\n", "its unit must be no unit"),
    "value-without-a-column": (b"count,duration,\n3,5.0,7\n", "a value in a column without a name"),
    "nan": (b"count,duration\n3,nan\n", "duration: must be a finite number > 0"),
    "inf": (b"count,duration\n3,inf\n", "duration: must be a finite number > 0"),
    "overflowing": (b"count,duration\n3,1e400\n", "duration: must be a finite number > 0"),
    "fractional-count": (b"count,duration\n2.5,1\n", "count: must be a whole number"),
    "huge-count": (b"count,duration\n1e9,1\n", "count: must be in [1, 1000000]"),
    "one-speed": (b'count,duration,speed\n3,1,"[1.0]"\n', "speed: must be a number or [start, end]"),
    "letters": (b'count,duration,speed\n3,1,"[a, b]"\n', "speed: must be a number or [start, end]"),
    "repeated-column": (b"count,duration,duration\n3,1,1\n", "unknown or repeated column 'duration'"),
    "unknown-column": (b"count,duration,pressure\n3,1,1\n", "unknown or repeated column 'pressure'"),
    "no-duration": (b"count,speed\n3,1\n", "has no column 'duration'"),
    "extra-cell": (b"count,duration\n3,1,4\n", "line 2: has 3 cells, the header 2"),
    "missing-cell": (b"count,duration,dwell\n3,1\n", "line 2: has 2 cells, the header 3"),
    "negative-dwell": (b"count,duration,dwell\n3,1,-1\n", "dwell: must be >= 0"),
    "zero-count": (b"count,duration\n0,1\n", "count: must be in [1, 1000000]"),
    "a-megabyte-cell": (b"count,duration\n3," + b"1" * 1_000_000 + b"\n", "line 2: field larger than field limit"),
    "unclosed-quote": (b'count,duration,speed\n3,1,"[1.0, 0.0]\n', "line 2: unexpected end of data"),
    "text-after-a-quote": (b'count,duration,speed\n3,1,"[1.0, 0.0]"x\n', "line 2: ',' expected after '\"'"),
}


def programme_file(path: Path) -> ngwear.Scene:
    return ngwear.Scene.from_dict({**_DATA, "programme": {"file": str(path)}})


def blocks(scene) -> list[tuple]:
    return [(b.count, b.duration, tuple(b.speed), tuple(b.load), b.dwell) for b in scene.programme.blocks]


@pytest.mark.parametrize("name", READ_AS_MEANT)
def test_a_programme_file_as_spreadsheets_write_it_reads_as_the_clean_one(tmp_path, name):
    (tmp_path / "p.csv").write_bytes(READ_AS_MEANT[name])
    assert blocks(programme_file(tmp_path / "p.csv")) == GOOD_BLOCKS


@pytest.mark.parametrize("name", REFUSED_CSV)
def test_a_programme_file_no_one_means_is_one_line_naming_it(tmp_path, name):
    data, fragment = REFUSED_CSV[name]
    (tmp_path / "p.csv").write_bytes(data)
    message = refusal(lambda: programme_file(tmp_path / "p.csv"))
    assert message is not None and message.startswith("programme.file: ") and fragment in message, message


def not_a_file(kind: str, folder: Path) -> Path:
    """A path that is no scene or programme file: a folder, a device, a FIFO, a link to a device, a huge file."""
    path = folder / kind
    if kind == "folder":
        path.mkdir()
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "link-to-zero":
        path.symlink_to("/dev/zero")
    elif kind == "sparse-11-MB":
        with open(path, "wb") as file:
            file.truncate(11_000_000)
    elif kind == "missing":
        pass
    else:
        return Path(f"/dev/{kind}")
    return path


NOT_FILES = ["folder", "zero", "urandom", "null", "fifo", "link-to-zero", "sparse-11-MB", "missing"]


@pytest.mark.parametrize("kind", NOT_FILES)
def test_a_programme_file_that_is_no_file_is_refused_at_once(tmp_path, kind):
    message = refusal(lambda: programme_file(not_a_file(kind, tmp_path)))
    assert message is not None and message.startswith("programme.file: "), message


@pytest.mark.parametrize("kind", NOT_FILES)
def test_a_scene_file_that_is_no_file_is_refused_at_once(tmp_path, kind):
    message = refusal(lambda: ngwear.load_scene(not_a_file(kind, tmp_path)))
    assert message is not None and message.startswith("scene file: "), message


def test_a_link_to_a_programme_file_is_the_file(tmp_path):
    (tmp_path / "p.csv").write_text(GOOD_CSV)
    (tmp_path / "link.csv").symlink_to(tmp_path / "p.csv")
    assert blocks(programme_file(tmp_path / "link.csv")) == GOOD_BLOCKS


def command(argv, cwd) -> tuple[int, list[str], str]:
    """``ngwear ARGV`` in this process: its status, its stderr's lines and its stdout."""
    err, out = io.StringIO(), io.StringIO()
    with contextlib.chdir(cwd), contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        try:
            status = main([str(a) for a in argv])
        except SystemExit as exit_:
            status = exit_.code
    return status, err.getvalue().strip().splitlines(), out.getvalue()


COMMANDS = {
    "no-command": ([], "ngwear: the following arguments are required: command"),
    "unknown-command": (["fly"], "ngwear: argument command: invalid choice: 'fly'"),
    "quiet-and-verbose": (["run", PAPER, "-q", "-v"], "ngwear run: argument -v/--verbose: not allowed with"),
    "unknown-flag": (["run", PAPER, "--fast"], "ngwear: unrecognized arguments: --fast"),
    "run-without-scene": (["run"], "ngwear: scene file: missing"),
    "set-without-equals": (["run", PAPER, "--set", "time.steps=4", "contact.friction"], "ngwear: --set contact.friction"),
    "set-empty-key": (["run", PAPER, "--set", "=3"], "ngwear: --set =3: expected KEY=VALUE"),
    "set-unknown-key": (["run", PAPER, "--set", "contact.frictoin=0.3"], "ngwear: contact.frictoin: unknown key"),
    "set-negative": (["run", PAPER, "--set", "contact.friction=-1"], "ngwear: contact.friction: must be >= 0"),
    "set-nan": (["run", PAPER, "--set", "contact.friction=nan"], "ngwear: contact.friction: must be a finite"),
    "set-inf": (["run", PAPER, "--set", "time.T=inf"], "ngwear: time.T: must be a finite number"),
    "set-broken-list": (["run", PAPER, "--set", "contact.direction=[0,"], "ngwear: contact.direction:"),
    "set-a-section": (["run", PAPER, "--set", "contact=3"], "ngwear: contact: must be a table"),
    "set-below-a-number": (["run", PAPER, "--set", "contact.friction.x=3"], "ngwear: contact.friction.x:"),
    "set-zero-steps": (["run", PAPER, "--set", "time.steps=0"], "ngwear: time.steps: must be in [1, 1000000]"),
    "set-huge-mesh": (["run", PAPER, "--set", "mesh.maxh=1e9"], "ngwear: mesh.maxh: must be in (0, 3.0]"),
    "scene-missing": (["run", "nope.toml"], "ngwear: scene file: nope.toml does not exist"),
    "scene-typo": (["run", "paper_strp"], "ngwear: scene file: 'paper_strp' is neither a file nor a shipped scene"),
    "scene-folder": (["run", "folder"], "ngwear: scene file: folder is not a regular file"),
    "scene-device": (["run", "/dev/zero"], "ngwear: scene file: /dev/zero is not a regular file"),
    "scene-empty": (["run", "empty.toml"], "ngwear: scene file: empty.toml holds no keys"),
    "scene-not-toml": (["run", "broken.toml"], "ngwear: scene file: broken.toml is not valid TOML"),
    "scene-binary": (["run", "binary.toml"], "ngwear: scene file: cannot read binary.toml"),
    "out-is-a-file": (["run", PAPER, "--out", "afile"], "ngwear: --out: cannot write afile"),
    "resume-nowhere": (["run", "--resume", "nowhere"], "ngwear: --resume: nowhere holds no checkpoint.npz"),
    "resume-empty-folder": (["run", "--resume", "folder"], "ngwear: --resume: folder holds no checkpoint.npz"),
    "resume-a-file": (["run", "--resume", "afile"], "ngwear: --resume: afile holds no checkpoint.npz"),
    "verify-missing": (["verify", "nope.toml"], "ngwear: scene file: nope.toml does not exist"),
    "explore-missing": (["explore", "nope.toml"], "ngwear: scene file: nope.toml does not exist"),
    "stress-stray": (["stress", "nope.toml"], "ngwear stress: unrecognized arguments: nope.toml"),
    "schema-stray": (["schema", "extra"], "ngwear: unrecognized arguments: extra"),
    "copy-onto-a-file": (["examples", "--copy", "afile"], "ngwear: --copy: afile exists and is not a folder"),
    "sweep-missing": (["sweep", "nope.toml"], "ngwear: study file: cannot read nope.toml"),
    "sweep-a-folder": (["sweep", "folder"], "ngwear: study file: cannot read folder"),
    "workers-not-a-number": (["sweep", "nope.toml", "--workers", "two"], "ngwear sweep: argument --workers"),
    "port-not-a-number": (["explore", "--port", "http"], "ngwear explore: argument --port"),
}


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    folder = tmp_path_factory.mktemp("typed")
    (folder / "folder").mkdir()
    (folder / "afile").write_text("a file\n")
    (folder / "empty.toml").write_text("")
    (folder / "broken.toml").write_text("x = 1\n[[[\n")
    (folder / "binary.toml").write_bytes(np.random.default_rng(5).bytes(3000))
    return folder


@pytest.mark.parametrize("case", COMMANDS)
def test_a_command_typed_wrong_is_one_line_and_exit_2(workdir, case):
    argv, first = COMMANDS[case]
    status, lines, out = command(argv, workdir)
    assert status == 2 and len(lines) == 1 and out == "", (status, lines)
    assert lines[0].startswith(first), lines[0]


LONGER = {"time.T": 2.0, "time.steps": 40}


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """The output folder of the coarse strip's first second (a checkpoint of 20 steps) and its checkpoint's arrays."""
    folder = tmp_path_factory.mktemp("saved") / "run"
    scene = STRIP.replace(**{"time.T": 1.0, "time.steps": 20})
    assert ngwear.simulate(scene, checkpoint=folder, progress=False).completed
    with np.load(folder / CHECKPOINT) as data:
        arrays = {key: data[key] for key in data.files}
    return folder, arrays


def resumed(saved, tmp_path, change) -> str | None:
    """Resume a copy of the saved folder whose checkpoint ``change`` changed: its refusal's line, or None (it ran)."""
    folder = tmp_path / "run"
    shutil.copytree(saved[0], folder)
    data = dict(saved[1])
    change(data)
    np.savez(folder / CHECKPOINT, **data)
    try:
        run = ngwear.simulate(STRIP.replace(**LONGER), resume=folder, progress=False)
    except SceneError as err:
        assert "\n" not in str(err)
        return str(err)
    assert run.completed and run.steps == LONGER["time.steps"]
    return None


CHECKPOINT_KEYS = ("contact_points", "weights", "friction_coefficient", "wear_coefficient", "contact_stiffness",
                   "newton_iterations", "newton_converged", "newton_active", "newton_damped", "newton_bulk",
                   "newton_tangents", "newton_cutbacks", "newton_lengths", "newton_residuals", "status", "wall_time",
                   "solve_time", "rejected", "warnings", "jumped", "thickness", "removed_rows", "removed",
                   "moved_weights", "provenance", "x", "lam", "step", "rows", "history", "checksums", "mesh_sha256",
                   "scene")
"""Every key of a checkpoint of a run without heat or geometry updates."""
FLOATS = ("contact_points", "weights", "friction_coefficient", "wear_coefficient", "contact_stiffness", "wall_time",
          "solve_time", "thickness", "x", "lam", "step")
ARRAYS = ("contact_points", "weights", "friction_coefficient", "wear_coefficient", "contact_stiffness",
          "newton_iterations", "newton_converged", "newton_active", "newton_damped", "newton_bulk", "newton_tangents",
          "newton_cutbacks", "newton_lengths", "newton_residuals", "thickness", "x", "lam")


def test_the_cases_cover_every_key_of_the_checkpoint(saved):
    assert set(saved[1]) == set(CHECKPOINT_KEYS)


@pytest.mark.parametrize("key", CHECKPOINT_KEYS)
def test_a_checkpoint_without_a_key_is_refused_naming_it(saved, tmp_path, key):
    message = resumed(saved, tmp_path, lambda data: data.pop(key))
    assert message is not None and f"(no {key})" in message and CHECKPOINT in message, message


@pytest.mark.parametrize("key", FLOATS)
def test_a_checkpoint_with_a_nan_is_refused_naming_it(saved, tmp_path, key):
    def nan(data):
        data[key] = np.array(data[key], dtype=float)
        data[key].flat[0] = np.nan
    message = resumed(saved, tmp_path, nan)
    assert message is not None and f"not finite: {key}" in message, message


def test_a_failed_newtons_merit_may_be_nan(saved, tmp_path):
    """The one number a checkpoint may hold as NaN: a failed Newton iteration's merit (it is only a record)."""
    def nan(data):
        data["newton_residuals"] = data["newton_residuals"].copy()
        data["newton_residuals"][0] = np.nan
    assert resumed(saved, tmp_path, nan) is None


@pytest.mark.parametrize("key", ARRAYS)
def test_a_checkpoint_with_an_array_cut_short_is_refused(saved, tmp_path, key):
    message = resumed(saved, tmp_path, lambda data: data.__setitem__(key, data[key][:-1]))
    assert message is not None and CHECKPOINT in message or "mesh.vol" in message, message
    assert any(text in message for text in (f"{key} has the shape", "Newton records", "contact points differ")), message


OUT_OF_RANGE = {
    "negative-step": ("step", -1.0, "out of range: step"),
    "negative-rows": ("rows", -1, "Newton records for -1 steps"),
    "too-many-rows": ("rows", 10 ** 9, "Newton records for 1000000000 steps"),
    "checksums-not-json": ("checksums", "x", "its checksums are not a table"),
    "checksums-a-list": ("checksums", "[1, 2]", "its checksums are not a table"),
    "history-elsewhere": ("history", "../elsewhere", "names no history folder of its own"),
    "mesh-digest": ("mesh_sha256", "abc", "SHA-256 differs"),
    "provenance-not-json": ("provenance", "{", "holds no valid scene"),
    "scene-a-number": ("scene", 3, "its scene is not the one its run recorded"),
    "jumped-backwards": ("jumped", [5, 3], "out of range: jumped"),
    "removed-rows-without-surface": ("removed_rows", [99], "moved its worn surface 1 times but holds no"),
    "negative-rejected": ("rejected", -5, "out of range: rejected"),
    "negative-iterations": ("newton_iterations", [-1] * 21, "out of range: newton_iterations"),
    "negative-lengths": ("newton_lengths", [-1] * 21, "newton_residuals has the shape"),
    "x-a-word": ("x", "abc", "x has the shape ()"),
    "x-a-column": ("x", np.zeros((16, 1)), "x has the shape (16, 1)"),
    "negative-wall-time": ("wall_time", -1.0, "out of range: wall_time"),
    "negative-thickness": ("thickness", -np.ones(16), "out of range: thickness"),
    "negative-weights": ("weights", -np.ones(16), "out of range: weights"),
    "negative-friction": ("friction_coefficient", -np.ones(16), "out of range: friction_coefficient"),
    "negative-wear-coefficient": ("wear_coefficient", -np.ones(16), "out of range: wear_coefficient"),
    "zero-stiffness": ("contact_stiffness", np.zeros(16), "out of range: contact_stiffness"),
}


@pytest.mark.parametrize("case", OUT_OF_RANGE)
def test_a_checkpoint_out_of_range_is_refused_naming_it(saved, tmp_path, case):
    key, value, fragment = OUT_OF_RANGE[case]
    message = resumed(saved, tmp_path, lambda data: data.__setitem__(key, np.array(value)))
    assert message is not None and fragment in message, message
