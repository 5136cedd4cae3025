"""The NGSolve contact form: Taylor test of its linearisation, and agreement with the condensed path."""
from pathlib import Path

import ngsolve as ngs
import numpy as np
import pytest

import ngwear
from ngwear.model.compliance import compliance_from
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.forms import contact_form

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def disc(paper_scene):
    return Discretization(paper_scene.replace(**{"mesh.maxh": 0.25}))


def state_away_from_kink(disc, rng):
    """A displacement whose penetrations at the contact points are ≥ 0.02 or ≤ −0.02."""
    u = ngs.GridFunction(disc.fes)
    u.vec.FV().NumPy()[:] = 0.01 * rng.standard_normal(disc.fes.ndof)
    u.vec.FV().NumPy()[~disc.body.free] = 0
    pen = disc.condensation.N @ u.vec.FV().NumPy()
    w = pen - np.where(rng.random(len(pen)) < 0.7, 0.05, -0.05)
    return u, w


def taylor_remainders(disc, scene, rng, epsilons):
    """One-sided and central Taylor remainders of the elastic + contact residual, and ‖Jδ‖.

    ``one_sided[i]`` = ‖R(u + εδ) − R(u) − εJδ‖ and ``central[i]`` = ‖(R(u + εδ) − R(u − εδ))/2 − εJδ‖ at
    ε = ``epsilons[i]``: R the residual (``Apply``), J its linearisation at u (``AssembleLinearization``), δ a
    random direction on the free DOFs, u away from the law's kink by more than ε δ moves it.
    """
    cf = contact_form(disc.fes, scene, compliance_from(scene.contact), disc.elastic.laws)
    u, w = state_away_from_kink(disc, rng)
    contact = disc.with_scene(scene).contact       # μ and L of ``scene`` (a change that rebuilds nothing)
    disc.set_nodal(cf.w, w)
    disc.set_nodal(cf.stiffness, contact.coefficients.stiffness)
    for gf, component in zip(cf.friction, contact.friction_directions(contact.coefficients, 1.0).T):
        disc.set_nodal(gf, component)
    delta = u.vec.CreateVector()
    delta.FV().NumPy()[:] = rng.standard_normal(disc.fes.ndof) * disc.body.free
    assert np.abs(disc.condensation.N @ delta.FV().NumPy()).max() * max(epsilons) < 0.02     # the kink stays out of reach
    res0, plus, minus, jd, shifted = (u.vec.CreateVector() for _ in range(5))
    cf.form.Apply(u.vec, res0)
    cf.form.AssembleLinearization(u.vec)
    jd.data = cf.form.mat * delta
    one_sided, central = [], []
    for eps in epsilons:
        shifted.data = u.vec + eps * delta
        cf.form.Apply(shifted, plus)
        shifted.data = u.vec - eps * delta
        cf.form.Apply(shifted, minus)
        r0, rp, rm, j = (v.FV().NumPy() for v in (res0, plus, minus, jd))
        one_sided.append(np.linalg.norm(rp - r0 - eps * j))
        central.append(np.linalg.norm(0.5 * (rp - rm) - eps * j))
    return np.array(one_sided), np.array(central), float(np.linalg.norm(jd.FV().NumPy()))


EPSILONS = [1e-3 * 0.5**i for i in range(4)]      # floats: numpy scalar * BaseVector is not a vector expression


@pytest.mark.parametrize("friction", [0.0, 0.8])
def test_taylor_jacobian_matches_residual(disc, friction):
    """Power law p = L r₊^2.5 (smooth away from r = 0): one-sided remainder O(ε²), central O(ε³).

    ‖R(u + εδ) − R(u) − εJδ‖ = ε²/2 ‖R''(δ, δ)‖ + O(ε³) and the central remainder is ε³/6 ‖R'''(δ, δ, δ)‖
    + O(ε⁵): the observed rates log₂(r(ε)/r(ε/2)) over ε = 1e-3 … 1.25e-4 must be 2 and 3 (to 0.1).  A
    wrong Jacobian (even in one entry) leaves a remainder of order ε in both.
    """
    scene = disc.scene.replace(**{"contact.friction": friction, "contact.law": "power", "contact.exponent": 2.5})
    one_sided, central, jd = taylor_remainders(disc, scene, np.random.default_rng(1), EPSILONS)
    assert jd > 0 and central.min() > 1e3 * np.finfo(float).eps * jd    # far above round-off
    assert np.allclose(np.log2(one_sided[:-1] / one_sided[1:]), 2.0, atol=0.1), one_sided
    assert np.allclose(np.log2(central[:-1] / central[1:]), 3.0, atol=0.1), central


