"""Stability stress matrix: every extreme scene converges with its invariants or stops clearly.

One test per scene of :data:`ngwear.studies.stress.CATALOGUE`.  A scene must end (a) ``converged`` with
every invariant held at every step, (b) ``stopped`` with a message naming the step and a remedy
(the kept steps still satisfying the invariants), or be ``rejected`` up front with a SceneError
naming the field; where the outcome is known it is pinned (``expect``, with the reason in the
catalogue) and the scene's physics checks must pass.  Scenes exposing a known ngwear bug are
strict xfails: they assert the correct outcome, so fixing the bug turns them into failures that
ask for the ``bug`` note to be removed from the catalogue.
"""
import math

import numpy as np
import pytest

from ngwear import SceneError
from ngwear.runs.checks import TOL, allowances, invariants, k_alpha_slope
from ngwear.studies import stress
from ngwear.studies.stress import CATALOGUE


def _param(spec):
    marks = [pytest.mark.xfail(reason=spec.bug, strict=True)] if spec.bug else []
    return pytest.param(spec, id=spec.name, marks=marks)


@pytest.mark.parametrize("spec", [_param(s) for s in CATALOGUE])
def test_scene(spec):
    row = stress.run_scene(spec)
    where = f"{spec.name} ({row.params}): {row.outcome}: {row.message}"
    assert row.outcome != "crashed", row.traceback or where
    assert row.acceptable, where
    if row.outcome in ("converged", "stopped"):
        allowed = allowances(spec.scene())
        assert all(v <= allowed[k] for k, v in row.violations.items()), f"{where}; worst invariant {row.worst}"
        assert row.violations["finite"] == 0, where
    if row.outcome == "stopped":
        assert not stress.clear_stop_message(row.message), where
        assert any(why in row.message for why in ("Newton did not converge", "non-finite",
                                                  "beyond the small-strain model")), where
    if spec.expect is not None:
        assert row.outcome == spec.expect, f"{where}; expected {spec.expect}: {spec.reason}"
    assert not row.check_failures, f"{where}; {row.check_failures}"


def test_catalogue_covers_the_matrix():
    names = [s.name for s in CATALOGUE]
    assert len(names) >= 30 and len(set(names)) == len(names)
    scenes = {s.name: s.scene() for s in CATALOGUE if s.expect != "rejected"}
    for spec in CATALOGUE:
        if spec.expect == "rejected" and not {"rejected_names_steps", "rejected_names_friction"} & set(spec.checks):
            # the others need the mesh: its α, its contact points
            with pytest.raises(SceneError):
                spec.scene()
    values = lambda f: {f(sc) for sc in scenes.values()}  # noqa: E731
    assert {0.0, 0.5, 1.0, 5.0, 20.0} <= values(lambda sc: sc.contact.friction)
    assert {1.0, 1e-2, 1e-4, 1e-6} <= values(lambda sc: sc.contact.gap)
    assert {1e-2, 1e8} <= values(lambda sc: sc.contact.stiffness)
    assert {2.0, 3.0} <= {sc.contact.exponent for sc in scenes.values() if sc.contact.law == "power"}
    assert {"explicit", "implicit", "trapezoidal"} <= values(lambda sc: sc.wear.integrator)
    kal = {k_alpha_slope(sc) for sc in scenes.values() if not isinstance(sc.contact.wear, str) and sc.contact.wear > 0}
    assert min(kal) <= 0.01 and any(math.isclose(k, 100) for k in kal)
    assert 2 in values(lambda sc: sc.mesh.order) and 3 in values(lambda sc: sc.dim)
    assert any(sc.geometry.size == (10.0, 0.1) for sc in scenes.values())
    assert any(sc.mesh.maxh == 1.0 for sc in scenes.values())
    signs = lambda table: {np.sign(f) for _, f in table}  # noqa: E731
    assert any({-1, 1} <= signs(sc.loads.time_table) for sc in scenes.values())
    assert any({-1, 1} <= signs(sc.foundation.speed_table) for sc in scenes.values())
    for sc in scenes.values():  # small enough for the < 60 s budget
        assert sc.time.steps <= 40
        if sc.geometry.kind == "strip" and sc.geometry.size == (3.0, 1.0):
            assert sc.mesh.maxh >= 0.05


