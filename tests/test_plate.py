"""Force control: a rigid plate on a boundary, pressed by a force, its displacement δ one more unknown.

Checks: the force balance Σ m_i (p_i + λ_i) = F·ν + (body force)·ν at every step to round-off for a
body held by the plate alone; a nearly rigid body under a plate is a rigid punch on the compliant layer
(uniform p = F/A, δ = F/(A L)); with the tilt free, the contact forces of a nearly rigid body have no
moment about the plate's centroid, while a plate that cannot tilt carries the friction couple μ F h;
the full-system path agrees with the condensed one; a power-law layer (zero stiffness at first touch)
and a layer worn away between steps are found by the rigid-motion predictor.
"""
import numpy as np
import pytest
from conftest import ROOT

import ngwear

BOX = ROOT / "geometries" / "box3d.toml"
FORCE = 0.05


@pytest.fixture(scope="module")
def pressed():
    """The 3D box held only by a plate on its top face, pressed with F = 0.05 onto the moving foundation."""
    return ngwear.load_scene(BOX).replace(**{
        "mesh.maxh": 0.2, "time.steps": 20, "output.every": 1.0, "geometry.dirichlet": [], "loads.traction": {},
        "loads.plate": {"boundary": "top", "force": [0.0, 0.0, -FORCE]}})


def test_force_balance_at_every_step(pressed):
    scene = pressed.replace(**{"loads.body_force": [0.0, 0.0, -0.2], "loads.time_table": [[0, 0.5], [1, 1.5]],
                               "wear.integrator": "implicit"})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed and result.wear.max() > 0.3 * scene.contact.gap
    weight = 0.2 * 0.25                                           # body force × volume
    carried = (FORCE + weight) * np.interp(result.times, [0, 1], [0.5, 1.5])
    assert np.abs(result.normal_force - carried).max() < 1e-10 * carried.max()
    assert result.plate_displacement.shape == (21, 1) and (np.diff(result.plate_displacement[:, 0]) > 0).all()


def test_a_stiff_body_is_a_rigid_punch_on_the_layer(pressed):
    scene = pressed.replace(**{"material": {"young": 1e7, "poisson": 0.3}, "contact.wear": 0.0,
                               "contact.friction": 0.0, "time.steps": 2, "output.every": 1.0})
    result = ngwear.simulate(scene, progress=False)
    area, stiffness = 1.0 * 0.5, scene.contact.stiffness
    assert result.pressure[-1] == pytest.approx(np.full(len(result.weights), FORCE / area), rel=1e-5)
    assert result.plate_displacement[-1, 0] == pytest.approx(FORCE / (area * stiffness), rel=1e-5)
    assert result.contact_area[-1] == pytest.approx(area, rel=1e-12)


def friction_couple(result):
    """Σ m_i p_i (x_i − x_c): the pressure's first moment along the sliding direction x."""
    x = result.contact_points[:, 0] - 0.5
    return (result.pressure[-1] + result.reaction[-1]) @ (result.weights * x)


@pytest.mark.parametrize("tilt", [True, False])
def test_tilt_frees_the_plate_of_the_friction_couple(pressed, tilt):
    """Nearly rigid box, μ = 0.5: friction μF at the contact face, the abutment's −μF at the plate (h = 0.5).

    Free tilt: the contact forces (pressure and friction) have zero moment about the plate's centroid,
    Σ m p (x − x_c) = −μ F h.  No tilt: the plate carries the couple and the pressure stays uniform.
    """
    mu, h = 0.5, 0.5
    scene = pressed.replace(**{"material": {"young": 1e7, "poisson": 0.3}, "contact.wear": 0.0,
                               "contact.friction": mu, "loads.plate.tilt": tilt, "time.steps": 2,
                               "output.every": 1.0})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed
    expected = -mu * FORCE * h if tilt else 0.0
    assert friction_couple(result) == pytest.approx(expected, abs=1e-5 * FORCE * h)
    assert result.plate_displacement.shape[1] == (3 if tilt else 1)


