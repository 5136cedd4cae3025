"""The wear metrics against hand-computed values: thickness range, tapers, dissipated energy, per block, stops left."""
import math

import numpy as np
import pytest

from ngwear.results.metrics import (
    disc_taper,
    dissipated,
    friction_power,
    per_block,
    plane_slope,
    stops_to_limit,
    taper_along,
    thickness_range,
)


def sector(n=400, seed=1):
    """Points of the pad's face r = 0.10 … 0.15, |φ| ≤ 30°, with equal weights."""
    rng = np.random.default_rng(seed)
    r, phi = rng.uniform(0.10, 0.15, n), rng.uniform(-np.pi / 6, np.pi / 6, n)
    return r, phi, np.column_stack([r * np.cos(phi), r * np.sin(phi), np.zeros(n)]), np.full(n, 1.0 / n)


def test_thickness_range_is_weighted_by_area():
    assert thickness_range(np.array([1.0, 2.0, 4.0]), np.array([1.0, 1.0, 2.0])) == (1.0, 2.75, 4.0)


def test_best_fit_plane_slope():
    _, _, x, m = sector()
    values = 2.0 + 0.3 * x[:, 0] - 0.1 * x[:, 1]
    assert np.allclose(plane_slope(x, values, m, [0.0, 0.0, -1.0]), [0.3, -0.1, 0.0], atol=1e-12)
    x2 = x[:, :2]
    assert np.allclose(plane_slope(x2, 1.0 - 0.5 * x2[:, 0], m, [0.0, -1.0]), [-0.5, 0.0], atol=1e-12)


@pytest.mark.parametrize("turning", [1.0, -1.0])
def test_disc_taper_radial_and_from_leading_to_trailing(turning):
    """A field 5 + 2 (r − r_m) + 0.1 φ̃, φ̃ the angle in the disc's sense of turning.

    Radial 2·0.05, circumferential 0.1·(−60°): the disc enters the pad at φ̃ = −30°, whichever way it turns.
    """
    r, phi, x, m = sector()
    values = 5.0 + 2.0 * (r - 0.125) + 0.1 * turning * phi
    radial, circumferential = disc_taper(x, values, m, [0.0, 0.0, 0.0], [0.0, 0.0, 50.0 * turning])
    assert radial == pytest.approx(2.0 * np.ptp(r), rel=1e-12)
    assert circumferential == pytest.approx(-0.1 * np.ptp(phi), rel=1e-12)
    radial2d, circumferential2d = disc_taper(x[:, :2], values, m, [0.0, 0.0], 50.0 * turning)
    assert (radial2d, circumferential2d) == pytest.approx((radial, circumferential), rel=1e-12)


def test_taper_along_a_translating_counterface():
    x = np.column_stack([np.linspace(0.0, 2.0, 11), np.zeros(11)])
    assert taper_along(x, 1.0 + 0.5 * x[:, 0], np.ones(11), [3.0, 0.0]) == pytest.approx(-1.0)
    assert taper_along(x, 1.0 + 0.5 * x[:, 0], np.ones(11), [-3.0, 0.0]) == pytest.approx(1.0)


def test_dissipated_energy_of_a_stop_to_rest():
    """μ p ‖v‖ m with v falling linearly to rest over T = 2: P = 0.3 · 4 · 10 (1 − t/2) · 0.5, E = P(0) T / 2."""
    times = np.linspace(0.0, 2.0, 21)
    speeds = (10.0 * (1 - times / 2))[:, None] * np.ones((1, 2))
    power = friction_power(np.array([0.25, 0.25]), np.array([0.3, 0.3]), np.full((21, 2), 4.0), speeds)
    assert power[0] == pytest.approx(6.0) and dissipated(times, power) == pytest.approx(6.0, rel=1e-14)


def test_per_block_and_stops_to_the_limit():
    out = per_block(np.array([0, 0, 1]), np.array([1.0, 2.0, 4.0]), np.array([1e6, 1e6, 2e6]))
    assert list(out["stops"]) == [2, 1]
    assert np.allclose(out["volume_per_stop"], [1.5, 4.0]) and np.allclose(out["volume_per_megajoule"], [1.5, 2.0])
    remaining, rate = np.array([10.0, 8.0, 9.0]), np.array([0.1, 0.05, 0.0])
    assert stops_to_limit(remaining, 2.0, rate) == pytest.approx(80.0)
    assert stops_to_limit(remaining, 8.0, rate) == 0.0 and stops_to_limit(remaining, 2.0, np.zeros(3)) == math.inf
