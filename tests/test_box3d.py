"""The 3D box runs with the same code and keeps the same invariants, with P1 and P2 tetrahedra."""
import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.studies import verify


@pytest.fixture(scope="module")
def box():
    return ngwear.load_scene(ROOT / "geometries" / "box3d.toml")


@pytest.mark.parametrize("order, maxh", [(1, 0.125), (2, 0.25)], ids=["P1", "P2"])
def test_box_invariants(box, order, maxh):
    scene = box.replace(**{"mesh.order": order, "mesh.maxh": maxh})
    r = ngwear.simulate(scene, progress=False)
    g = scene.contact.gap
    assert r.completed and r.contact_points.shape[1] == 3
    gap = r.normal_displacement - r.d0 - g
    assert gap.max() <= 1e-9 and r.reaction.min() >= 0 and np.abs(r.reaction * gap).max() < 1e-9
    assert r.wear.min() >= 0 and np.diff(r.wear, axis=0).min() >= -1e-15 and r.wear.max() > 0
    assert np.isfinite(r.pressure).all()
    alpha = scene.contact.wear * np.linalg.norm(scene.foundation.velocity)
    assert np.allclose(np.diff(r.wear @ r.weights), scene.dt * alpha * (r.pressure[:-1] @ r.weights), rtol=1e-12)
    u = r.displacement_at([[1.0, 0.25, 0.5]], -1)[0]
    assert u[2] < 0 and u[0] > 0, "sinks, dragged along v*"


def test_p2_full_system_agrees_with_the_condensed_path(box):
    """P2 tetrahedra, edge-midpoint contact points, friction and wear: the NGSolve form's Newton = the condensed one."""
    scene = box.replace(**{"mesh.order": 2, "mesh.maxh": 0.25, "time.steps": 8})
    fast = ngwear.simulate(scene, progress=False)
    full = ngwear.simulate(scene.replace(**{"solver.method": "full"}), progress=False)
    assert fast.completed and full.completed and fast.wear.max() > 0
    for name in ("normal_displacement", "wear", "pressure", "reaction"):
        assert np.abs(getattr(fast, name) - getattr(full, name)).max() < 1e-9, name
    pts = [[1.0, 0.25, 0.5], [0.5, 0.1, 0.0]]
    assert np.allclose(fast.displacement_at(pts, -1), full.displacement_at(pts, -1), atol=1e-9)


@pytest.mark.slow
def test_p2_is_more_accurate_than_p1_at_every_mesh_size(box):
    """P2's errors in the paper's norms are below P1's on the same mesh, and both converge.

    h-study of the box (20 steps) against a P2 reference at maxh 1/16.
    """
    scene = box.replace(**{"time.steps": 20})
    rows = {order: verify.h_study(scene.replace(**{"mesh.order": order}), [0.5, 0.25, 0.125], 0.0625)
            for order in (1, 2)}
    for p1, p2 in zip(rows[1], rows[2]):
        assert p2["V_sum"] < 0.8 * p1["V_sum"] and p2["W_sum"] < 0.6 * p1["W_sum"], (p1, p2)
    for order in (1, 2):
        orders = verify.orders(rows[order], "h")
        assert orders["V_sum"] > 0.5 and orders["W_sum"] > 1.0, (order, orders)