@pytest.mark.parametrize("friction", [0.0, 0.8])
def test_linearisation_of_the_linear_law_is_exact(disc, friction):
    """The linear law p = L r₊ is affine away from r = 0, so R(u + εδ) − R(u) = εJδ to round-off.

    NGSolve's tests/pytest/test_contact.py checks its piecewise-quadratic contact energy the same way (central
    difference against the linearisation, to 1e-10 relative).
    """
    scene = disc.scene.replace(**{"contact.friction": friction})
    one_sided, central, jd = taylor_remainders(disc, scene, np.random.default_rng(1), EPSILONS)
    assert jd > 0
    assert one_sided.max() < 1e-10 * min(EPSILONS) * jd and central.max() < 1e-10 * min(EPSILONS) * jd


def test_contact_form_is_nodal(disc):
    """Apply of the contact form alone equals Pᵀ f_c with f_i = m_i p_i (ν + μ n*)."""
    rng = np.random.default_rng(2)
    cf = contact_form(disc.fes, disc.scene, disc.contact.law, None)
    u, w = state_away_from_kink(disc, rng)
    disc.set_nodal(cf.w, w)
    disc.set_nodal(cf.stiffness, disc.contact.coefficients.stiffness)
    for gf, component in zip(cf.friction, disc.contact.friction_directions(disc.contact.coefficients, 1.0).T):
        disc.set_nodal(gf, component)
    res = u.vec.CreateVector()
    cf.form.Apply(u.vec, res)
    pressure = disc.contact.law(disc.condensation.N @ u.vec.FV().NumPy() - disc.condensation.d0 - w)
    forces = disc.contact.forces(disc.contact.coefficients, pressure, np.zeros_like(pressure), 1.0)
    expected = disc.points.P.T @ forces.ravel()
    assert np.allclose(res.FV().NumPy(), expected, atol=1e-13)


@pytest.mark.parametrize("order", [1, 2])
def test_full_and_condensed_paths_agree(paper_scene, order):
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "mesh.order": order, "time.steps": 20})
    fast = ngwear.simulate(scene, progress=False)
    full = ngwear.simulate(scene.replace(**{"solver.method": "full"}), progress=False)
    assert fast.completed and full.completed
    for name in ("normal_displacement", "wear", "pressure"):
        assert np.abs(getattr(fast, name) - getattr(full, name)).max() < 1e-9, name
    assert np.abs(fast.reaction - full.reaction).max() < 1e-8 * max(1, fast.reaction.max())
    pts = [[3.0, 1.0], [1.0, 0.0]]
    assert np.allclose(fast.displacement_at(pts, -1), full.displacement_at(pts, -1), atol=1e-9)


@pytest.mark.parametrize("order", [1, 2])
def test_nodal_rule_on_triangles_integrates_the_elements_shape_functions(order):
    """3D contact points: the vertex rule (P1) and, for P2, the edge midpoints alone (exact for quadratics).

    Σ m_i f(x_i) = ∫_ΓC f for every f of the element's degree; the weights are positive; the values at
    the Γ_C vertices (for pictures) and the scalar function Q w (for NGSolve) reproduce a linear w.
    """
    box = ngwear.load_scene(ROOT / "geometries" / "box3d.toml").replace(**{"mesh.maxh": 0.2, "mesh.order": order})
    points = Discretization(box).points
    x, y, _ = points.coords.T
    assert points.weights.min() > 0 and np.isclose(points.weights.sum(), 0.5)
    assert (points.vertices >= 0).all() if order == 1 else (points.edges >= 0).all()
    exact = {"1": 0.5, "x": 0.25, "y": 0.125, "x*y": 0.0625, "x*x": 1 / 6, "y*y": 1 / 24}  # ∫ over [0,1]×[0,0.5]
    for f, value in exact.items():
        if order == 1 and "*" in f:
            continue
        values = eval(f, {"x": x, "y": y}) * np.ones_like(x)
        assert points.weights @ values == pytest.approx(value, rel=1e-12), f
    linear = 1 + 2 * x - 3 * y
    at = points.at_vertices
    touched = np.flatnonzero(at.getnnz(axis=1))
    corners = Discretization(box).mesh.ngmesh.Coordinates()[touched]
    assert np.allclose((at @ linear)[touched], 1 + 2 * corners[:, 0] - 3 * corners[:, 1], atol=1e-12)
    disc = Discretization(box)
    gf = ngs.GridFunction(ngs.H1(disc.mesh, order=order, definedon="body"))
    disc.set_nodal(gf, linear)
    assert np.allclose([gf(disc.mesh(*p)) for p in points.coords], linear, atol=1e-12)
