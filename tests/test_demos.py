"""The gallery's demos (docs/demos) run, and each one's number agrees with a closed form or an independent run.

The demos run once, in the docs build (the ``site`` fixture: Sphinx-Gallery executes each one, then its check in
tests/demo_checks.py on its variables); here the check's recorded numbers are asserted.  The checks compare one
number with a value computed from the theory or by another run, never with a stored output.
"""
import pytest
from conftest import ROOT

pytest.importorskip("sphinx", reason="the demos run in the docs build: it needs the docs extra (pip install 'ngwear[docs]')")
from demo_checks import CHECKS  # noqa: E402

DEMOS = ROOT / "docs" / "demos"
MARKS = {"07_explorer": [pytest.mark.browser]}


def test_every_demo_has_a_check():
    assert sorted(CHECKS) == sorted(p.stem for p in DEMOS.glob("[0-9][0-9]_*.py"))


@pytest.mark.slow
@pytest.mark.xdist_group("site")
@pytest.mark.parametrize("name", [pytest.param(n, marks=MARKS.get(n, [])) for n in CHECKS])
def test_demo(name, site, worker_id, request):
    if request.config.getoption("loadgroup", default=False):   # else the other worker waited for the build
        assert site[1]["worker"] == worker_id, "--dist loadgroup did not keep the site's tests on its worker"
    check = site[1]["checks"].get(name)
    assert check is not None, f"{name} did not run in the docs build"
    assert "error" not in check, check.get("error")
    assert check["value"] == pytest.approx(check["expected"], **check["tolerance"]), check["doc"]
    assert check["pictures"] > 0, "the demo draws its pictures"
