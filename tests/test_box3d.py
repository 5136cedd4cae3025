"""The 3D box runs with the same code and keeps the same invariants."""
import numpy as np
from conftest import ROOT

import ngwear


def test_box_invariants():
    scene = ngwear.load_scene(ROOT / "geometries" / "box3d.toml")
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
