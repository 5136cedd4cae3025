"""The heat's scene keys and their rules, and coefficients of state (T, p, v).

See ngwear/model/sections.py, rules.py, coefficients.py, expressions.py.
"""
import numpy as np
import pytest

from ngwear.model.coefficients import Coefficients, at_points, describe, state_of, stateful
from ngwear.model.scene import Scene, SceneError

THERMAL = {"conductivity": 1.0, "density": 2.0, "heat_capacity": 3.0}
HEATED = {"heat.model": "conduction", "heat.partition": 0.8, **{f"material.{k}": v for k, v in THERMAL.items()}}


@pytest.fixture(scope="module")
def strip():
    return Scene.from_dict({"geometry": {"kind": "strip", "size": [3.0, 1.0]}})


LAME = {"material.lame_lambda": 1.0, "material.lame_mu": 1.0}
"""[material]'s constants named: with regions a scene gets no default ones (the regions' tables are checked)."""


def refusal(scene, **dotted) -> str:
    with pytest.raises(SceneError) as err:
        scene.replace(**dotted)
    message = str(err.value)
    assert "\n" not in message
    return message


def test_defaults_are_no_heat(strip):
    """Without a [heat] table: no temperature, η unset, adiabatic, T₀ = T_∞ = 0; no thermal material constants."""
    assert strip.heat.model == "none" and strip.heat.partition is None and strip.heat.convection == ()
    assert strip.heat.start == strip.heat.ambient == 0.0
    assert strip.material.conductivity is None and strip.foundation.thermal_mass is None
    assert strip.replace(**{"heat.ambient": 20.0}).heat.start == 20.0
    assert strip.replace(**{"heat.ambient": 20.0, "heat.initial": 5.0}).heat.start == 5.0


def test_a_heated_scene_round_trips(strip):
    heated = strip.replace(**HEATED, **{"heat.convection": [{"boundary": "top", "coefficient": 12.5}],
                                        "foundation.thermal_mass": 4.0, "foundation.cooling": 0.5})
    assert heated.heat.convection[0].boundary == "top" and heated.heat.convection[0].coefficient == 12.5
    assert Scene.from_dict(heated.to_dict()) == heated
    assert heated.changed_from(strip).name == "NOTHING"       # the heat keys invalidate no piece of the elastic body


