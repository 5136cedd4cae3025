"""Observed convergence orders (Theorem 5 predicts at least 1/2 in h and 1 in k) and the (H_S) check."""
import ngsolve as ngs
import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.model.compliance import largest_slope
from ngwear.numerics import discrete
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.forms import elastic_form, load_form
from ngwear.studies import verify
from ngwear.studies.theory import smallness, trace_constant


@pytest.fixture(scope="module")
def scene(paper_scene):
    return paper_scene.replace(**{"time.steps": 20, "output.every": 1.0})


@pytest.mark.slow
def test_h_orders(scene):
    rows = verify.h_study(scene, [0.4, 0.2, 0.1], 0.025)
    rates = verify.orders(rows, "h")
    assert rates["V_sum"] > 0.7 and rates["V_final"] > 0.7, rates   # theory: 0.5; observed ≈ 1
    assert rates["W_sum"] > 1.3 and rates["W_final"] > 1.3, rates   # observed ≈ 1.7–1.9


@pytest.mark.parametrize("integrator, low, high", [("explicit", 0.8, 1.6), ("implicit", 0.8, 1.3),
                                                   ("trapezoidal", 1.6, 2.4)])
def test_k_orders_of_wear_integrators(scene, integrator, low, high):
    rows = verify.k_study(scene.replace(**{"wear.integrator": integrator, "mesh.maxh": 0.2}), [20, 40, 80], 640)
    rate = verify.orders(rows, "k")["W_sum"]
    assert low < rate < high, f"{integrator}: observed order {rate:.2f}"


def test_error_of_reference_against_itself_is_zero(scene):
    result, _ = verify._run(scene.replace(**{"mesh.maxh": 0.3, "time.steps": 4, "output.every": 1.0,
                                             "wear.integrator": "implicit"}))
    e = verify.errors(result, result)
    assert max(e.V_sum, e.W_sum, e.V_final, e.W_final) < 1e-12


def test_trace_constant_bounds_a_rayleigh_quotient(paper_scene):
    """c₀² is the maximum of ‖v‖²_ΓC / ‖ε(v)‖² over V: any v (here the elastic response) stays below it."""
    disc = Discretization(paper_scene.replace(**{"mesh.maxh": 0.2}))
    c0 = trace_constant(disc)
    a, f = elastic_form(disc.fes, disc.elastic.laws), load_form(disc.fes, disc.scene)
    a.Assemble(), f.Assemble()
    v = ngs.GridFunction(disc.fes)
    v.vec.data = a.mat.Inverse(disc.fes.FreeDofs()) * f.vec
    strain = ngs.Sym(ngs.Grad(v))
    quotient = ngs.Integrate(ngs.InnerProduct(v, v), disc.mesh, definedon=disc.mesh.Boundaries("contact")) / \
        ngs.Integrate(ngs.InnerProduct(strain, strain), disc.mesh, definedon=disc.mesh.Materials("body"))
    assert 0.3 * c0**2 < quotient <= c0**2 * (1 + 1e-9)


def test_smallness_hypothesis(paper_scene):
    disc = Discretization(paper_scene.replace(**{"mesh.maxh": 0.2}))
    paper = smallness(disc)
    assert not paper.holds and "does not cover this scene" in paper.message() and "warning" not in paper.message()
    tiny = smallness(disc.with_scene(disc.scene.replace(**{"contact.friction": 1e-4})))
    assert tiny.holds and tiny.c0 == pytest.approx(paper.c0)


def test_stability_picture(paper_scene):
    """Wear passes the largest penetration so far for explicit once kαL > 1, trapezoidal once kαL > 2, implicit never.

    The overshoot is max_j (w_j − max_(m≤j) (u_ν − d₀)₊)/g: after lift-off w > u_ν − d₀ is physical and not
    counted (before, the implicit update showed 0.0101 here).
    """
    scene = paper_scene.replace(**{"mesh.maxh": 0.3})
    rows = {r["steps"]: r for r in verify.stability_study(scene, [30, 10, 6], ref_steps=320)}
    assert [rows[n]["k_alpha_L"] for n in (30, 10, 6)] == pytest.approx([0.5, 1.5, 2.5])
    assert rows[30]["explicit_overshoot"] == 0 and rows[10]["explicit_overshoot"] > 0.005   # kαL = 0.5, 1.5
    assert rows[10]["trapezoidal_overshoot"] == 0 and rows[6]["trapezoidal_overshoot"] > 0.005  # 1.5, 2.5
    assert all(r["implicit_overshoot"] == 0 for r in rows.values())
    assert rows[10]["trapezoidal_W_final"] < rows[10]["implicit_W_final"] < rows[10]["explicit_W_final"]


