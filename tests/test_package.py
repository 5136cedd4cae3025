"""ngwear as a user gets it: the wheel and the sdist, the version, the shipped scenes, the documented public API.

The wheel test installs the built wheel with pip into a new virtual environment and runs its ``ngwear`` from a
folder outside the repository.  Installing ngwear's dependencies there (NGSolve, VTK, MKL, Dask, …: about 1 GB)
would take minutes, so the wheel goes in with ``--no-deps`` and, once it is installed, a ``.pth`` file lets the
new environment also see this interpreter's site-packages for the dependencies.  ``pip check`` then checks that
they satisfy what the wheel's metadata requires, and the test asserts that ``ngwear`` is imported from the new
environment (its own site-packages come first), not from the repository or this environment.  The ``mkl`` wheel
installs its shared libraries into ``<prefix>/lib`` (where ngwear's PARDISO binding looks), not into
site-packages: they are linked into the new environment's ``lib`` as ``pip install mkl`` would have put them.
"""
import inspect
import json
import os
import re
import subprocess
import sys
import sysconfig
import tarfile
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.model import examples
from ngwear.numerics.points import initial_distance


def run(*args, cwd, env=None, timeout=300) -> subprocess.CompletedProcess:
    return subprocess.run([*map(str, args)], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)


def test_version_is_single_sourced():
    """The pyproject takes the version from ngwear.version (ngwear.__version__); --version and python -m ngwear print it."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "version" not in project["project"] and "version" in project["project"]["dynamic"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "ngwear.version.__version__"}
    assert re.fullmatch(r"\d+\.\d+\.\d+([ab]|rc|\.dev)?\d*", ngwear.__version__)
    assert project["project"]["license"] == "MIT" and project["project"]["license-files"] == ["LICENSE"]
    assert "MIT License" in (ROOT / "LICENSE").read_text() and "ngwear developers" in (ROOT / "LICENSE").read_text()
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for command in ([sys.executable, "-m", "ngwear", "--version"], [sys.executable, "-m", "ngwear.cli", "--version"]):
        done = run(*command, cwd=ROOT.parent, env=env)
        assert done.returncode == 0 and done.stdout == f"ngwear {ngwear.__version__}\n", done


def test_public_api_has_numpy_docstrings():
    """Every export has a docstring; functions document each parameter, what they return and what they raise."""
    for name in ngwear.__all__:
        obj = getattr(ngwear, name)
        doc = inspect.getdoc(obj)
        assert doc and len(doc.splitlines()[0]) > 10, name
        if inspect.isfunction(obj):
            sections = re.findall(r"^(\w+)\n-+$", doc, re.MULTILINE)
            assert "Parameters" in sections and "Returns" in sections, (name, sections)
            params = [p for p in inspect.signature(obj).parameters if p not in ("self", "kw", "kwargs")]
            documented = re.findall(r"^(\w+)(?: : |$)", doc.split("Parameters\n----------\n")[1], re.MULTILINE)
            assert set(params) <= set(documented), (name, set(params) - set(documented))
        elif inspect.isclass(obj) and not issubclass(obj, Exception):
            assert re.search(r"^(Parameters|Attributes)\n-+$", doc, re.MULTILINE), name


@pytest.mark.slow
def test_wheel_installs_and_runs_a_shipped_scene(tmp_path):
    """`python -m build` → sdist and wheel; the wheel in a new venv runs `ngwear run paper_strip` outside the repo."""
    dist, version = tmp_path / "dist", ngwear.__version__
    built = run(sys.executable, "-m", "build", "--outdir", dist, ROOT, cwd=tmp_path)   # the wheel from the sdist
    assert built.returncode == 0, built.stdout[-2000:] + built.stderr[-3000:]
    (wheel,), (sdist,) = dist.glob(f"ngwear-{version}-py3-none-any.whl"), dist.glob(f"ngwear-{version}.tar.gz")
    shipped = [f"ngwear/examples/{name.as_posix()}" for name in examples.shipped_files()]
    assert {"ngwear/examples/paper_strip.toml", "ngwear/examples/cad_pad.step"} <= set(shipped)
    with tarfile.open(sdist) as tar:
        assert {f"ngwear-{version}/{name}" for name in [*shipped, "LICENSE"]} <= set(tar.getnames())
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        metadata = archive.read(f"ngwear-{version}.dist-info/METADATA").decode()
    assert set(shipped) <= names and f"ngwear-{version}.dist-info/licenses/LICENSE" in names
    assert f"Version: {version}\n" in metadata and "License-Expression: MIT" in metadata

    venv, env = tmp_path / "venv", {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    assert run(sys.executable, "-m", "venv", "--without-pip", venv, cwd=tmp_path).returncode == 0
    python = venv / "bin" / "python"
    installed = run(sys.executable, "-m", "pip", "--python", python, "install", "--no-deps", "--no-index", wheel,
                    cwd=tmp_path, env=env)
    assert installed.returncode == 0 and "Successfully installed" in installed.stdout, installed
    site = Path(run(python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])",
                    cwd=tmp_path).stdout.strip())
    ours = {sysconfig.get_paths()[key] for key in ("purelib", "platlib")}
    (site / "zz_ngwear_dependencies.pth").write_text("\n".join(sorted(ours)) + "\n")
    for library in (Path(sys.prefix) / "lib").glob("lib*.so*"):     # MKL's, which its wheel puts in <prefix>/lib
        (venv / "lib" / library.name).symlink_to(library)
    checked = run(sys.executable, "-m", "pip", "--python", python, "check", cwd=tmp_path, env=env)
    assert checked.returncode == 0, checked.stdout

    user = tmp_path / "user"                 # a user's folder, outside the repository
    user.mkdir()
    where = run(python, "-c", "import ngwear; print(ngwear.__file__)", cwd=user, env=env)
    assert Path(where.stdout.strip()).is_relative_to(site), where
    assert run(venv / "bin" / "ngwear", "--version", cwd=user, env=env).stdout == f"ngwear {version}\n"
    listed = run(venv / "bin" / "ngwear", "examples", cwd=user, env=env)
    assert [line.split()[0] for line in listed.stdout.splitlines()] == examples.names()

    done = run(venv / "bin" / "ngwear", "run", "paper_strip", "--set", "time.steps=10", "--out", "out", cwd=user,
               env=env)
    assert done.returncode == 0, done.stderr
    assert "\r" not in done.stderr and "Traceback" not in done.stderr
    out = user / "out"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["steps"] == 10 and "units" not in summary
    g = ngwear.load_scene("paper_strip").contact.gap
    with np.load(out / "result.npz") as data:
        wear, s, points = data["wear"], data["normal_displacement"], data["contact_points"]
        assert wear.shape == (11, len(points)) and np.all(wear >= 0)
        assert np.all(np.diff(wear, axis=0) >= -1e-12 * g)            # wear never decreases
        assert np.all(s - initial_distance(points, (0.0, -1.0)) <= g * (1 + 1e-9))   # u_ν − d₀ ≤ g
        assert summary["max_wear"] == pytest.approx(wear.max(), rel=1e-12) and wear.max() > 0
    assert {"fields.pvd", "mesh.vol", "history.png", "wear.png"} <= {p.name for p in out.iterdir()}
