"""Code style (numpy docstrings, imports, line length) is enforced by ruff, as configured in pyproject.toml."""
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT


def test_ruff_is_clean():
    ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    done = subprocess.run([ruff, "check", "ngwear", "tests", "benchmarks", "scripts", "notebooks", "docs"], cwd=ROOT,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.parametrize("module, not_imported", [
    ("ngwear.views.picture_data", ("pyvista", "ipywidgets")),   # the picture's arrays, as dolfinx.plot gives them
    ("ngwear.views.widget", ("ngwear.views.explore",)),          # explore imports widget, not the other way
])
def test_imports_point_one_way(module, not_imported):
    code = f"import sys, {module}; print([m for m in {not_imported!r} if m in sys.modules])"
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.strip() == "[]", done.stdout + done.stderr
