"""The generalised Archard law ``contact.wear_law = "power"``: w' = κ ‖v*‖^a p^b, ``contact.wear_exponents = [a, b]``.

A column pressed by a plate with the force F on a translating counterface (μ small: the pressure p = F/A is uniform)
wears uniformly at w' = κ v^a (F/A)^b; the scheme's nodal update is that rate at every step and point, the
exponents [1, 1] are Archard's law to the bit, and the stability slope is κ v^a b p(g)^(b−1) L.
"""
import numpy as np
import pytest

import ngwear
from ngwear.model.scene import Scene, SceneError
from ngwear.numerics.discrete import Discretization

SPEED, FORCE, WIDTH, KAPPA = 2.0, 0.2, 0.2, 0.01


def column(**changes) -> Scene:
    scene = Scene.from_dict({
        "geometry": {"kind": "strip", "size": [WIDTH, 1.0], "dirichlet": []}, "mesh": {"maxh": 0.05},
        "material": {"lame_lambda": 0.0, "lame_mu": 1000.0},
        "contact": {"law": "linear", "stiffness": 100.0, "gap": 0.5, "friction": 1e-3, "wear": KAPPA,
                    "direction": [0.0, -1.0], "wear_law": "power", "wear_exponents": [1.5, 2.0]},
        "foundation": {"velocity": [SPEED, 0.0]},
        "loads": {"plate": {"boundary": "top", "force": [0.0, -FORCE]}},
        "wear": {"integrator": "implicit"},
        "time": {"T": 1.0, "steps": 10}})
    return scene.replace(**changes) if changes else scene


@pytest.mark.parametrize("a, b", [(1.5, 2.0), (0.5, 1.0), (2.0, 3.0)])
def test_the_column_wears_at_kappa_v_to_the_a_p_to_the_b(a, b):
    result = ngwear.simulate(column(**{"contact.wear_exponents": [a, b]}), progress=False)
    assert result.completed
    p = result.pressure
    assert np.ptp(p[1:]) < 2e-3 * p.max()                               # uniform, F/A
    increments = np.diff(result.wear, axis=0)
    assert np.allclose(increments, 0.1 * KAPPA * SPEED ** a * p[1:] ** b, rtol=1e-12, atol=0)   # implicit: p_{j+1}
    expected = KAPPA * SPEED ** a * (FORCE / WIDTH) ** b * WIDTH * result.times
    assert np.allclose(result.wear_volume, expected, rtol=3e-3 * b, atol=0)


def test_exponents_one_and_one_are_archards_law_to_the_bit():
    power = ngwear.simulate(column(**{"contact.wear_exponents": [1.0, 1.0]}), progress=False)
    archard = ngwear.simulate(column(**{"contact.wear_law": "archard", "contact.wear_exponents": [1.0, 1.0]}),
                              progress=False)
    for name in ("wear", "pressure", "normal_displacement"):
        assert np.array_equal(getattr(power, name), getattr(archard, name)), name


def test_the_stability_slope_is_the_rates_largest_derivative_over_the_layer():
    """K α g'(p(g)) L with α = κ v^a, g' = b p^(b−1), p(g) = L g: the explicit update is refused beyond 2."""
    scene = column(**{"wear.integrator": "explicit", "wear.allow_unstable": True})
    rate = Discretization(scene).contact.largest_rate()
    L, g = 100.0, 0.5
    assert rate == pytest.approx(KAPPA * SPEED ** 1.5 * 2.0 * (L * g) ** 1.0 * L, rel=1e-12)
    with pytest.raises(SceneError, match=r"^time\.steps: explicit wear with k·α·L = 28\.3 > 2 diverges"):
        ngwear.simulate(column(**{"wear.integrator": "explicit"}), progress=False)


@pytest.mark.parametrize("changes, message", [
    ({"contact.wear_exponents": [1.0, 0.5]}, "contact.wear_exponents: b must be in [1, 4] (got [1.0, 0.5])"),
    ({"contact.wear_exponents": [5.0, 1.0]}, "contact.wear_exponents: a must be in [0, 4] (got [5.0, 1.0])"),
    ({"contact.wear_exponents": [1.0]}, "contact.wear_exponents: must be [a, b], two numbers (got [1.0])"),
    ({"contact.wear_law": "archard"}, "contact.wear_exponents: only with contact.wear_law = 'power' (got [1.5, 2.0] "
                                      "with contact.wear_law = 'archard')"),
])
def test_exponents_out_of_range_are_one_line_naming_the_key(changes, message):
    with pytest.raises(SceneError) as err:
        column(**changes)
    assert str(err.value) == message
