"""Files from outside, or damaged on disk: every case is one line naming the field, status 2, no traceback, no crash.

Part files (``.vol``, ``.msh``, ``.step`` cut short, empty, random bytes) are read in a child process
first, so a file that crashes Netgen (a ``.vol`` cut short: SIGSEGV) is a message naming ``geometry.file``,
also for a study's case beside a valid one.  A resume checks its ``checkpoint.npz`` (readable, every key),
its ``mesh.vol`` (there, with the SHA-256 the checkpoint recorded, and the checkpoint's contact points) and its rows
(whole rows, as many as counted, their CRC-32) before it trusts them; a saved result's ``result.npz`` holds every
key its writer writes.
"""
import json
import re
import shutil

import numpy as np
import pandas as pd
import pytest
from conftest import PAPER, ROOT
from gmsh_files import write_msh
from test_cli import assert_one_line_error, ngwear

import ngwear as ng
from ngwear.results.checkpoint import CHECKPOINT

pytestmark = pytest.mark.hostile

SMALL = ["mesh.maxh=0.2", "time.steps=40"]
LONGER = ["--set", "time.T=2", "time.steps=80"]


def strip_msh(path, nx=15, ny=5, lx=3.0, ly=1.0):
    """A Gmsh 2 mesh of [0, lx] × [0, ly]: triangles of region body, edges contact (y = 0), left, right, top."""
    node = lambda i, j: 1 + i + j * (nx + 1)  # noqa: E731
    points = [(lx * i / nx, ly * j / ny, 0) for j in range(ny + 1) for i in range(nx + 1)]
    edges = [(1, node(i, 0), node(i + 1, 0)) for i in range(nx)] + [(4, node(i, ny), node(i + 1, ny)) for i in range(nx)]
    edges += [(2, node(0, j), node(0, j + 1)) for j in range(ny)] + [(3, node(nx, j), node(nx, j + 1)) for j in range(ny)]
    cells = [(node(i, j), node(i + 1, j), node(i + 1, j + 1)) for i in range(nx) for j in range(ny)]
    cells += [(node(i, j), node(i + 1, j + 1), node(i, j + 1)) for i in range(nx) for j in range(ny)]
    elements = [(1, tag, (a, b)) for tag, a, b in edges] + [(2, 5, cell) for cell in cells]
    names = [(1, 1, "contact"), (1, 2, "left"), (1, 3, "right"), (1, 4, "top"), (2, 5, "body")]
    return write_msh(path, names, points, elements)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """A finished run (its folder resumes), another run on another mesh, and the part files of both kinds."""
    tmp = tmp_path_factory.mktemp("runs")
    for name, maxh in (("base", 0.2), ("other", 0.25)):
        done = ngwear("run", PAPER, "--out", tmp / name, "--set", f"mesh.maxh={maxh}", SMALL[1], "--quiet",
                      "--no-pictures", cwd=tmp)
        assert done.returncode == 0, done.stderr
    return tmp