@pytest.mark.parametrize("dotted, message", [
    ({"heat.model": "conduction"}, "material.conductivity: missing (heat.model = 'conduction' needs conductivity, "
                                   "heat_capacity and density on every region)"),
    ({**HEATED, "heat.partition": None}, "heat.partition: missing"),
    ({**HEATED, "heat.partition": 1.5}, "heat.partition: must be a number in [0, 1] or 'effusivity' (got 1.5)"),
    ({**HEATED, "heat.partition": "half"}, "heat.partition: must be a number in [0, 1] or 'effusivity' (got 'half')"),
    ({**HEATED, "heat.partition": "effusivity"}, "foundation.conductivity: missing (heat.partition = 'effusivity'"),
    ({**HEATED, "heat.convection": [{"boundary": "contact", "coefficient": 1.0}]},
     "heat.convection[0].boundary: unknown, contact or repeated boundary 'contact' (allowed: left, right, top)"),
    ({**HEATED, "heat.convection": [{"boundary": "top", "coefficient": 1.0}, {"boundary": "top", "coefficient": 2}]},
     "heat.convection[1].boundary: unknown, contact or repeated boundary 'top' (allowed: left, right)"),
    ({**HEATED, "heat.convection": [{"boundary": "top", "coefficient": -1.0}]},
     "heat.convection[0].coefficient: must be a finite number >= 0 (got -1.0)"),
    ({**HEATED, "heat.convection": [{"boundary": "top"}]}, "heat.convection[0]: must be a table { boundary = NAME, "
                                                           "coefficient = h }"),
    ({**HEATED, "heat.convection": "top"}, "heat.convection: must be a list of tables { boundary, coefficient }"),
    ({**HEATED, "foundation.thermal_mass": 3.0}, "foundation.cooling: missing (a lumped counterface"),
    ({**HEATED, "foundation.cooling": 3.0}, "foundation.cooling: only with foundation.thermal_mass"),
    ({**HEATED, "foundation.thermal_mass": 3.0, "foundation.cooling": 1.0, "foundation.temperature": 20.0},
     "foundation.temperature: not with foundation.thermal_mass"),
    ({**HEATED, "foundation.temperature": [[0.0, 20.0], [0.5, 30.0]]},
     "foundation.temperature: must cover [0, time.T] = [0, 1.0] (got 0.0 to 0.5)"),
    ({**HEATED, "foundation.temperature": "hot"}, "foundation.temperature: must be a finite number or a table"),
    ({**HEATED, "foundation.thermal_mass": 0.0, "foundation.cooling": 1.0}, "foundation.thermal_mass: must be > 0"),
    ({"material.conductivity": -1.0}, "material.conductivity: must be > 0 (got -1.0)"),
    ({"contact.wear": "1e-3 * exp(T / 100)"}, "contact.wear: depends on the temperature T: needs heat.model = "
                                              "'conduction' (got 'none')"),
    ({"contact.friction": [[0.0, 0.4], [300.0, 0.3]]}, "contact.friction: depends on the temperature T"),
    ({"contact.friction": [[0.0, 0.4], [-300.0, 0.3]]}, "contact.friction: the temperatures of a table [[T, value], "
                                                        "…] must be finite and increasing (got [0.0, -300.0])"),
    ({"contact.stiffness": [[0.0, 4.0], [300.0, 0.0]]}, "contact.stiffness: the values of a table [[T, value], …] "
                                                        "must be finite and > 0 (got 0 at T = 300)"),
    ({"contact.friction": "0.4 - q"}, "contact.friction: unknown name 'q'"),
])
def test_refusals_name_the_key(strip, dotted, message):
    assert refusal(strip, **dotted).startswith(message)


def test_thermal_keys_per_region(strip):
    """A region takes [material]'s thermal keys, its own override them, also where it replaces the law."""
    backed = strip.replace(**HEATED, **{"geometry.backing": 0.2, **LAME, "material.regions": {"backing": {
        "young": 210e3, "poisson": 0.3, "conductivity": 50.0, "expansion": 1.2e-5}}})
    tables = backed.material.by_region(("body", "backing"))
    assert tables["backing"].conductivity == 50.0 and tables["backing"].density == 2.0
    assert tables["backing"].young == 210e3 and tables["backing"].lame_mu is None   # its own law, [material]'s heat
    assert tables["body"].conductivity == 1.0 and tables["body"].expansion is None
    heated = {"heat.model": "conduction", "heat.partition": 1.0, "geometry.backing": 0.2}
    assert refusal(strip, **heated, **LAME, **{"material.regions": {"body": THERMAL}}).startswith(
        "material.conductivity: missing")                          # the backing takes [material]'s: none
    backing = {"material.regions": {"body": THERMAL, "backing": {"density": 1.0}}}
    assert refusal(strip, **heated, **LAME, **backing).startswith("material.regions.backing.conductivity: missing")


POINTS = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
STATE = {"T": np.array([100.0, 300.0, 500.0]), "p": np.array([0.0, 1.0, 2.0]), "v": np.array([3.0, 3.0, 4.0])}


def test_expressions_of_the_state():
    wear = "8e-13 * (1 + exp((T - 300) / 40))"
    assert state_of(wear, "wear") == {"T"} and state_of("x * p + v", "friction") == {"p", "v"}
    assert state_of("x + pi", "friction") == set() and state_of(0.3, "friction") == set()
    assert np.array_equal(at_points(wear, "wear", POINTS, STATE), 8e-13 * (1 + np.exp((STATE["T"] - 300) / 40)))
    friction = at_points("0.42 - 0.0004 * max(T - 250, 0) + 0.01 * p * v + 0 * x", "friction", POINTS, STATE)
    assert np.allclose(friction, 0.42 - 0.0004 * np.maximum(STATE["T"] - 250, 0) + 0.01 * STATE["p"] * STATE["v"],
                       rtol=1e-15)


