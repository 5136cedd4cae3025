"""Closed-form cases.

Column under gravity (λ = 0, so no Poisson effect and the 1D field is exact in 2D/3D): the top
y = H is clamped, a body force (0, −b) presses the bottom Γ_C onto the layer, μ = 0.  Then
σ_yy(y) = b y − P with P = p + λ at the bottom, u_ν = −u_y(0) = (b H²/2 − P H)/(2η), and

    before the layer is compressed through:  u_ν = (c₁ + c₂ w)  with c₁ = bH²/2/(2η + LH), c₂ = LH/(2η + LH),
    explicit wear:  w_{j+1} = w_j + k α L (u_ν,j − w_j)  ⇒  w_j = w∞ (1 − (1 − k α L (1 − c₂))^j), w∞ = c₁/(1 − c₂),
    once u_ν = g:   P = (b H²/2 − 2η g)/H,  λ = P − L (g − w).

P2 elements (triangles and tetrahedra) represent the quadratic u_y exactly, so the FE values match to
round-off.  The layer g = 0.02 and the loads b ≤ 0.12 keep the mean strain across the column, u_ν/H ≤ g/H, at 2 %
at most: within the small-strain model (beyond 10 % a run stops, ``ngwear.runs.validity``); the solution is
linear in (b, g) together.
"""
import ngsolve as ngs
import numpy as np
import pytest

import ngwear
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.forms import elastic_form, load_form


def column(dim, b, order, steps=20, gap=0.02, maxh=0.5):
    size = [1.0, 1.0] if dim == 2 else [0.5, 0.5, 1.0]
    geometry = {"kind": "strip" if dim == 2 else "box", "size": size, "dirichlet": ["top"]}
    direction = [0.0, -1.0] if dim == 2 else [0.0, 0.0, -1.0]
    return ngwear.Scene.from_dict({
        "name": f"column{dim}d",
        "geometry": geometry,
        "mesh": {"maxh": maxh, "order": order},
        "material": {"lame_lambda": 0.0, "lame_mu": 1.0},
        "contact": {"stiffness": 10.0, "gap": gap, "friction": 0.0, "wear": 1.5, "direction": direction},
        "foundation": {"velocity": [1.0] + [0.0] * (dim - 1)},
        "loads": {"body_force": [0.0] * (dim - 1) + [-b]},
        "time": {"T": 1.0, "steps": steps},
    })


def closed_form(scene, b):
    eta, L, g = scene.material.lame_mu, scene.contact.stiffness, scene.contact.gap
    H = scene.geometry.size[-1]
    alpha, k = scene.contact.wear, scene.dt
    c1, c2 = b * H**2 / 2 / (2 * eta + L * H), L * H / (2 * eta + L * H)
    w, s, lam, p = [0.0], [], [], []
    for _ in range(scene.time.steps + 1):
        un = c1 + c2 * w[-1]
        if un <= g:
            s.append(un), lam.append(0.0)
        else:
            s.append(g), lam.append((b * H**2 / 2 - 2 * eta * g) / H - L * (g - w[-1]))
        p.append(L * max(s[-1] - w[-1], 0))
        w.append(w[-1] + k * alpha * p[-1])
    return np.array(w[:-1]), np.array(s), np.array(p), np.array(lam)


@pytest.mark.parametrize("dim", [2, 3], ids=["2D", "3D"])
@pytest.mark.parametrize("b", [0.02, 0.12], ids=["compliant", "worn-through"])
def test_column_p2_is_exact(b, dim):
    scene = column(dim, b, order=2)
    r = ngwear.simulate(scene, progress=False)
    w, s, p, lam = closed_form(scene, b)
    assert r.completed
    for name, exact in (("wear", w), ("normal_displacement", s), ("pressure", p), ("reaction", lam)):
        assert np.allclose(getattr(r, name), exact[:, None], atol=1e-11), name
    if b == 0.12:
        assert (r.reaction[-1] > 0).all() and (r.reaction[0] == 0).all()


def test_column_3d_box_p1():
    """Same closed form in 3D with P1 tetrahedra: displacement and wear within 2 % at h = 1/8."""
    scene = column(3, 0.12, order=1, steps=10, maxh=0.125)
    r = ngwear.simulate(scene, progress=False)
    w, s, p, lam = closed_form(scene, 0.12)
    assert r.completed
    assert np.abs(r.normal_displacement - s[:, None]).max() < 0.02 * s.max()
    assert np.abs(r.wear - w[:, None]).max() < 0.02 * w.max()
    assert (r.normal_displacement - r.d0 - scene.contact.gap).max() <= 1e-10
    assert np.diff(r.wear, axis=0).min() >= 0 and r.reaction.min() >= 0


def test_no_contact_is_pure_elasticity(paper_scene):
    """An upward load lifts the strip off: u is the linear-elastic solution, computed independently."""
    scene = paper_scene.replace(**{"loads.traction": {"top": [0.0, 0.05]}, "mesh.maxh": 0.2,
                                   "time.steps": 3, "wear.integrator": "implicit"})
    r = ngwear.simulate(scene, progress=False)
    assert r.completed and r.pressure.max() == 0 and r.wear.max() == 0 and r.reaction.max() == 0
    disc = Discretization(scene)
    a, f = elastic_form(disc.fes, disc.elastic.laws), load_form(disc.fes, scene)
    a.Assemble(), f.Assemble()
    u = ngs.GridFunction(disc.fes)
    u.vec.data = a.mat.Inverse(disc.fes.FreeDofs(), inverse="sparsecholesky") * f.vec
    pts = np.array([[3.0, 1.0], [1.5, 0.0], [2.0, 0.5]])
    expected = np.array([u(disc.mesh(*p)) for p in pts])
    assert np.allclose(r.displacement_at(pts, -1), expected, rtol=1e-9, atol=1e-12)
