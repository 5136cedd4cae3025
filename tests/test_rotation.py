"""A rotating counterface: slip, friction direction and wear rate per contact point.

v*(x, t) = s(t)(ω × (x − c) + v₀).  A rotation about an axis far away, with ω R = 1, slides the body
almost as the unit translation does: the difference falls like 1/R.  The discrete Archard identity
holds with the per-point α_i to round-off, points on the axis neither rub nor wear, and the friction
torque is −μ Σ m_i p_i |x_i − c| for a pure rotation.
"""
import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.numerics.contact import Motion

BOX = ROOT / "geometries" / "box3d.toml"


@pytest.fixture(scope="module")
def box():
    return ngwear.load_scene(BOX).replace(**{"mesh.maxh": 0.2, "time.steps": 20, "output.every": 1.0})


def spun(scene, radius, **extra):
    """The box on a disc turning clockwise about the vertical axis through (0.5, 0.25 − R): v* ≈ (1, 0, 0) under it."""
    return scene.replace(**{"foundation.velocity": [0.0, 0.0, 0.0], "foundation.angular_velocity": [0, 0, -1 / radius],
                            "foundation.center": [0.5, 0.25 - radius, 0.0], **extra})


def test_far_axis_rotation_tends_to_the_translation(box):
    straight = ngwear.simulate(box, progress=False)
    errors = []
    for radius in (10.0, 100.0, 1000.0):
        turning = ngwear.simulate(spun(box, radius), discretization=straight.discretization, progress=False)
        assert turning.completed
        errors.append(np.abs(turning.wear - straight.wear).max() / straight.wear.max())
    assert errors[0] < 0.05
    assert 7 < errors[0] / errors[1] < 13 and 7 < errors[1] / errors[2] < 13   # first order in 1/R


def test_zero_angular_velocity_is_the_translation_exactly(box):
    base = ngwear.simulate(box, progress=False)
    still = ngwear.simulate(box.replace(**{"foundation.angular_velocity": [0.0, 0.0, 0.0],
                                           "foundation.center": [3.0, 1.0, 0.0]}),
                            discretization=base.discretization, progress=False)
    for name in ("wear", "normal_displacement", "pressure", "reaction"):
        assert np.array_equal(getattr(base, name), getattr(still, name)), name


@pytest.mark.parametrize("integrator", ["explicit", "implicit", "trapezoidal"])
def test_archard_identity_with_per_point_alpha(box, integrator):
    """Σ m (w_{j+1} − w_j) = k Σ m (θ_old α_j p_j + θ_new α_{j+1} p_{j+1}), α_i = κ ‖v*(x_i)‖."""
    scene = spun(box, 1.0, **{"wear.integrator": integrator, "foundation.center": [0.2, 0.1, 0.0]})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed
    contact = result.discretization.contact
    alpha = np.array([contact.alpha(contact.coefficients, s) for s in result.speed_factor])
    assert alpha.min() < 0.2 * alpha.max()                # the slip really varies over Γ_C
    th_old, th_new = {"explicit": (1, 0), "implicit": (0, 1), "trapezoidal": (0.5, 0.5)}[integrator]
    rate = alpha * result.pressure
    step = scene.dt * (th_old * rate[:-1] + th_new * rate[1:])
    assert np.abs(np.diff(result.wear, axis=0) - step).max() < 1e-14
    assert np.abs(np.diff(result.wear_volume) - step @ result.weights).max() < 1e-15


def test_points_on_the_axis_neither_rub_nor_wear(box):
    """The axis through the free corner (1, 0) of Γ_C: that contact point gets α = 0, n* = 0, no wear."""
    scene = spun(box, 1.0, **{"foundation.center": [1.0, 0.0, 0.0], "foundation.angular_velocity": [0, 0, 2.0]})
    result = ngwear.simulate(scene, progress=False)
    corner = np.flatnonzero(np.linalg.norm(result.contact_points - [1.0, 0.0, 0.0], axis=1) < 1e-12)
    assert len(corner) == 1 and result.pressure[-1, corner[0]] > 0
    assert result.wear[:, corner[0]].max() == 0.0
    disc = result.discretization
    assert disc.contact.alpha(disc.contact.coefficients, 1.0)[corner[0]] == 0
    assert not disc.contact.motion.n_star(1.0)[corner[0]].any()
    others = np.delete(np.arange(len(result.weights)), corner)
    assert (result.wear[-1, others][result.pressure[-1, others] > 0] > 0).all()


