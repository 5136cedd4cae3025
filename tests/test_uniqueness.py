"""(H_S) in the run's energy norm: c_K² = λ_max(W^½ P K⁻¹ Pᵀ W^½) from the run's factorisation, and its report.

c_K² is checked against a dense eigenvalue computed independently, on the dense and the matrix-free contact
solves; against the paper's form (‖v‖_K² ≥ m_F ‖ε(v)‖² gives c_K² ≤ c₀²/m_F with c₀ for the same trace); and
``ngwear run`` reports it as a stage of the run, skips it with ``--no-check`` and after an interrupt, and says in
one line when Lanczos does not converge.
"""
import re
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from conftest import PAPER
from test_cli import ngwear as run_cli

import ngwear
from ngwear.cli.run import uniqueness as run_check
from ngwear.numerics.discrete import Discretization
from ngwear.studies import theory
from ngwear.studies.theory import energy_trace, uniqueness

STRAIN_ONLY = {"lame_lambda": 0.0, "lame_mu": 0.5}     # F(ε) = ε: K is the form (ε(u), ε(v)), m_F = 1


@pytest.fixture(scope="module")
def strip(paper_scene):
    return paper_scene.replace(**{"mesh.maxh": 0.3, "time.steps": 20})


def dense_trace(disc) -> float:
    """λ_max(W^½ P K⁻¹ Pᵀ W^½) by numpy on the free DOFs."""
    K = disc.elastic.stiffness.toarray()[np.ix_(disc.body.free, disc.body.free)]
    P = disc.points.P.toarray()[:, disc.body.free]
    root = np.sqrt(np.repeat(disc.points.weights, disc.scene.dim))
    return float(np.linalg.eigvalsh(root[:, None] * (P @ np.linalg.solve(K, P.T)) * root[None, :]).max())


@pytest.mark.parametrize("contact_solve", ["dense", "krylov"])
def test_trace_in_the_energy_norm_is_the_largest_eigenvalue(strip, contact_solve):
    disc = Discretization(strip, contact_solve=contact_solve)
    assert disc.matrix_free == (contact_solve == "krylov")
    assert energy_trace(disc) == pytest.approx(dense_trace(disc), rel=1e-8)


def test_the_papers_condition_implies_the_energy_one(strip):
    """‖v‖_K² = ∫ 2η|ε|² + λ (tr ε)² ≥ 2η ‖ε(v)‖²: c_K² ≤ c₀²/m_F, c₀² the same trace's constant for F(ε) = ε."""
    disc = Discretization(strip)
    c_K2 = energy_trace(disc)
    c02 = energy_trace(Discretization(strip.replace(material=STRAIN_ONLY)))
    assert c_K2 <= c02 / 2.0 and c_K2 > 0.3 * c02 / 2.0           # λ = η = 1: m_F = 2
    check = uniqueness(disc)
    assert check.product == pytest.approx(c_K2 * 10.0 * 1.0) and not check.holds
    assert uniqueness(disc.with_scene(strip.replace(**{"contact.friction": 0.5 / (10 * c_K2)}))).holds


def test_the_run_reports_it_as_a_stage_and_no_check_skips_it(tmp_path):
    args = ["--set", "mesh.maxh=0.3", "time.steps=20", "--no-pictures"]
    checked = run_cli("run", PAPER, *args, "--out", tmp_path / "a", cwd=tmp_path)
    assert checked.returncode == 0, checked.stderr
    assert "(H_S) c_K² L_p μ = " in checked.stdout and "uniqueness (H_S)" in checked.stderr   # the progress bar
    lines = checked.stdout.splitlines()
    assert lines.index(next(x for x in lines if "(H_S)" in x)) < lines.index(next(x for x in lines
                                                                                   if x.startswith("written")))
    skipped = run_cli("run", PAPER, *args, "--no-check", "--quiet", "--out", tmp_path / "b", cwd=tmp_path)
    assert skipped.returncode == 0 and "(H_S)" not in skipped.stdout


def test_never_after_an_interrupt(strip):
    import threading
    stop = threading.Event()
    result = ngwear.simulate(strip, progress=False)
    label, text = run_check(result, stop, progress=False)       # (H_S) fails here: information all the same
    assert label == "uniqueness" and text.startswith("(H_S) c_K² L_p μ") and "≥ 1" in text
    assert text.endswith("does not cover this scene (a sufficient condition, not a necessary one); the run's own "
                         "checks hold")
    stop.set()
    assert run_check(result, stop, progress=False) is None
    result.status = "interrupted"
    assert run_check(result, threading.Event(), progress=False) is None


def test_a_signal_during_the_check_aborts_it(strip):
    calls = []

    def interrupted():
        calls.append(1)
        return len(calls) > 2                                   # the third product: a signal has come
    with pytest.raises(KeyboardInterrupt):
        uniqueness(Discretization(strip), interrupted)


def test_lanczos_failing_is_one_line(strip, monkeypatch):
    def fails(*args, **kwargs):
        raise spla.ArpackNoConvergence("No convergence (21 iterations, 0/1 eigenvectors converged)", np.zeros(0),
                                       np.zeros((0, 0)))                 # as scipy raises it
    monkeypatch.setattr(theory.spla, "eigsh", fails)
    import threading
    label, text = run_check(ngwear.simulate(strip, progress=False), threading.Event(), progress=False)
    assert label == "uniqueness" and "\n" not in text
    assert text.startswith("(H_S) not evaluated: Lanczos did not converge (ARPACK error -1: No convergence")


def test_the_cli_survives_lanczos_failing(tmp_path):
    code = ("import sys, scipy.sparse.linalg as spla\n"
            "from ngwear.studies import theory\n"
            "def fails(*a, **k): raise spla.ArpackNoConvergence('No convergence', [], [])\n"
            "theory.spla.eigsh = fails\n"
            "from ngwear.cli import main\nsys.exit(main())\n")
    proc = subprocess.run([sys.executable, "-c", code, "run", str(PAPER), "--set", "mesh.maxh=0.3", "time.steps=20",
                           "--quiet", "--no-pictures", "--out", str(tmp_path / "out")], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
    assert re.search(r"^uniqueness +\(H_S\) not evaluated: Lanczos did not converge \(ARPACK error -1: No convergence\)$",
                     proc.stdout, re.M), proc.stdout
