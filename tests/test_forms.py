"""The NGSolve contact form: Taylor test of its linearisation, and agreement with the condensed path."""
from pathlib import Path

import ngsolve as ngs
import numpy as np
import pytest

import ngwear
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


@pytest.mark.parametrize("friction", [0.0, 0.8])
def test_taylor_jacobian_matches_residual(disc, friction):
    """‖R(u + εδ) − R(u) − ε J δ‖ = O(ε²): the remainder drops by ~4 when ε halves."""
    rng = np.random.default_rng(1)
    cf = contact_form(disc.fes, disc.scene.replace(**{"contact.friction": friction}), disc.law, disc.elastic.laws)
    u, w = state_away_from_kink(disc, rng)
    disc.set_nodal(cf.w, w)
    disc.set_nodal(cf.stiffness, disc.coefficients.stiffness)
    for gf, component in zip(cf.friction, disc.friction_directions(0.0).T):
        disc.set_nodal(gf, component)
    delta = u.vec.CreateVector()
    delta.FV().NumPy()[:] = rng.standard_normal(disc.fes.ndof) * disc.body.free
    res0, res1, jd = u.vec.CreateVector(), u.vec.CreateVector(), u.vec.CreateVector()
    cf.form.Apply(u.vec, res0)
    cf.form.AssembleLinearization(u.vec)
    jd.data = cf.form.mat * delta
    remainders = []
    for eps in (1e-3, 5e-4, 2.5e-4):
        shifted = u.vec.CreateVector()
        shifted.data = u.vec + eps * delta
        cf.form.Apply(shifted, res1)
        remainders.append(np.linalg.norm(res1.FV().NumPy() - res0.FV().NumPy() - eps * jd.FV().NumPy()))
    assert remainders[0] < 1e-6 * np.linalg.norm(jd.FV().NumPy()) or \
        (remainders[0] / remainders[1] > 3.5 and remainders[1] / remainders[2] > 3.5)
    assert np.linalg.norm(jd.FV().NumPy()) > 0


def test_contact_form_is_nodal(disc):
    """Apply of the contact form alone equals Pᵀ f_c with f_i = m_i p_i (ν + μ n*)."""
    rng = np.random.default_rng(2)
    cf = contact_form(disc.fes, disc.scene, disc.law, None)
    u, w = state_away_from_kink(disc, rng)
    disc.set_nodal(cf.w, w)
    disc.set_nodal(cf.stiffness, disc.coefficients.stiffness)
    for gf, component in zip(cf.friction, disc.friction_directions(0.0).T):
        disc.set_nodal(gf, component)
    res = u.vec.CreateVector()
    cf.form.Apply(u.vec, res)
    pressure = disc.law(disc.condensation.N @ u.vec.FV().NumPy() - disc.condensation.d0 - w)
    expected = disc.points.P.T @ disc.contact_forces(pressure, np.zeros_like(pressure), 0.0).ravel()
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