def test_catalogue_covers_regions_laws_and_fields():
    """Regions, laws and fields: a backing 1000× stiffer, β = 100η, a μ field up to 2 with a zone of 0, κ = 0 on half of Γ_C.

    And a field negative somewhere, refused.
    """
    from ngwear.model.materials import region_laws, young_along
    from ngwear.numerics.discrete import Discretization

    specs = {s.name: s for s in CATALOGUE}
    scenes = {name: spec.scene() for name, spec in specs.items() if spec.expect != "rejected"}
    stiffer = []
    for sc in scenes.values():
        if sc.geometry.backing:
            laws = region_laws(sc)
            stiffer.append(young_along(laws["backing"], sc.contact.direction) /
                           young_along(laws["body"], sc.contact.direction))
    assert any(math.isclose(ratio, 1000) for ratio in stiffer), stiffer
    assert any(sc.material.kind == "compaction" and math.isclose(sc.material.compaction_modulus, 100 * sc.material.lame[1])
               for sc in scenes.values())
    fields = {}
    for sc in scenes.values():
        if isinstance(sc.contact.friction, str) or isinstance(sc.contact.wear, str):
            coefficients = Discretization(sc).contact.coefficients
            fields[sc.name] = coefficients.friction, coefficients.wear
    assert any(mu.max() == 2 and (mu == 0).any() for mu, _ in fields.values())
    assert any(math.isclose((kappa == 0).mean(), 0.5, abs_tol=0.05) and kappa.max() > 0 for _, kappa in fields.values())
    negative = [s for s in CATALOGUE if s.expect == "rejected" and "rejected_names_friction" in s.checks]
    assert negative and isinstance(negative[0].scene().contact.friction, str)


def test_invariant_checker_is_not_vacuous():
    """Corrupting a good run is caught by the matching invariant."""
    spec = next(s for s in CATALOGUE if s.name == "mu_1_paper")
    r = stress.run_scene(spec, keep_result=True).result
    allowed = allowances(r.scene)
    assert all(v <= allowed[k] for k, v in invariants(r).items())
    g = r.scene.contact.gap

    def broken(name, change):
        saved = getattr(r, name).copy()
        change(getattr(r, name))
        try:
            return invariants(r)
        finally:
            getattr(r, name)[...] = saved

    assert broken("normal_displacement", lambda a: a.__setitem__((5, 3), r.d0[3] + 1.001 * g))["gap"] > allowed["gap"]
    assert broken("wear", lambda a: a.__setitem__((5, 3), -1e-6))["wear_sign"] > TOL
    assert broken("wear", lambda a: a.__setitem__((5, 3), a[6, 3] + 1e-6))["wear_monotone"] > TOL
    assert broken("reaction", lambda a: a.__setitem__((5, 3), -1e-3))["reaction_sign"] > allowed["reaction_sign"]
    active = np.argwhere(r.reaction > 0)[0]
    assert broken("normal_displacement", lambda a: a.__setitem__(tuple(active), a[tuple(active)] - 0.01))[
        "contact"] > allowed["contact"]
    assert broken("pressure", lambda a: a.__setitem__((5, 3), a[5, 3] + 1e-3))["pressure_law"] > TOL
    assert broken("wear", lambda a: a.__setitem__((-1, 3), a[-1, 3] + 1e-6))["archard"] > TOL
    reached = np.maximum(r.normal_displacement - r.d0, 0).max(axis=0)
    assert broken("wear", lambda a: a.__setitem__((-1, 3), reached[3] + 1e-6))["wear_le_penetration"] > TOL
    assert broken("pressure", lambda a: a.__setitem__((5, 3), np.nan))["finite"] == math.inf


def test_report_and_main(tmp_path):
    out = tmp_path / "stress.md"
    only = ["mu_0", "full_solver_implicit_wear", "liftoff", "L_1e8_explicit_wear"]
    assert stress.main(["--only", *only, "--out", str(out)]) == 0
    text = out.read_text()
    assert "Regenerate" in text[:300] and "python -m ngwear.studies.stress" in text[:400]
    rows = [line for line in text.splitlines() if line.startswith("| ") and not line.startswith("| scene")]
    assert [row.split(" | ")[0][2:] for row in rows] == [s.name for s in CATALOGUE if s.name in only]
    assert "rejected" in text and "solver.method" in text
    with pytest.raises(KeyError, match="unknown stress scene"):
        stress.run_matrix(only=["no_such_scene"])