def part(tmp_path, source, corruption):
    """``source`` cut to a third, emptied or replaced by random bytes, under the same suffix."""
    data = source.read_bytes()
    damaged = {"cut": data[:len(data) // 3], "empty": b"",
               "random": np.random.default_rng(1).bytes(4096)}[corruption]
    path = tmp_path / f"part{source.suffix}"
    path.write_bytes(damaged)
    return path


def part_scene(tmp_path, path):
    if path.suffix == ".step":
        text = (f'name = "part"\n[geometry]\nkind = "step"\nfile = "{path.name}"\ndirichlet = []\n'
                '[contact]\ndirection = [0.0, 0.0, -1.0]\n[loads]\nplate = { boundary = "back", force = [0, 0, -1.0] }\n')
    else:
        text = f'name = "part"\n[geometry]\nkind = "mesh"\nfile = "{path.name}"\ndirichlet = ["left"]\n'
    (tmp_path / "part.toml").write_text(text)
    return tmp_path / "part.toml"


@pytest.mark.parametrize("corruption", ["cut", "empty", "random"])
@pytest.mark.parametrize("kind", [".vol", ".msh", ".step"])
def test_a_damaged_part_file_is_one_line_naming_geometry_file(runs, tmp_path, kind, corruption):
    source = {".vol": lambda: runs / "base" / "mesh.vol", ".msh": lambda: strip_msh(tmp_path / "strip.msh"),
              ".step": lambda: ROOT / "geometries" / "cad_pad.step"}[kind]()
    path = part(tmp_path, source, corruption)
    proc = ngwear("run", part_scene(tmp_path, path), "--quiet", "--no-pictures", cwd=tmp_path)
    assert_one_line_error(proc, "geometry.file")
    assert path.name in proc.stderr and not (tmp_path / "out").exists()


def test_an_intact_gmsh_part_runs(tmp_path):
    """The .msh the damaged cases start from is a part that runs: its strip has the named contact edge."""
    scene = ng.load_scene(part_scene(tmp_path, strip_msh(tmp_path / "part.msh"))).replace(
        **{"time.steps": 4})
    result = ng.simulate(scene, progress=False)
    assert result.completed and result.weights.sum() == pytest.approx(3.0)   # Γ_C is the edge y = 0 of length 3
    assert scene.geometry.regions == ("body",)          # the edges' names are boundaries (Netgen lists them too)


def without(path, key):
    data = dict(np.load(path))
    data.pop(key)
    np.savez(path, **data)


def changed(path, key, change):
    """``key`` of the checkpoint at ``path`` replaced by ``change(value)``."""
    data = dict(np.load(path))
    data[key] = change(data[key])
    np.savez(path, **data)


def nan_at_first(value):
    value = np.array(value, dtype=float)
    value.flat[0] = np.nan
    return value


def edited(scene):
    data = json.loads(str(scene))
    data["contact"]["friction"] = 0.9
    return np.array(json.dumps(data))


def cut(path, size):
    with open(path, "r+b") as file:
        file.truncate(size)


def flip(path, offset):
    data = bytearray(path.read_bytes())
    data[offset] ^= 1
    path.write_bytes(bytes(data))


def steps(folder):
    return next(folder.glob("steps-*"))


RESUME_CASES = {
    "checkpoint-cut": (lambda c, o: cut(c / CHECKPOINT, 1000), "checkpoint.npz is damaged (BadZipFile"),
    "checkpoint-empty": (lambda c, o: cut(c / CHECKPOINT, 0), "checkpoint.npz is damaged (EOFError"),
    "checkpoint-random": (lambda c, o: (c / CHECKPOINT).write_bytes(np.random.default_rng(2).bytes(3000)),
                          "checkpoint.npz is damaged"),
    "checkpoint-no-x": (lambda c, o: without(c / CHECKPOINT, "x"), "not a checkpoint of ngwear (no x)"),
    "checkpoint-no-scene": (lambda c, o: without(c / CHECKPOINT, "scene"), "(no scene)"),
    "mesh-missing": (lambda c, o: (c / "mesh.vol").unlink(), "holds no mesh.vol"),
    "mesh-foreign": (lambda c, o: shutil.copy(o / "mesh.vol", c / "mesh.vol"), "SHA-256 differs"),
    "mesh-cut": (lambda c, o: cut(c / "mesh.vol", 3000), "SHA-256 differs"),
    "checkpoint-no-mesh-sha256": (lambda c, o: without(c / CHECKPOINT, "mesh_sha256"), "(no mesh_sha256)"),
    "checkpoint-no-jumped": (lambda c, o: without(c / CHECKPOINT, "jumped"), "(no jumped)"),
    "checkpoint-no-rows": (lambda c, o: without(c / CHECKPOINT, "rows"), "(no rows)"),
    "rows-cut": (lambda c, o: cut(steps(c) / "wear.f64", 200), "wear.f64 holds 1.5625 rows"),
    "rows-changed": (lambda c, o: flip(steps(c) / "pressure.f64", 808), "pressure.f64: its first 41 rows"),
    "rows-missing": (lambda c, o: (steps(c) / "reaction.f64").unlink(), "reaction.f64 is missing"),
    "steps-missing": (lambda c, o: shutil.rmtree(steps(c)), "is missing (it holds the steps"),
    "checkpoint-nan-x": (lambda c, o: changed(c / CHECKPOINT, "x", nan_at_first), "is damaged (not finite: x)"),
    "checkpoint-nan-lam": (lambda c, o: changed(c / CHECKPOINT, "lam", nan_at_first), "(not finite: lam)"),
    "checkpoint-short-x": (lambda c, o: changed(c / CHECKPOINT, "x", lambda x: x[:-1]),
                           "(x has the shape (15,), its run's is (16,))"),
    "checkpoint-edited-scene": (lambda c, o: changed(c / CHECKPOINT, "scene", edited),
                                "is damaged (its scene is not the one its run recorded"),
}


@pytest.mark.parametrize("case", RESUME_CASES)
def test_a_damaged_resume_folder_is_one_line_naming_the_file(runs, tmp_path, case):
    damage, fragment = RESUME_CASES[case]
    folder = tmp_path / "run"
    shutil.copytree(runs / "base", folder)
    damage(folder, runs / "other")
    proc = ngwear("run", "--resume", folder, *LONGER, "--quiet", "--no-pictures", cwd=tmp_path)
    assert_one_line_error(proc, "--resume")
    assert fragment in proc.stderr, proc.stderr


def test_the_intact_folder_resumes(runs, tmp_path):
    """The folder the damaged cases start from goes on, to the numbers of the longer run."""
    folder = tmp_path / "run"
    shutil.copytree(runs / "base", folder)
    proc = ngwear("run", "--resume", folder, *LONGER, "--quiet", "--no-pictures", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    longer = ng.simulate(ng.load_scene(PAPER).replace(**{"mesh.maxh": 0.2, "time.T": 2.0, "time.steps": 80}),
                         progress=False)
    assert np.array_equal(np.load(folder / "result.npz")["wear"], longer.wear)


def test_a_saved_result_with_a_foreign_mesh_is_refused(runs, tmp_path):
    folder = tmp_path / "run"
    shutil.copytree(runs / "base", folder)
    assert ng.load_result(folder).steps == 40
    shutil.copy(runs / "other" / "mesh.vol", folder / "mesh.vol")
    with pytest.raises(ng.SceneError, match=r"^directory: .*mesh\.vol is not the mesh its results were computed on"):
        ng.load_result(folder)


@pytest.mark.parametrize("damage", ["cut", "empty"])
def test_a_damaged_result_npz_is_one_line_naming_it(runs, tmp_path, damage):
    folder = tmp_path / "run"
    shutil.copytree(runs / "base", folder)
    cut(folder / "result.npz", (folder / "result.npz").stat().st_size // 2 if damage == "cut" else 0)
    with pytest.raises(ng.SceneError, match=rf"^directory: {re.escape(str(folder / 'result.npz'))} is damaged "
                                            r"\((BadZipFile|EOFError): [^\n]*\)$"):
        ng.load_result(folder)


@pytest.mark.parametrize("key", ["jumped", "solve_time", "thickness", "newton_cutbacks", "wear", "mesh_sha256"])
def test_a_saved_result_missing_a_key_is_refused_in_one_line_naming_it(runs, tmp_path, key):
    """A result.npz without a key that Result.save writes is not read: one line naming the file and the key."""
    folder = tmp_path / "run"
    shutil.copytree(runs / "base", folder)
    without(folder / "result.npz", key)
    with pytest.raises(ng.SceneError) as err:
        ng.load_result(folder)
    assert str(err.value) == f"directory: {folder / 'result.npz'} is damaged or not a result of ngwear (no {key})"


def test_a_study_with_a_crashing_part_keeps_its_valid_case(runs, tmp_path):
    """A case whose .vol crashes Netgen is rejected naming geometry.file; the client lives on, its neighbour runs."""
    good = shutil.copy(runs / "base" / "mesh.vol", tmp_path / "good.vol")
    bad = part(tmp_path, runs / "base" / "mesh.vol", "cut")
    study = {"name": "parts", "scene": {"name": "part", "time": {"steps": 4},
                                        "geometry": {"kind": "mesh", "file": str(good), "dirichlet": ["left"]}},
             "grid": {"geometry.file": [str(good), str(bad)]}}
    table = ng.sweep(study, out=tmp_path / "out", workers=1, progress=False).set_index("geometry.file")
    assert table.loc[str(good), "status"] == "completed" and pd.isna(table.loc[str(good), "error"])
    assert table.loc[str(bad), "status"] == "rejected"
    assert table.loc[str(bad), "error"].startswith(f"geometry.file: Netgen crashed reading {bad.name}")
    assert table.attrs["summary"]["crashed"] == 0


@pytest.mark.parametrize("args, field", [
    (["sweep", ROOT / "geometries" / "studies" / "friction_wear.toml", "--scheduler", "not a url"], "scheduler"),
    (["sweep", ROOT / "geometries" / "studies" / "friction_wear.toml", "--scheduler", "foo://host:1"], "scheduler"),
    (["explore", PAPER, "--port", "99999"], "--port"),
    (["explore", PAPER, "--port", "0"], "--port"),
], ids=["scheduler-not-a-url", "scheduler-scheme", "port-99999", "port-0"])
def test_a_malformed_address_is_one_line(tmp_path, args, field):
    assert_one_line_error(ngwear(*args, cwd=tmp_path), field)


@pytest.fixture(scope="module")
def moved(tmp_path_factory):
    """The folder of a "surface" run stopped after two geometry updates (its checkpoint holds the moved body)."""
    from test_life import taper_scene

    folder = tmp_path_factory.mktemp("moved")
    part = ng.simulate(taper_scene(T=1.5, steps=15).replace(**{"output.every": 0.5}), progress=False,
                       checkpoint=folder)
    assert part.geometry_updates >= 1
    return folder


@pytest.mark.parametrize("key, damage, fragment", [
    ("surface_wear", nan_at_first, "is damaged (not finite: surface_wear)"),
    ("surface_coordinates", nan_at_first, "is damaged (not finite: surface_coordinates)"),
    ("surface_reference", lambda x: x[:-1], "(surface_reference has the shape"),
    ("surface_wear", None, "is damaged (it moved its worn surface 2 times but holds no surface_wear)"),
    ("body_coordinates", nan_at_first, "is damaged (not finite: body_coordinates)"),
])
def test_a_damaged_checkpoint_of_a_moved_body_is_one_line_naming_it(moved, tmp_path, key, damage, fragment):
    folder = tmp_path / "run"
    shutil.copytree(moved, folder)
    if damage is None:
        without(folder / CHECKPOINT, key)
    else:
        changed(folder / CHECKPOINT, key, damage)
    with pytest.raises(ng.SceneError) as err:
        ng.simulate(None, progress=False, resume=folder)
    message = str(err.value)
    assert message.startswith(f"resume: {folder / CHECKPOINT} ") and fragment in message and "\n" not in message
