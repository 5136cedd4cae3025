"""Running-in of real parts against the machine-design theory of wear (disc brakes, clutches, pin-on-disc).

Pad: a brake pad pressed by a rigid plate onto a disc turning at ω.  A new pad presses almost
uniformly (the layer is much softer than the pad), so the friction torque starts at the uniform-
pressure value (2/3) μ F (r_o³ − r_i³)/(r_o² − r_i²).  Once worn in, every point in contact wears at
the plate's speed δ', κ ω r p = δ': p·r is constant over the face and the torque is
μ F Σm / Σ(m/r) exactly (nodal quadrature of ∫dA / ∫dA/r), which tends to the uniform-wear value
μ F (r_i + r_o)/2 as O(h²): the vertex rule integrates 1/r with a relative error ≲ h²/(6 r_i²).
The transient decays like exp(−κ ω r L t) (the layer's wear law linearised about the worn-in state).

Pin: the worn volume grows at Σ m κ ω r p; in the steady state p·r = const, so the rate is
κ ω F R_eff with R_eff = Σm / Σ(m/r) = R (1 − a²/(8R²) + …) for a pin of radius a at radius R:
Archard's κ ω R F to 0.13 % at a/R = 0.1.  A spherical end wears a growing flat and gets there too.
"""
import numpy as np
import pytest

import ngwear

RI, RO, MU = 0.3, 1.0, 0.3
AREA = np.pi / 3 * (RO ** 2 - RI ** 2) / 2


def pad(maxh):
    return ngwear.Scene.from_dict({
        "name": "running_in", "geometry": {"kind": "pad", "size": [RI, RO, 60.0, 0.1], "dirichlet": []},
        "mesh": {"maxh": maxh}, "material": {"young": 1000.0, "poisson": 0.3},
        "contact": {"stiffness": 50.0, "gap": 0.5, "friction": MU, "wear": 0.15},
        "foundation": {"velocity": [0, 0, 0], "angular_velocity": [0, 0, 1.0]},
        "loads": {"plate": {"boundary": "back", "force": [0, 0, -AREA]}},
        "time": {"T": 4.0, "steps": 100}, "wear": {"integrator": "trapezoidal"}})


def radius(result):
    return np.linalg.norm(result.contact_points[:, :2], axis=1)


@pytest.fixture(scope="module")
def worn_in():
    return ngwear.simulate(pad(0.08), progress=False)


def test_pad_torque_goes_from_uniform_pressure_to_uniform_wear(worn_in):
    r, force = worn_in, AREA
    assert r.completed and (r.pressure > 0).all(), "the whole face stays in contact"
    uniform_pressure = 2 / 3 * MU * force * (RO ** 3 - RI ** 3) / (RO ** 2 - RI ** 2)
    uniform_wear = MU * force * (RI + RO) / 2
    braking = -r.torque
    assert braking[0] == pytest.approx(uniform_pressure, rel=1e-3)      # layer 200× softer than the pad
    assert (np.diff(braking) < 0).all(), "the torque falls monotonically while the pad wears in"
    discrete = MU * force * r.weights.sum() / (r.weights / radius(r)).sum()
    pr = r.pressure[-1] * radius(r)
    assert braking[-1] == pytest.approx(discrete, rel=np.std(pr) / np.mean(pr))   # up to the transient left
    h = r.scene.mesh.maxh
    assert abs(braking[-1] - uniform_wear) <= h ** 2 / (6 * RI ** 2) * uniform_wear


def test_pad_wears_in_to_constant_pressure_times_radius(worn_in):
    r = worn_in
    spread = [np.std(r.pressure[j] * radius(r)) / np.mean(r.pressure[j] * radius(r)) for j in (0, 25, 50, 100)]
    assert spread[0] > 0.2                                     # new: p nearly uniform, p·r ∝ r
    assert spread[1] < 0.02 and spread[2] < 2e-3 and spread[3] < 1e-4
    assert spread[1] / spread[2] > 5                           # exponential decay
    assert r.wear.max() < r.scene.contact.gap                  # never worn through


def test_pad_torque_converges_in_h_at_second_order(worn_in):
    fine = ngwear.simulate(pad(0.04), progress=False)
    errors = [abs(-r.torque[-1] - MU * AREA * (RI + RO) / 2) for r in (worn_in, fine)]
    assert errors[0] / errors[1] > 3.0


@pytest.mark.parametrize("end", ["flat", "sphere"])
def test_pin_wears_at_the_archard_rate(end):
    kappa, omega, R, F, a = 0.01, 1.0, 1.0, 0.05, 0.1
    geometry = {"kind": "pin", "size": [a, 0.3], "position": [R, 0.0], "dirichlet": [], "end": end}
    if end == "sphere":
        geometry["end_radius"] = 0.3
    scene = ngwear.Scene.from_dict({
        "geometry": geometry, "mesh": {"maxh": 0.05, "contact_maxh": 0.02},
        "material": {"young": 1e4, "poisson": 0.3},
        "contact": {"stiffness": 1000.0, "gap": 0.1, "friction": 0.5, "wear": kappa},
        "foundation": {"velocity": [0, 0, 0], "angular_velocity": [0, 0, omega]},
        "loads": {"plate": {"boundary": "back", "force": [0, 0, -F]}},
        "time": {"T": 2.0, "steps": 100}, "wear": {"integrator": "implicit"}})
    r = ngwear.simulate(scene, progress=False)
    assert r.completed and r.wear.max() < scene.contact.gap
    rate = np.diff(r.wear_volume) / scene.dt
    archard = kappa * omega * R * F
    effective = r.weights.sum() / (r.weights / radius(r)).sum()
    assert effective == pytest.approx(R * (1 - a ** 2 / (8 * R ** 2)), rel=2e-4)
    assert rate[-1] == pytest.approx(archard * effective / R, rel=1e-6)      # steady state, exactly
    assert rate[-1] == pytest.approx(archard, rel=2e-3)                      # Archard, to (a/R)²/8
    if end == "sphere":                                                      # a flat grows on the cap
        assert r.contact_area[0] < 0.6 * r.weights.sum() and r.contact_area[-1] == pytest.approx(r.weights.sum())
