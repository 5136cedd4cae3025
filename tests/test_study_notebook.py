"""notebooks/study.ipynb runs a small study on a local Dask cluster in a real kernel (quick mode)."""
import pandas as pd
import pytest
from conftest import ROOT
from test_notebooks import execute, outputs


@pytest.mark.slow
def test_study_notebook_runs(tmp_path, monkeypatch):
    notebook = execute(ROOT / "notebooks" / "study.ipynb", tmp_path, monkeypatch)
    out = tmp_path / "notebooks" / "out" / "study"
    table = pd.read_parquet(out / "results.parquet")
    assert len(table) == 16 and (table.status == "completed").all() and table.worker.nunique() == 2
    assert len(outputs(notebook, "image/png")) == 2 and len(outputs(notebook, "text/html")) == 1
    printed = "".join(o.get("text", "") for c in notebook.cells for o in c.get("outputs", []))
    assert "16 cases (16 completed); 0 finished earlier, 16 run on 2 workers" in printed
    assert "16 cases (16 completed); 16 finished earlier, 0 run on 0 workers" in printed
