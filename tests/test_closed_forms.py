"""The closed forms of a part's life (ngwear.studies.closed_forms), and today's ``layer`` mode against them.

The forms: the worn-in pad's pressure carries the force, the taper's pressure the force and the friction couple,
Argatov's flat the worn volume of a spherical cap.  Layer mode, while the layer lasts: the shipped brake pad (a
plate pressing it onto a disc) wears in to p·r = const, the torque μF(r_i + r_o)/2 and a uniform wear rate; a
rectangular pad (per unit width, plane strain) under a tilting plate on a translating counterface wears in to the
linear pressure F/A + (μFh/I)ξ and a plate turning at κ‖v*‖μFh/I.  Both differ from the closed forms by the
nodal quadrature only (Σm/Σ(m/r) for ∫dA/∫dA/r, Σ m ξ² for I: O(h²)).  Surface mode, far beyond the layer: the
shipped pin's spherical end wears flat as Argatov's law says, where layer mode stops wearing at g.
"""
import math

import numpy as np
import pytest
from conftest import ROOT
from scipy.integrate import quad

import ngwear
from ngwear.results.metrics import contact_radius
from ngwear.runs.validity import WORN
from ngwear.studies.closed_forms import (
    rectangle_inertia,
    taper_pressure,
    tilt_rate,
    uniform_pressure_torque,
    uniform_wear_pressure,
    uniform_wear_rate,
    uniform_wear_torque,
    worn_flat_radius,
)


def test_the_forms_balance_their_loads():
    inner, outer, angle, force, mu = 0.1, 0.15, math.pi / 3, 3000.0, 0.4
    carried = quad(lambda r: angle * r * uniform_wear_pressure(force, r, inner, outer, angle), inner, outer)[0]
    torque = quad(lambda r: angle * r * r * mu * uniform_wear_pressure(force, r, inner, outer, angle), inner, outer)[0]
    assert carried == pytest.approx(force) and torque == pytest.approx(uniform_wear_torque(mu, force, inner, outer))
    uniform = quad(lambda r: angle * r * r * mu * force / (angle * (outer ** 2 - inner ** 2) / 2), inner, outer)[0]
    assert uniform == pytest.approx(uniform_pressure_torque(mu, force, inner, outer))
    a, b, h = 1.0, 0.5, 0.25
    p = lambda xi: taper_pressure(force, a, b, mu, h, xi)  # noqa: E731
    assert b * quad(p, -a / 2, a / 2)[0] == pytest.approx(force)
    assert b * quad(lambda xi: p(xi) * xi, -a / 2, a / 2)[0] == pytest.approx(mu * force * h), "the friction couple"


def test_argatov_flat_holds_the_archard_volume():
    """A flat of radius a on a sphere R ≫ a takes the cap π a⁴/(4R): with a₀ = 0 it is Archard's κFs."""
    kappa, force, distance, radius = 1e-13, 10.0, 500.0, 5e-3
    a = worn_flat_radius(0.0, kappa, force, distance, radius)
    height = radius - math.sqrt(radius ** 2 - a ** 2)
    cap = math.pi * height ** 2 * (3 * radius - height) / 3
    assert cap == pytest.approx(kappa * force * distance, rel=(a / radius) ** 2)
    assert worn_flat_radius(2e-4, kappa, force, 0.0, radius) == 2e-4


def test_the_shipped_pad_wears_in_to_uniform_wear():
    """The shipped brake pad (150 s, its layer 1 mm, 0.36 mm worn): torque μF(r_i + r_o)/2, uniform wear rate."""
    scene = ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml").replace(**{"output.every": 150.0})
    result = ngwear.simulate(scene, progress=False)
    inner, outer, angle = 0.10, 0.15, math.pi / 3
    force, mu, kappa, omega = 3000.0, 0.4, 8e-13, 50.0
    assert result.completed and result.wear.max() < 0.5 * scene.contact.gap, "the layer lasts"
    braking = -result.torque
    assert braking[0] == pytest.approx(uniform_pressure_torque(mu, force, inner, outer), rel=1e-3)
    assert braking[-1] == pytest.approx(uniform_wear_torque(mu, force, inner, outer), rel=1e-3)
    rate = (result.wear[-1] - result.wear[-11]) / (result.times[-1] - result.times[-11])
    m = result.weights
    mean = m @ rate / m.sum()
    assert np.ptp(rate) < 0.01 * mean, "a wear rate uniform over the face"
    assert mean == pytest.approx(uniform_wear_rate(kappa, omega, force, inner, outer, angle), rel=1e-3)


