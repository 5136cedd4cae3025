"""Skip rules: what a scene change does not invalidate is not rebuilt, and μ = 0 takes the symmetric path."""
import numpy as np
import pytest

import ngwear
from ngwear.numerics.discrete import Discretization


@pytest.fixture(scope="module")
def base(paper_scene):
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 10})
    disc = Discretization(scene)
    result = ngwear.simulate(scene, discretization=disc, progress=False)
    return scene, disc, result


@pytest.mark.parametrize("change", [{"contact.wear": 0.5}, {"contact.friction": 0.3},
                                    {"foundation.velocity": [2.0, 0.0]}, {"contact.gap": 0.1},
                                    {"loads.traction": {"top": [0.0, -0.2]}}])
def test_change_reuses_factorisation(base, change):
    scene, disc, _ = base
    new = disc.with_scene(scene.replace(**change))
    assert new.mesh is disc.mesh and new.operator is disc.operator
    assert new.normal_rows is disc.normal_rows
    reused_load = "loads.traction" not in change
    assert (new.__dict__.get("u_load") is disc.u_load) == reused_load


def test_material_change_refactorises_but_keeps_mesh(base):
    scene, disc, _ = base
    new = disc.with_scene(scene.replace(**{"material.lame_mu": 2.0}))
    assert new.mesh is disc.mesh and new.operator is not disc.operator


def test_reused_run_equals_fresh_run(base):
    scene, disc, _ = base
    changed = scene.replace(**{"contact.wear": 0.5, "contact.friction": 0.3})
    reused = ngwear.simulate(changed, discretization=disc, progress=False)
    fresh = ngwear.simulate(changed, progress=False)
    assert np.allclose(reused.wear, fresh.wear, atol=1e-14)


def test_zero_friction_matrix_is_symmetric(base):
    """μ = 0: the condensed Newton matrix is the symmetric H (no friction compliance is formed)."""
    scene, disc, _ = base
    H = disc.normal_compliance
    assert np.allclose(H, H.T, atol=1e-14 * np.abs(H).max())
    frictional = H + disc.friction_compliance(disc.n_star(0.0))
    assert not np.allclose(frictional, frictional.T, atol=1e-6 * np.abs(H).max())


def test_zero_wear_rate_gives_no_wear(base):
    scene, disc, _ = base
    r = ngwear.simulate(scene.replace(**{"contact.wear": 0.0}), discretization=disc, progress=False)
    assert r.wear.max() == 0 and r.pressure.max() > 0
    assert np.allclose(r.normal_displacement, r.normal_displacement[0], atol=1e-14), "steady without wear"


def test_zero_friction_skips_friction_work(base, monkeypatch):
    scene, disc, _ = base
    frictionless = disc.with_scene(scene.replace(**{"contact.friction": 0.0}))

    def forbidden(*_):
        raise AssertionError("friction compliance formed although μ = 0")
    monkeypatch.setattr(frictionless, "friction_compliance", forbidden)
    assert ngwear.simulate(frictionless.scene, discretization=frictionless, progress=False).completed
