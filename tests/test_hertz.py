"""Hertz line contact: a half-cylinder pressed onto a rigid flat, against the closed form.

The curved Γ_C enters only through the initial distance d₀(x) = y(x) − min y.  For a cylinder of
radius R on a rigid flat in plane strain, with contact force P′ per unit thickness,

    a = √(4 P′ R / (π E*)),   p₀ = 2 P′ / (π a),   p(x) = p₀ √(1 − x²/a²),   E* = E / (1 − ν²).

The half-disk of ``geometries/hertz.toml`` is clamped on its top edge and loaded by a body force,
so the clamp takes part of the load: P′ is the contact force of the run, Σ m_i (p_i + λ_i).
The contact traction is p + λ (compliance pressure plus rigid reaction).  The half-width is read
off the traction where it drops to zero: p² is linear in x near a Hertz edge, so the zero of the
line through the last two loaded points on each side, averaged over both sides.
"""
import json
import math

import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.model.scene import Scene, SceneError
from ngwear.model.scene_mesh import mesh_key
from ngwear.numerics.discrete import Discretization

HERTZ = ROOT / "geometries" / "hertz.toml"


@pytest.fixture(scope="module")
def scene():
    return ngwear.load_scene(HERTZ)


@pytest.fixture(scope="module")
def disc(scene):
    return Discretization(scene)


@pytest.fixture(scope="module")
def signorini(scene, disc):
    return ngwear.simulate(scene, discretization=disc, progress=False)


def hertz(result, step=-1) -> dict:
    """Contact force, Hertz's a and p₀ for it, and the measured half-width and peak traction."""
    sc = result.scene
    young, poisson = sc.material.young, sc.material.poisson
    radius = sc.geometry.size[0]
    order = np.argsort(result.contact_points[:, 0])
    x = result.contact_points[order, 0]
    traction = (result.pressure[step] + result.reaction[step])[order]
    force = float(np.sum(result.weights[order] * traction))
    e_star = young / (1 - poisson ** 2)
    a = math.sqrt(4 * force * radius / (math.pi * e_star))
    loaded = np.flatnonzero(traction > 0)
    edges = []
    for last, inner in ((loaded[0], loaded[0] + 1), (loaded[-1], loaded[-1] - 1)):
        x1, x0 = abs(x[last]), abs(x[inner])
        q1, q0 = traction[last] ** 2, traction[inner] ** 2
        edges.append(x1 + q1 * (x1 - x0) / (q0 - q1))
    return {"force": force, "a_hertz": a, "p0_hertz": 2 * force / (math.pi * a),
            "a": float(np.mean(edges)), "peak": float(traction.max()), "loaded": len(loaded),
            "x": x, "traction": traction}


# ---------------------------------------------------------------- scene and geometry


def test_scene_file(scene):
    g, m = scene.geometry, scene.mesh
    assert g.kind == "half_disk" and scene.dim == 2 and g.size == (1.0,) and g.dirichlet == ("top",)
    assert m.contact_maxh == 0.001 and m.contact_zone == 0.15 and m.grading == 0.1
    assert scene.contact.friction == 0 and scene.contact.wear == 0 and scene.contact.gap <= 1e-8
    assert scene.loads.body_force == (0.0, -0.01) and scene.loads.traction == {}
    assert Scene.from_dict(json.loads(json.dumps(scene.to_dict()))) == scene


def test_half_disk_mesh(scene, disc):
    """Γ_C is the arc (vertices on the circle), touching y = 0 at a vertex; refined within the zone."""
    radius, zone, h = scene.geometry.size[0], scene.mesh.contact_zone, scene.mesh.contact_maxh
    pts = disc.points.coords
    assert np.abs(np.hypot(pts[:, 0], pts[:, 1] - radius) - radius).max() < 1e-12
    assert pts[:, 1].min() == pytest.approx(0, abs=1e-14) and np.abs(pts[:, 0]).min() < 1e-14
    assert np.all(pts[:, 1] <= radius + 1e-12)
    np.testing.assert_allclose(disc.condensation.d0, pts[:, 1], atol=1e-14)  # d₀ = height above the lowest point
    assert set(disc.mesh.GetBoundaries()) == {"contact", "top"}
    assert set(disc.mesh.GetMaterials()) == {"body"}
    x = np.sort(pts[:, 0])
    spacing, middle = np.diff(x), 0.5 * (x[1:] + x[:-1])
    assert spacing[np.abs(middle) < zone].max() <= 1.2 * h   # Netgen keeps maxh to ~15 %
    assert spacing[np.abs(middle) > 0.5].min() > 4 * h   # coarse away from the contact