def test_stability_uses_the_scenes_own_wear_rate():
    """The pin on a turning disc: α = κ|ω| r at the outermost contact point (the translation alone gives α = 0)."""
    pin = verify.refined(ngwear.load_scene(ROOT / "geometries" / "pin_on_disc.toml"), 2.0)
    disc = Discretization(pin)
    radius = np.hypot(*disc.points.coords[:, :2].T).max()
    rate = pin.contact.wear * 10.0 * radius * largest_slope(pin.contact)
    assert verify.alpha_slope(pin) == pytest.approx(rate, rel=1e-12) and rate > 0
    steps = verify.stability_steps(pin)
    assert steps == sorted({max(1, round(pin.time.T * rate / r)) for r in (0.5, 1, 1.5, 2.5, 5)}, reverse=True)


def test_trace_constant_matrix_free_equals_dense(paper_scene, monkeypatch):
    """Beyond DENSE_LIMIT contact DOFs c₀ comes from shift-invert Lanczos with back-substitutions: the same number."""
    disc = Discretization(paper_scene.replace(**{"mesh.maxh": 0.2}))
    dense = trace_constant(disc)
    monkeypatch.setattr(discrete, "DENSE_LIMIT", 1)
    large = Discretization(disc.scene, disc.mesh)
    assert large.with_scene(large.scene.replace(material={"lame_lambda": 0.0, "lame_mu": 0.5})).matrix_free
    assert trace_constant(large) == pytest.approx(dense, rel=1e-7)


def test_h_study_refines_every_size():
    """The pin's Γ_C mesh is set by mesh.contact_maxh: refining maxh alone gave the same mesh at every size."""
    pin = ngwear.load_scene(ROOT / "geometries" / "pin_on_disc.toml")
    finer = verify.refined(pin, 0.5)
    assert (finer.mesh.maxh, finer.mesh.contact_maxh) == pytest.approx((pin.mesh.maxh / 2, pin.mesh.contact_maxh / 2))
    box = ngwear.load_scene(ROOT / "geometries" / "box3d.toml").replace(**{"time.steps": 4, "output.every": 1.0,
                                                                           "wear.integrator": "implicit"})
    with pytest.raises(ngwear.SceneError, match=r"^mesh\.maxh: refining .* the meshes do not get finer"):
        verify.h_study(box, [1.0, 0.6], 0.4)                              # Netgen's box is one layer of cells
    assert verify.refined(box, 2.0).mesh.contact_maxh is None


def test_smallness_takes_the_softest_region_of_a_two_material_pad():
    """m_F of (H_S) is min over the regions: the friction material's smallest Mandel eigenvalue, not the steel's 2η."""
    pad = ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml").replace(**{"mesh.maxh": 0.024})
    m = pad.material
    compliance = np.zeros((6, 6))
    compliance[:3, :3] = [[1 / m.young_plane, -m.poisson_plane / m.young_plane, -m.poisson_axis / m.young_axis],
                          [-m.poisson_plane / m.young_plane, 1 / m.young_plane, -m.poisson_axis / m.young_axis],
                          [-m.poisson_axis / m.young_axis, -m.poisson_axis / m.young_axis, 1 / m.young_axis]]
    compliance[3:, 3:] = np.diag([1 / (2 * m.shear_axis)] * 2 + [(1 + m.poisson_plane) / m.young_plane])
    expected = np.linalg.eigvalsh(np.linalg.inv(compliance))[0]      # invariant under the rotation onto the axis
    steel = m.regions["backing"]
    assert expected < steel.young / (1 + steel.poisson)               # 2η of the steel
    assert smallness(Discretization(pad)).monotonicity == pytest.approx(expected, rel=1e-12)


@pytest.mark.hostile
def test_a_programme_is_verified_on_its_first_stop(paper_scene):
    """``ngwear verify`` of a programme: its first stop as a scene of its own, the same wear as the programme's stop."""
    from ngwear.studies.convergence import first_stop

    blocks = [{"count": 3, "duration": 0.5, "speed": [1.0, 0.0], "load": [1.0, 0.5], "dwell": 0.5}]
    programme = paper_scene.replace(**{"programme.stops": blocks, "mesh.maxh": 0.2, "output.every": 0.5})
    stop = first_stop(programme)
    assert stop.programme is None and (stop.time.T, stop.time.steps) == (0.5, 20)
    assert stop.foundation.speed_table == ((0.0, 1.0), (0.5, 0.0)) and stop.loads.time_table == ((0.0, 1.0), (0.5, 0.5))
    whole, alone = ngwear.simulate(programme, progress=False), ngwear.simulate(stop, progress=False)
    assert np.allclose(whole.wear[:21], alone.wear, rtol=1e-12, atol=1e-15)
    assert np.allclose(whole.speed_factor[:21], alone.speed_factor, rtol=0, atol=1e-15)