def test_a_pad_under_a_tilting_plate_wears_in_to_the_taper():
    """A 1 × 0.25 pad per unit width, μ = 0.3, under a tilting plate on its top (h = 0.25), worn in 10 τ."""
    a, h, force, mu, kappa, speed = 1.0, 0.25, 0.1, 0.3, 0.1, 1.0
    scene = ngwear.Scene.from_dict({
        "name": "taper", "geometry": {"kind": "strip", "size": [a, h], "dirichlet": []},
        "mesh": {"maxh": 0.05}, "material": {"young": 100.0, "poisson": 0.3},
        "contact": {"stiffness": 10.0, "gap": 0.2, "friction": mu, "wear": kappa},
        "foundation": {"velocity": [speed, 0.0]},
        "loads": {"plate": {"boundary": "top", "force": [0.0, -force], "tilt": True}},
        "time": {"T": 10.0, "steps": 100}, "wear": {"integrator": "trapezoidal"}, "output": {"every": 10.0}})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed and result.wear.max() < scene.contact.gap
    xi = a / 2 - result.contact_points[:, 0]                    # towards the leading edge: the foundation enters at 0
    pressure = result.pressure[-1]
    slope, mean = np.polyfit(xi, pressure, 1)
    assert np.abs(pressure - (mean + slope * xi)).max() < 1e-4 * mean, "worn in: an affine pressure"
    assert mean == pytest.approx(force / a, rel=1e-6)
    assert slope == pytest.approx((taper_pressure(force, a, 1.0, mu, h, 1.0) - force / a), rel=0.01)
    m = result.weights
    assert slope == pytest.approx(mu * force * h / (m @ xi ** 2), rel=1e-6), "exactly, with the nodal inertia"
    tilt = result.plate_displacement[:, 1]
    turning = (tilt[-1] - tilt[-11]) / (result.times[-1] - result.times[-11])
    assert abs(turning) == pytest.approx(tilt_rate(kappa, speed, mu, force, h, a, 1.0), rel=0.01)
    assert rectangle_inertia(a, 1.0) == pytest.approx(1 / 12)


@pytest.mark.slow
def test_a_sphere_wears_flat_far_beyond_its_layer_as_argatov_says():
    """The pin's 5 mm sphere, a 10 µm layer, worn 13 g in ``"surface"`` mode: a⁴ = a₀⁴ + 4κFsR/π within 5 % for s ≥ 4s₀.

    s₀ is where the measured contact radius reaches 2a₀ (the Hertzian start is not a flat: Argatov's law holds once
    the flat is most of the contact).  In ``"layer"`` mode the same scene's wear stops at g, and the run says so.
    """
    scene = ngwear.load_scene(ROOT / "geometries" / "pin_on_disc.toml").replace(**{
        "contact.gap": 1e-5, "contact.stiffness": 1e12, "mesh.contact_maxh": 1e-4, "mesh.contact_zone": 1.5e-3,
        "time.T": 150.0, "time.steps": 300, "wear.integrator": "trapezoidal", "wear.geometry": "surface",
        "wear.update": 0.5, "output.every": 150.0})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed and result.total_wear[-1].max() > 10 * scene.contact.gap, "worn far beyond the layer"
    assert result.geometry_updates > 10
    distance = scene.foundation.angular_velocity[2] * scene.geometry.position[0] * result.times
    force, radius, kappa = -scene.loads.plate.force[2], scene.geometry.end_radius, scene.contact.wear
    radii = np.array([contact_radius(m, p, r) for m, p, r in zip(result.row_weights, result.pressure,
                                                                     result.reaction, strict=True)])
    s0 = distance[np.argmax(radii >= 2 * radii[0])]
    assert 0 < s0 < distance[-1] / 4, "the flat doubles the Hertzian radius early in the run"
    late = distance >= 4 * s0
    argatov = np.array([worn_flat_radius(radii[0], kappa, force, s, radius) for s in distance[late]])
    assert np.abs(radii[late] / argatov - 1).max() < 0.05

    layer = ngwear.simulate(scene.replace(**{"wear.geometry": "layer", "time.T": 30.0, "time.steps": 60,
                                             "output.every": 30.0}), progress=False)
    g = scene.contact.gap
    assert (1 - 0.02) * g < layer.wear.max() <= g, "the layer mode's wear stops at g"
    assert any(warning.startswith(WORN) for warning in layer.warnings), "and the run says the layer is worn through"
