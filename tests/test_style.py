"""Code style (numpy docstrings, imports, line length) is enforced by ruff, as configured in pyproject.toml."""
import shutil
import subprocess
import sys
from pathlib import Path

from conftest import ROOT


def test_ruff_is_clean():
    ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    done = subprocess.run([ruff, "check", "ngwear", "tests", "benchmarks", "scripts", "notebooks", "docs"], cwd=ROOT,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