@pytest.mark.parametrize("changes, field, allowed", [
    ({"geometry.dirichlet": ["left"]}, "geometry.dirichlet", "allowed: top"),
    ({"geometry.dirichlet": ["contact"]}, "geometry.dirichlet", "allowed: top"),
    ({"geometry.size": [1.0, 1.0]}, "geometry.size", "list of 1 numbers"),
    ({"geometry.size": [-1.0]}, "geometry.size", "> 0"),
    ({"loads.traction.top": [0.0, -1.0]}, "loads.traction.top", "non-Neumann"),
    ({"mesh.contact_maxh": 0.2}, "mesh.contact_maxh", "in (0, 0.1]"),
    ({"mesh.contact_zone": 1.5}, "mesh.contact_zone", "in (0, 1.0]"),
    ({"mesh.grading": 0.01}, "mesh.grading", "in [0.1, 1.0]"),
])
def test_half_disk_scene_errors(scene, changes, field, allowed):
    with pytest.raises(SceneError) as info:
        scene.replace(**changes)
    msg = str(info.value)
    assert msg.startswith(f"{field}:") and allowed in msg and "\n" not in msg, msg


def test_half_disk_defaults_and_other_kinds(paper_scene):
    s = Scene.from_dict({"geometry": {"kind": "half_disk"}})
    assert s.geometry.size == (1.0,) and s.geometry.dirichlet == ("top",)
    with pytest.raises(SceneError, match=r"^mesh\.contact_zone: only with mesh\.contact_maxh"):
        paper_scene.replace(**{"mesh.contact_zone": 0.1})
    refined = paper_scene.replace(**{"mesh.contact_maxh": 0.02, "mesh.grading": 0.2})
    assert refined.mesh.contact_maxh == 0.02 and refined.mesh.grading == 0.2


def test_mesh_key_depends_only_on_what_shapes_the_mesh(paper_scene):
    """Loads, material, contact law (g included) and time reuse the cached mesh; mesh keys do not."""
    same = {mesh_key(paper_scene.replace(**{k: v})) for k, v in
            (("contact.gap", 0.1), ("contact.friction", 0.3), ("loads.traction.top", [0.0, -0.3]),
             ("material.lame_mu", 2.0), ("time.steps", 7))}
    assert same == {mesh_key(paper_scene)}
    keys = {mesh_key(paper_scene.replace(**{k: v})) for k, v in
            (("mesh.contact_maxh", 0.02), ("mesh.contact_maxh", 0.01), ("mesh.grading", 0.2))}
    assert len(keys) == 3 and mesh_key(paper_scene) not in keys


def test_strip_contact_maxh_refines_contact_edge(paper_scene):
    base = paper_scene.replace(**{"mesh.maxh": 0.2})
    coarse = Discretization(base)
    fine = Discretization(base.replace(**{"mesh.contact_maxh": 0.05}))
    assert coarse.points.n == 16 and fine.points.n == 61          # 3 / 0.2 + 1, 3 / 0.05 + 1
    assert np.diff(np.sort(fine.points.coords[:, 0])).max() <= 0.05 * 1.001


# ---------------------------------------------------------------- Hertz


