"""Notebooks are thin, stripped in git, and run in a real Jupyter kernel at a coarse resolution.

Each notebook is executed by nbclient in a copy of the folder layout (``notebooks/`` beside
``geometries/``) under a temporary directory, with ``NGWEAR_NOTEBOOK_QUICK=1`` selecting the coarse,
short run and a kernel spec pointing at this Python (``JUPYTER_PATH``), whatever kernels the user has.  Running a
notebook takes a kernel and a run: those tests are ``slow``.
"""
import nbformat
import pytest
from conftest import ROOT
from ipykernel.kernelspec import write_kernel_spec
from nbclient import NotebookClient

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
KERNEL = "ngwear-test"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_is_stripped(path):
    cells = nbformat.read(path, as_version=4).cells
    code = [c for c in cells if c.cell_type == "code"]
    assert code and all(not c.outputs and c.execution_count is None for c in code), "outputs are stripped"


def execute(path, tmp_path, monkeypatch):
    """Run the notebook in ``tmp_path/notebooks``; returns the executed notebook."""
    write_kernel_spec(tmp_path / "jupyter" / "kernels" / KERNEL)
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    monkeypatch.setenv("NGWEAR_NOTEBOOK_QUICK", "1")
    work = tmp_path / "notebooks"
    work.mkdir()
    (tmp_path / "geometries").symlink_to(ROOT / "geometries")
    notebook = nbformat.read(path, as_version=4)
    client = NotebookClient(notebook, timeout=120, kernel_name=KERNEL,
                            resources={"metadata": {"path": str(work)}})
    client.execute()
    return notebook


def outputs(notebook, kind):
    return [o for c in notebook.cells if c.cell_type == "code" for o in c.outputs
            if kind in o.get("data", {})]


@pytest.mark.slow
def test_paper_reproduction_runs(tmp_path, monkeypatch):
    notebook = execute(ROOT / "notebooks" / "paper_reproduction.ipynb", tmp_path, monkeypatch)
    out = tmp_path / "notebooks" / "out"
    assert len(list(out.glob("fig*_step*.png"))) == 4 and (out / "run.gif").stat().st_size > 10_000
    assert (out / "wear.png").stat().st_size > 10_000
    assert len(outputs(notebook, "image/png")) + len(outputs(notebook, "image/gif")) >= 7
    assert "implicit  k = 0.1" in notebook.cells[-1].outputs[-1]["text"]


@pytest.mark.slow
def test_explorer_notebook_runs(tmp_path, monkeypatch):
    notebook = execute(ROOT / "notebooks" / "explore.ipynb", tmp_path, monkeypatch)
    assert len(outputs(notebook, "application/vnd.jupyter.widget-view+json")) == 1
    assert len(outputs(notebook, "image/png")) == 2
    printed = "".join(o.get("text", "") for c in notebook.cells for o in c.get("outputs", []))
    assert "{'wear': 0.0}: max wear at t = 0.50: 0.0000" in printed and "new factorisation: False" in printed
    assert "A/B: B differs from A in speed 1 → 2" in printed


@pytest.mark.slow
def test_convergence_notebook_runs(tmp_path, monkeypatch):
    notebook = execute(ROOT / "notebooks" / "convergence.ipynb", tmp_path, monkeypatch)
    out = tmp_path / "notebooks" / "out"
    assert (out / "convergence_h.png").stat().st_size > 10_000 and (out / "convergence_k.png").is_file()
    printed = "".join(o.get("text", "") for c in notebook.cells for o in c.get("outputs", []))
    assert "(H_S)" in printed and "does not cover this scene" in printed