def test_friction_direction_and_torque_of_a_pure_rotation(box):
    scene = spun(box, 1.0, **{"foundation.center": [0.5, -0.6, 0.0], "foundation.angular_velocity": [0, 0, 3.0],
                              "wear.integrator": "implicit"})
    result = ngwear.simulate(scene, progress=False)
    motion = Motion(scene, result.contact_points, scene.contact.direction)
    arms = result.contact_points - np.array([0.5, -0.6, 0.0])
    n_star = motion.n_star(1.0)
    assert np.allclose(np.linalg.norm(n_star, axis=1), 1.0)
    assert np.allclose(np.einsum("ij,ij->i", n_star, arms), 0.0, atol=1e-14)   # tangential to the circles
    assert np.allclose(np.cross(arms, n_star)[:, 2], -np.linalg.norm(arms[:, :2], axis=1))   # against ω
    expected = -scene.contact.friction * (result.pressure * np.linalg.norm(arms[:, :2], axis=1)) @ result.weights
    assert np.allclose(result.torque, expected, rtol=1e-13, atol=0) and (result.torque[1:] < 0).all()
    assert np.allclose(result.normal_force, (result.pressure + result.reaction) @ result.weights)


def test_speed_reversal_flips_the_friction_direction(box):
    scene = spun(box, 1.0, **{"foundation.speed_table": [[0.0, 1.0], [0.5, 1.0], [0.5001, -1.0], [1.0, -1.0]]})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed
    disc = result.discretization
    motion = disc.contact.motion
    assert np.array_equal(motion.n_star(motion.at(0.9).speed), -motion.n_star(motion.at(0.2).speed))
    assert np.sign(result.torque[2]) == -np.sign(result.torque[-1]) != 0


def test_full_system_agrees_on_a_rotating_counterface(box):
    scene = spun(box, 1.0, **{"foundation.center": [0.2, 0.1, 0.0], "time.steps": 4, "output.every": 1.0,
                              "wear.allow_unstable": True})         # the full path has explicit wear only
    fast = ngwear.simulate(scene, progress=False)
    full = ngwear.simulate(scene.replace(**{"solver.method": "full"}), progress=False)
    assert fast.completed and full.completed
    for name in ("normal_displacement", "wear", "pressure"):
        assert np.abs(getattr(fast, name) - getattr(full, name)).max() < 1e-9, name


def test_rotation_in_2d(paper_scene):
    """The strip on top of a wheel of radius 50 turning clockwise (ω = −1/50): close to the paper's translation."""
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 20, "output.every": 1.0})
    straight = ngwear.simulate(scene, progress=False)
    wheel = ngwear.simulate(scene.replace(**{"foundation.velocity": [0.0, 0.0], "foundation.angular_velocity": -0.02,
                                             "foundation.center": [1.5, -50.0]}),
                            discretization=straight.discretization, progress=False)
    assert wheel.completed
    assert np.abs(wheel.wear - straight.wear).max() < 0.05 * straight.wear.max()
    assert (wheel.torque[1:] < 0).all()


@pytest.mark.parametrize("changes, field, fragment", [
    ({"foundation.angular_velocity": 2.0}, "foundation.angular_velocity", "3 numbers in 3D"),
    ({"foundation.angular_velocity": [0, 1]}, "foundation.angular_velocity", "3 numbers"),
    ({"foundation.center": [1, 2]}, "foundation.center", "list of 3 numbers"),
    ({"foundation.velocity": [0, 0, 0], "foundation.angular_velocity": [1, 0, 0]}, "foundation.velocity",
     "tangential"),
])
def test_rotation_keys_are_validated(box, changes, field, fragment):
    with pytest.raises(ngwear.SceneError) as info:
        box.replace(**changes)
    message = str(info.value)
    assert message.startswith(f"{field}:") and fragment in message and "\n" not in message