def test_hertz_rigid_flat(signorini):
    """Signorini limit (g → 0): a and p₀ within 2 % of Hertz, a resolved by ≥ 20 elements."""
    assert signorini.completed
    h = hertz(signorini)
    assert h["a_hertz"] / signorini.scene.mesh.contact_maxh >= 20
    assert h["loaded"] >= 40
    assert h["a"] == pytest.approx(h["a_hertz"], rel=0.02)
    assert h["peak"] == pytest.approx(h["p0_hertz"], rel=0.02)
    # the whole profile p₀ √(1 − x²/a²), within 2 % of p₀ away from the edges
    x, t = h["x"], h["traction"]
    exact = h["p0_hertz"] * np.sqrt(np.clip(1 - (x / h["a_hertz"]) ** 2, 0, None))
    inner = np.abs(x) < 0.9 * h["a_hertz"]
    assert np.abs(t - exact)[inner].max() < 0.02 * h["p0_hertz"]
    assert np.all(t[np.abs(x) > 1.1 * h["a_hertz"]] == 0)
    # rigid flat: the points in contact sit on it, u_ν − d₀ = g; the traction is the reaction
    pen = signorini.normal_displacement[-1] - signorini.d0
    assert pen.max() <= signorini.scene.contact.gap * (1 + 1e-6)
    contact = signorini.scene.contact
    assert signorini.pressure[-1].max() <= contact.stiffness * contact.gap * 1.01
    # symmetric, and the force is the one the foundation receives
    assert abs(np.sum(signorini.weights * (signorini.pressure[-1] + signorini.reaction[-1])
                      * signorini.contact_points[:, 0])) < 1e-3 * h["force"] * h["a_hertz"]
    np.testing.assert_allclose(signorini.forces[-1].sum(axis=0), [0, -h["force"]], rtol=1e-12, atol=0)
    # the clamp carries the rest of the body force
    resultant = 0.01 * math.pi / 2
    assert 0 < h["force"] < resultant


def test_hertz_stiff_compliance(scene, disc, signorini):
    """Compliance alone (g large, constraint never active) with L = 1e8 gives the same contact."""
    stiff = scene.replace(**{"contact.stiffness": 1e8, "contact.gap": 1.0, "solver.max_iterations": 1000})
    result = ngwear.simulate(stiff, discretization=disc, progress=False)
    assert result.completed and result.reaction.max() == 0
    h, ref = hertz(result), hertz(signorini)
    assert h["a"] == pytest.approx(h["a_hertz"], rel=0.02)
    assert h["peak"] == pytest.approx(h["p0_hertz"], rel=0.02)
    assert h["peak"] == pytest.approx(ref["peak"], rel=1e-5) and h["a"] == pytest.approx(ref["a"], rel=1e-5)


def test_hertz_approach_as_compliance_stiffens(scene, disc, signorini):
    """Compliance p = L r₊ with L = 1e2 … 1e5 approaches the rigid limit monotonically.

    The contact narrows and peaks towards the rigid solution, the distance to it falling like 1/L.
    """
    ref = hertz(signorini)
    runs = []
    for stiffness in (1e2, 1e3, 1e4, 1e5):
        s = scene.replace(**{"contact.stiffness": stiffness, "contact.gap": 1.0,
                             "solver.max_iterations": 1000})
        result = ngwear.simulate(s, discretization=disc, progress=False)
        assert result.completed
        runs.append(hertz(result))
    peaks = np.array([h["peak"] for h in runs])
    widths = np.array([h["a"] for h in runs])
    loaded = [h["loaded"] for h in runs]
    assert np.all(np.diff(peaks) > 0) and np.all(np.diff(widths) < 0)
    assert all(b <= a for a, b in zip(loaded, loaded[1:]))
    dp, da = np.abs(peaks / ref["peak"] - 1), np.abs(widths / ref["a"] - 1)
    assert np.all(dp[1:] < dp[:-1] / 5) and np.all(da[1:] < da[:-1] / 5)
    assert dp[-1] < 1e-3 and da[-1] < 1e-3
    last = runs[-1]
    assert last["a"] == pytest.approx(last["a_hertz"], rel=0.02)
    assert last["peak"] == pytest.approx(last["p0_hertz"], rel=0.02)
