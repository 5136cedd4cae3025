"""Wear by frictional work, ``contact.wear_law = "energy"``: w' = κ_E μ p ‖v*‖, the worn volume κ_E × the energy.

With the trapezoidal integrator the worn volume is κ_E times the dissipated energy (both the trapezoidal rule over the
same steps) to round-off, wherever μ and the slip vary; without friction nothing wears; with μ a field of x the wear
follows μ.
"""
import numpy as np
import pytest

import ngwear

KAPPA = 2e-2


def scene(**changes):
    return ngwear.load_scene("paper_strip").replace(**{
        "mesh.maxh": 0.2, "time.steps": 20, "contact.wear_law": "energy", "contact.wear": KAPPA,
        "wear.integrator": "trapezoidal", **changes})


@pytest.mark.parametrize("friction", [1.0, "0.4 + 0.2 * x"])
def test_the_worn_volume_is_kappa_times_the_dissipated_energy(friction):
    result = ngwear.simulate(scene(**{"contact.friction": friction}), progress=False)
    assert result.completed and result.wear_volume[-1] > 0
    assert np.allclose(result.wear_volume, KAPPA * result.dissipated_energy, rtol=1e-12,
                       atol=1e-12 * result.wear_volume[-1])


def test_no_friction_no_wear():
    result = ngwear.simulate(scene(**{"contact.friction": 0.0}), progress=False)
    assert result.completed and not result.wear.any() and result.pressure.max() > 0


def test_the_wear_rate_follows_mu_point_by_point():
    """At the first step the nodal increment is k/2 κ_E μ_i p_i v (both ends at its start: the rate at t₁ too)."""
    result = ngwear.simulate(scene(**{"contact.friction": "0.4 + 0.2 * x"}), progress=False)
    mu = result.friction_coefficient
    step = result.times[1] - result.times[0]
    rates = KAPPA * mu * result.pressure[:2] * 1.0                       # v = 1 along the strip
    assert np.allclose(result.wear[1], step / 2 * (rates[0] + rates[1]), rtol=1e-12, atol=1e-15)
    assert np.ptp(mu) > 0.5 and (result.wear[1] > 0).sum() > 5