def test_a_table_of_the_temperature_is_piecewise_linear_and_constant_beyond_its_ends(strip):
    table = strip.replace(**HEATED, **{"contact.friction": [[200, 0.4], [400, 0.2], [600, 0.3]]}).contact.friction
    assert table == ((200.0, 0.4), (400.0, 0.2), (600.0, 0.3)) and state_of(table, "friction") == {"T"}
    temperatures = np.array([0.0, 200.0, 300.0, 500.0, 900.0])
    values = at_points(table, "friction", np.zeros((5, 2)), {"T": temperatures})
    assert np.allclose(values, [0.4, 0.4, 0.3, 0.25, 0.3], rtol=1e-15)
    assert describe(table) == "a table of T, values in [0.2, 0.4]"


def test_a_value_out_of_range_is_refused_with_the_point_the_state_and_the_time():
    with pytest.raises(SceneError) as err:
        at_points("0.42 - 0.001 * T", "friction", POINTS, STATE, t=2.5)
    assert str(err.value) == ("contact.friction: must be >= 0 at every contact point (got -0.08 at (2, 0) with "
                              "T = 500, p = 2, v = 4 at t = 2.5)")
    with pytest.raises(SceneError, match=r"^contact.wear: must be finite at every contact point \(got inf"):
        at_points("exp(10 * T)", "wear", POINTS, STATE)
    with pytest.raises(SceneError, match=r"^contact.stiffness: must be > 0 .*got 0 at \(0, 0\) with T = 100"):
        at_points("10 * p", "stiffness", POINTS, STATE)


def test_coefficients_of_state_are_evaluated_each_step_the_fixed_ones_kept(strip):
    contact = strip.replace(**HEATED, **{"contact.friction": "0.5 - 0.0005 * T", "contact.wear": 0.01,
                                         "contact.stiffness": "10 + x"}).contact
    assert stateful(contact) == ("friction",)
    with pytest.raises(SceneError, match=r"^contact.friction: depends on the state \(T\): evaluated with the state "):
        Coefficients.of(contact, POINTS)
    first = Coefficients.of(contact, POINTS, STATE)
    later = first.updated(contact, POINTS, {**STATE, "T": STATE["T"] + 100}, t=1.0)
    assert later.wear is first.wear and later.stiffness is first.stiffness       # no cost for the fixed ones
    assert np.allclose(later.friction, 0.5 - 0.0005 * (STATE["T"] + 100), rtol=1e-15)
    fixed = strip.contact
    assert stateful(fixed) == () and Coefficients.of(fixed, POINTS).updated(fixed, POINTS, STATE).friction is not None


@pytest.mark.parametrize("dotted, fragment", [
    ({"heat.interface": "conductance"}, "heat.contact_conductance: missing (heat.interface = 'conductance' needs"),
    ({"heat.contact_conductance": 5.0}, "heat.contact_conductance: only with heat.interface = 'conductance'"),
    ({"heat.interface": "conductance", "heat.contact_conductance": -1.0}, "heat.contact_conductance: must be >= 0"),
    ({"heat.interface": "bonded", "heat.contact_conductance": 1.0}, "heat.interface: must be one of partition, "),
])
def test_the_contact_conductance_comes_with_its_interface(strip, dotted, fragment):
    assert refusal(strip, **HEATED, **dotted).startswith(fragment)


def test_the_conductance_interface_splits_half_and_half_unless_told(strip):
    from ngwear.model.thermal import partition
    given = {k: v for k, v in HEATED.items() if k != "heat.partition"}
    scene = strip.replace(**given, **{"heat.interface": "conductance", "heat.contact_conductance": 1e4})
    assert scene.heat.partition is None and partition(scene, ["body"]) == 0.5
    assert partition(scene.replace(**{"heat.partition": 0.8}), ["body"]) == 0.8
