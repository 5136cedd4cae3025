"""Closed forms of a part's life: uniform wear on a disc, the taper under a tilting plate, a sphere wearing flat.

**Uniform wear** (a pad r_i ≤ r ≤ r_o, |φ| ≤ θ/2 on a disc turning at ω, pressed by a rigid plate with F).  Worn in,
every point in contact wears at the plate's speed, κ ω r p = δ': p·r is constant over the face,

    p = F / (θ r (r_o − r_i)),     torque T = μ F (r_i + r_o) / 2,     δ' = κ ω F / (θ (r_o − r_i)),

against a new pad's uniform pressure F/A and its torque (2/3) μ F (r_o³ − r_i³)/(r_o² − r_i²).

**Taper** (a rectangular pad, face a × b with a along v*, on a counterface translating at ‖v*‖, under a plate on its
back that tilts freely, the back's centroid h above the face).  The friction μF at the face and its reaction at the
plate make a couple the pressure must balance, Σ m p (x − x_c) = −μ F h.  Worn in, the worn face follows the rigid
plate, so the wear rate κ‖v*‖p is affine and so is p:

    p = F/A + (μ F h / I) ξ,    I = b a³ / 12,    ξ the distance from the centre towards the leading edge,

and the plate turns (the leading edge rising into the pad) at the constant rate κ ‖v*‖ μ F h / I.

**A sphere wearing flat** (radius R, force F, sliding distance s; Argatov, Wear 2011): the contact radius a of the
worn flat, from its Hertzian a₀, grows as a⁴ = a₀⁴ + 4 κ F s R / π.
"""
from __future__ import annotations

import math


def uniform_pressure_torque(mu: float, force: float, inner: float, outer: float) -> float:
    """(2/3) μ F (r_o³ − r_i³)/(r_o² − r_i²): the friction torque of a uniform pressure (a new pad)."""
    return 2 / 3 * mu * force * (outer ** 3 - inner ** 3) / (outer ** 2 - inner ** 2)


def uniform_wear_torque(mu: float, force: float, inner: float, outer: float) -> float:
    """μ F (r_i + r_o)/2: the friction torque of a worn-in pad, p·r constant."""
    return mu * force * (inner + outer) / 2


def uniform_wear_pressure(force: float, radius, inner: float, outer: float, angle: float):
    """The pressure F / (θ r (r_o − r_i)) at the radius r of a worn-in pad of angle θ (radians)."""
    return force / (angle * radius * (outer - inner))


def uniform_wear_rate(kappa: float, omega: float, force: float, inner: float, outer: float, angle: float) -> float:
    """δ' = κ ω F / (θ (r_o − r_i)): the speed at which a worn-in pad's every point wears (and its plate moves)."""
    return kappa * omega * force / (angle * (outer - inner))


def rectangle_inertia(along: float, across: float) -> float:
    """I = b a³/12 of a face a (along the sliding) × b."""
    return across * along ** 3 / 12


def taper_pressure(force: float, along: float, across: float, mu: float, height: float, xi):
    """The worn-in pressure F/A + (μ F h / I) ξ, ξ from the face's centre towards the leading edge."""
    return force / (along * across) + mu * force * height / rectangle_inertia(along, across) * xi


def tilt_rate(kappa: float, speed: float, mu: float, force: float, height: float, along: float,
              across: float) -> float:
    """κ ‖v*‖ μ F h / I: the rate at which the worn-in pad's plate turns."""
    return kappa * speed * mu * force * height / rectangle_inertia(along, across)


def worn_flat_radius(start: float, kappa: float, force: float, distance: float, radius: float) -> float:
    """(a₀⁴ + 4 κ F s R / π)^(1/4): the radius of a sphere's worn flat after sliding ``distance`` (Argatov)."""
    return (start ** 4 + 4 * kappa * force * distance * radius / math.pi) ** 0.25