@pytest.mark.parametrize("changes", [
    {"loads.plate.tilt": True, "foundation.angular_velocity": [0, 0, 1.0], "foundation.center": [0.5, -1.0, 0]},
    {"geometry.dirichlet": ["left"]},
    {"contact.law": "power", "contact.exponent": 2.0, "contact.stiffness": 200.0, "wear.integrator": "explicit",
     "time.steps": 60, "output.every": 1.0},
], ids=["tilt-rotation", "clamped-too", "power-law"])
def test_full_system_agrees(pressed, changes):
    """The full-system path (explicit wear only) agrees, at any k·α·L: the unstable updates are allowed here."""
    scene = pressed.replace(**{"time.steps": 6, "output.every": 1.0, "wear.allow_unstable": True, **changes})
    fast = ngwear.simulate(scene, progress=False)
    full = ngwear.simulate(scene.replace(**{"solver.method": "full"}), progress=False)
    assert fast.completed and full.completed
    for name in ("normal_displacement", "wear", "pressure", "plate_displacement"):
        assert np.abs(getattr(fast, name) - getattr(full, name)).max() < 1e-9, name
    corner = [[1.0, 0.5, 0.5]]
    assert np.allclose(fast.displacement_at(corner, -1), full.displacement_at(corner, -1), atol=1e-9)


def test_worn_away_contact_is_found_again(pressed):
    """A worn-through contact is found again by the rigid-motion predictor.

    With k α L = 1.5 the explicit update wears past the surface and every point leaves contact.
    """
    scene = pressed.replace(**{"time.steps": 10, "output.every": 1.0})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed
    assert max(r.iterations for r in result.newton) <= 8
    assert np.abs(result.normal_force - FORCE).max() < 1e-10


def test_plate_in_2d_with_tilt(paper_scene):
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 10, "output.every": 1.0, "geometry.dirichlet": [],
                                   "loads.traction": {}, "contact.friction": 0.3,
                                   "loads.plate": {"boundary": "top", "force": [0.0, -0.3], "tilt": True},
                                   "wear.allow_unstable": True})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed and result.plate_displacement.shape == (11, 2)
    assert np.abs(result.normal_force - 0.3).max() < 1e-10
    full = ngwear.simulate(scene.replace(**{"solver.method": "full", "time.steps": 3, "output.every": 1.0}),
                           progress=False)
    fast = ngwear.simulate(scene.replace(**{"time.steps": 3, "output.every": 1.0}), progress=False)
    assert np.abs(full.wear - fast.wear).max() < 1e-9


def test_force_change_reuses_the_factorisation(pressed):
    first = ngwear.simulate(pressed, progress=False)
    disc = first.discretization
    operator, coupling = disc.elastic.operator, disc.condensation.plate
    second = ngwear.simulate(pressed.replace(**{"loads.plate.force": [0, 0, -0.1]}), discretization=disc,
                             progress=False)
    assert second.discretization.elastic.operator is operator and second.discretization.condensation.plate is coupling
    assert second.normal_force[-1] == pytest.approx(0.1, rel=1e-10)


@pytest.mark.parametrize("changes, field, fragment", [
    ({"geometry.dirichlet": []}, "geometry.dirichlet", "or give loads.plate"),
    ({"loads.traction": {}, "loads.plate": {"boundary": "contact", "force": [0, 0, -1]}}, "loads.plate.boundary",
     "allowed: right, front, back, top"),
    ({"loads.plate": {"boundary": "top", "force": [0, 0, -1]}}, "loads.plate.boundary", "loaded"),
    ({"loads.traction": {}, "loads.plate": {"boundary": "top", "force": [0, -1]}}, "loads.plate.force",
     "list of 3 numbers"),
    ({"loads.traction": {}, "geometry.dirichlet": [], "loads.plate": {"boundary": "top", "force": [0, 0, 1]}},
     "loads.plate.force", "must press the body"),
    ({"loads.traction": {}, "loads.plate": {"boundary": "top"}}, "loads.plate.force", "missing"),
    ({"loads.traction": {}, "loads.plate": {"boundary": "top", "force": [0, 0, -1], "angle": 3}},
     "loads.plate.angle", "unknown key (allowed: boundary, force, tilt)"),
])
def test_plate_keys_are_validated(changes, field, fragment):
    base = ngwear.load_scene(BOX)
    with pytest.raises(ngwear.SceneError) as info:
        base.replace(**changes)
    message = str(info.value)
    assert message.startswith(f"{field}:") and fragment in message and "\n" not in message, message
