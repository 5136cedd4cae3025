"""Scene loading and validation: malformed scenes fail with one-line messages naming the field."""
import json
import math
from pathlib import Path

import pytest
from pydantic import ValidationError

from ngwear.model.scene import Scene, SceneError, load_scene, parse_override

PAPER = Path(__file__).resolve().parents[1] / "geometries" / "paper_strip.toml"

BASE = """\
name = "base"

[geometry]
kind = "strip"
size = [3.0, 1.0]
dirichlet = ["left"]

[mesh]
maxh = 0.5
order = 1

[material]
lame_lambda = 1.0
lame_mu = 1.0

[contact]
gap = 0.2
friction = 1.0
wear = 1.5
direction = [0.0, -1.0]

[foundation]
velocity = [1.0, 0.0]

[loads]
traction = { top = [0.0, -0.1], right = [0.0, -0.1] }

[time]
T = 1.0
steps = 10

[wear]
integrator = "explicit"
"""


def edit(*pairs: str) -> str:
    """BASE with each ``old`` line replaced by ``new`` (pairs old, new, old, new, ...)."""
    text = BASE
    for old, new in zip(pairs[::2], pairs[1::2]):
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return text


def load_text(tmp_path, text: str) -> Scene:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return load_scene(path)


def check_message(err: SceneError, field: str, allowed: str) -> None:
    msg = str(err)
    assert "\n" not in msg, msg
    assert msg.startswith(f"{field}:"), msg
    assert allowed in msg, msg


# (id, TOML text, dotted field the message must start with, fragment stating what is allowed)
TOML_CASES = [
    ("gap-zero", edit("gap = 0.2", "gap = 0.0"), "contact.gap", "> 0"),
    ("gap-negative", edit("gap = 0.2", "gap = -0.1"), "contact.gap", "> 0"),
    ("friction-negative", edit("friction = 1.0", "friction = -1.0"), "contact.friction", ">= 0"),
    ("wear-negative", edit("wear = 1.5", "wear = -0.5"), "contact.wear", ">= 0"),
    ("stiffness-zero", edit("gap = 0.2", "gap = 0.2\nstiffness = 0"), "contact.stiffness", "> 0"),
    ("steps-zero", edit("steps = 10", "steps = 0"), "time.steps", "[1, 1000000]"),
    ("steps-fraction", edit("steps = 10", "steps = 2.5"), "time.steps", "whole number in [1, 1000000]"),
    ("steps-string", edit("steps = 10", 'steps = "ten"'), "time.steps", "whole number in [1, 1000000]"),
    ("steps-bool", edit("steps = 10", "steps = true"), "time.steps", "whole number in [1, 1000000]"),
    ("T-zero", edit("T = 1.0", "T = 0.0"), "time.T", "> 0"),
    ("T-negative", edit("T = 1.0", "T = -1"), "time.T", "> 0"),
    ("T-inf", edit("T = 1.0", "T = inf"), "time.T", "finite number > 0"),
    ("maxh-zero", edit("maxh = 0.5", "maxh = 0"), "mesh.maxh", "in (0, 3.0]"),
    ("maxh-negative", edit("maxh = 0.5", "maxh = -0.1"), "mesh.maxh", "in (0, 3.0]"),
    ("maxh-nan", edit("maxh = 0.5", "maxh = nan"), "mesh.maxh", "finite number in (0, 3.0]"),
    ("order-3", edit("order = 1", "order = 3"), "mesh.order", "in [1, 2]"),
    ("unknown-section", BASE + "\n[postprocess]\nplot = true\n", "postprocess", "allowed: name, units, geometry"),
    ("unknown-key", edit("gap = 0.2", "gap = 0.2\ngapp = 0.3"), "contact.gapp", "allowed: law, stiffness"),
    ("unknown-key-top-level", "title = 'x'\n" + BASE, "title", "allowed: name, units, geometry"),
    ("traction-unknown-boundary", edit("top = [0.0, -0.1]", "bottom = [0.0, -0.1]"),
     "loads.traction.bottom", "allowed: right, top"),
    ("traction-on-contact", edit("top = [0.0, -0.1]", "contact = [0.0, -0.1]"),
     "loads.traction.contact", "allowed: right, top"),
    ("traction-on-dirichlet", edit("top = [0.0, -0.1]", "left = [0.0, -0.1]"),
     "loads.traction.left", "allowed: right, top"),
    ("traction-wrong-length", edit("top = [0.0, -0.1]", "top = [0.0, -0.1, 0.0]"),
     "loads.traction.top", "list of 2 numbers"),
    ("traction-not-table", edit("traction = { top = [0.0, -0.1], right = [0.0, -0.1] }",
                                "traction = [0.0, -0.1]"), "loads.traction", "table of boundary"),
    ("dirichlet-unknown", edit('dirichlet = ["left"]', 'dirichlet = ["bottom"]'),
     "geometry.dirichlet", "allowed: left, right, top"),
    ("dirichlet-contact", edit('dirichlet = ["left"]', 'dirichlet = ["contact"]'),
     "geometry.dirichlet", "allowed: left, right, top"),
    ("dirichlet-empty", edit('dirichlet = ["left"]', "dirichlet = []"), "geometry.dirichlet", "or give loads.plate"),
    ("kind-unknown", edit('kind = "strip"', 'kind = "disc"'), "geometry.kind", "one of strip, box"),
    ("size-negative", edit("size = [3.0, 1.0]", "size = [3.0, -1.0]"), "geometry.size", "> 0"),
    ("size-wrong-length", edit("size = [3.0, 1.0]", "size = [3.0, 1.0, 1.0]"), "geometry.size",
     "list of 2 numbers"),
    ("direction-wrong-length", edit("direction = [0.0, -1.0]", "direction = [0.0, 0.0, -1.0]"),
     "contact.direction", "list of 2 numbers"),
    ("velocity-wrong-length", edit("velocity = [1.0, 0.0]", "velocity = [1.0]"),
     "foundation.velocity", "list of 2 numbers"),
    ("body-force-wrong-length", edit("[time]", "body_force = [0.0]\n\n[time]"),
     "loads.body_force", "list of 2 numbers"),
    ("gap-non-numeric", edit("gap = 0.2", 'gap = "thin"'), "contact.gap", "number > 0"),
    ("velocity-non-numeric", edit("velocity = [1.0, 0.0]", 'velocity = [1.0, "x"]'),
     "foundation.velocity", "list of 2 numbers"),
    ("gap-nan", edit("gap = 0.2", "gap = nan"), "contact.gap", "finite number > 0"),
    ("friction-inf", edit("friction = 1.0", "friction = inf"), "contact.friction", "finite number >= 0"),
    ("wear-minus-inf", edit("wear = 1.5", "wear = -inf"), "contact.wear", "finite number >= 0"),
    ("velocity-nan", edit("velocity = [1.0, 0.0]", "velocity = [nan, 0.0]"), "foundation.velocity", "finite"),
    ("direction-inf", edit("direction = [0.0, -1.0]", "direction = [0.0, -inf]"), "contact.direction",
     "finite"),
    ("lame-and-young", edit("lame_mu = 1.0", "lame_mu = 1.0\nyoung = 2.6\npoisson = 0.3"),
     "material.young", "either lame_lambda and lame_mu, or young and poisson"),
    ("lame-and-poisson", edit("lame_mu = 1.0", "lame_mu = 1.0\npoisson = 0.3"),
     "material.poisson", "either lame_lambda and lame_mu, or young and poisson"),
    ("poisson-missing", edit("lame_lambda = 1.0\nlame_mu = 1.0", "young = 2.6"), "material.poisson",
     "missing (young and poisson go together)"),
    ("young-missing", edit("lame_lambda = 1.0\nlame_mu = 1.0", "poisson = 0.3"), "material.young",
     "missing (young and poisson go together)"),
    ("lame-lambda-negative", edit("lame_lambda = 1.0", "lame_lambda = -0.5"), "material.lame_lambda", ">= 0"),
    ("poisson-half", edit("lame_lambda = 1.0\nlame_mu = 1.0", "young = 2.6\npoisson = 0.5"),
     "material.poisson", "in (-1, 0.499]"),
    ("poisson-above-half", edit("lame_lambda = 1.0\nlame_mu = 1.0", "young = 2.6\npoisson = 0.7"),
     "material.poisson", "in (-1, 0.499]"),
    ("poisson-minus-one", edit("lame_lambda = 1.0\nlame_mu = 1.0", "young = 2.6\npoisson = -1.0"),
     "material.poisson", "in (-1, 0.499]"),
    ("young-zero", edit("lame_lambda = 1.0\nlame_mu = 1.0", "young = 0\npoisson = 0.3"),
     "material.young", "> 0"),
    ("lame-mu-zero", edit("lame_mu = 1.0", "lame_mu = 0.0"), "material.lame_mu", "> 0"),
    ("direction-zero", edit("direction = [0.0, -1.0]", "direction = [0.0, 0.0]"), "contact.direction",
     "non-zero"),
    ("friction-velocity-normal", edit("velocity = [1.0, 0.0]", "velocity = [0.0, -1.0]"),
     "foundation.velocity", "tangential"),
    ("friction-velocity-normal-away", edit("velocity = [1.0, 0.0]", "velocity = [0.0, 2.0]"),
     "foundation.velocity", "tangential"),
    ("friction-velocity-normal-oblique",
     edit("velocity = [1.0, 0.0]", "velocity = [0.3, -0.7]", "direction = [0.0, -1.0]", "direction = [0.3, -0.7]"),
     "foundation.velocity", "tangential"),
    ("friction-velocity-zero", edit("velocity = [1.0, 0.0]", "velocity = [0.0, 0.0]"),
     "foundation.velocity", "tangential"),
    ("wear-velocity-zero", edit("velocity = [1.0, 0.0]", "velocity = [0.0, 0.0]", "friction = 1.0", "friction = 0.0"),
     "foundation.velocity", "non-zero"),
    ("speed-table-short", edit("velocity = [1.0, 0.0]", "velocity = [1.0, 0.0]\nspeed_table = [[0.0, 1.0], [0.5, 1.0]]"),
     "foundation.speed_table", "cover [0, time.T] = [0, 1.0]"),
    ("speed-table-late-start", edit("velocity = [1.0, 0.0]",
                                    "velocity = [1.0, 0.0]\nspeed_table = [[0.1, 1.0], [1.0, 1.0]]"),
     "foundation.speed_table", "cover [0, time.T] = [0, 1.0]"),
    ("speed-table-decreasing", edit("velocity = [1.0, 0.0]",
                                    "velocity = [1.0, 0.0]\nspeed_table = [[0.0, 1.0], [0.8, 1.0], [0.5, 1.0], [1.0, 1.0]]"),
     "foundation.speed_table", "non-decreasing"),
    ("speed-table-bad-row", edit("velocity = [1.0, 0.0]", "velocity = [1.0, 0.0]\nspeed_table = [[0.0, 1.0, 2.0]]"),
     "foundation.speed_table", "[t, factor] pairs"),
    ("time-table-short", edit("[time]", "time_table = [[0.0, 0.0], [0.9, 1.0]]\n\n[time]"),
     "loads.time_table", "cover [0, time.T]"),
    ("integrator-unknown", edit('integrator = "explicit"', 'integrator = "rk4"'), "wear.integrator",
     "one of explicit, implicit, trapezoidal"),
    ("law-unknown", edit("gap = 0.2", 'gap = 0.2\nlaw = "quadratic"'), "contact.law", "one of linear, power"),
    ("exponent-with-linear-law", edit("gap = 0.2", "gap = 0.2\nexponent = 2.0"), "contact.exponent",
     "must be 1"),
    ("solver-unknown", BASE + '\n[solver]\nmethod = "direct"\n', "solver.method", "one of condensed, full"),
    ("full-solver-implicit-wear", edit('integrator = "explicit"', 'integrator = "implicit"')
     + '\n[solver]\nmethod = "full"\n', "solver.method", "only wear.integrator = 'explicit'"),
    ("full-solver-trapezoidal-wear", edit('integrator = "explicit"', 'integrator = "trapezoidal"')
     + '\n[solver]\nmethod = "full"\n', "solver.method", "only wear.integrator = 'explicit'"),
    ("tolerance-too-large", BASE + "\n[solver]\ntolerance = 0.5\n", "solver.tolerance", "in [1e-15, 0.01]"),
    ("max-iterations-zero", BASE + "\n[solver]\nmax_iterations = 0\n", "solver.max_iterations", "[1, 10000]"),
    ("output-every-zero", BASE + "\n[output]\nevery = 0\n", "output.every", "a time in (0, time.T] = (0, 1.0]"),
    ("output-every-steps", BASE + "\n[output]\nevery = 25\n", "output.every", "a time in (0, time.T]"),
    ("name-path", edit('name = "base"', 'name = "../../../x"'), "name", "not a path"),
    ("section-not-table", edit('name = "base"', 'name = "base"\nwear = "explicit"', '[wear]\nintegrator = "explicit"', ""),
     "wear", "must be a table"),
    ("name-empty", edit('name = "base"', 'name = ""'), "name", "a plain name"),
]


@pytest.mark.parametrize("text, field, allowed", [c[1:] for c in TOML_CASES], ids=[c[0] for c in TOML_CASES])
def test_malformed_toml_names_field(tmp_path, text, field, allowed):
    with pytest.raises(SceneError) as info:
        load_text(tmp_path, text)
    check_message(info.value, field, allowed)


# (id, ``--set`` style overrides applied to the paper scene, field, fragment stating what is allowed)
OVERRIDE_CASES = [
    ("steps-zero", ["time.steps=0"], "time.steps", "[1, 1000000]"),
    ("steps-fraction", ["time.steps=0.5"], "time.steps", "whole number"),
    ("steps-huge-int", ["time.steps=1" + "0" * 400], "time.steps", "[1, 1000000]"),
    ("maxh-negative", ["mesh.maxh=-0.05"], "mesh.maxh", "in (0, 3.0]"),
    ("order-3", ["mesh.order=3"], "mesh.order", "in [1, 2]"),
    ("gap-zero", ["contact.gap=0"], "contact.gap", "> 0"),
    ("friction-nan", ["contact.friction=nan"], "contact.friction", "finite number >= 0"),
    ("T-inf", ["time.T=inf"], "time.T", "finite number > 0"),
    ("T-word", ["time.T=long"], "time.T", "number > 0"),
    ("integrator-bare-word", ["wear.integrator=rk4"], "wear.integrator", "one of explicit, implicit"),
    ("full-with-implicit", ["solver.method=full", "wear.integrator=implicit"], "solver.method",
     "only wear.integrator = 'explicit'"),
    ("young-on-lame-scene", ["material.young=100"], "material.young", "either lame_lambda"),
    ("traction-on-dirichlet", ["loads.traction.left=[0.0, 1.0]"], "loads.traction.left", "allowed: right, top"),
    ("traction-wrong-length", ["loads.traction.top=[1.0]"], "loads.traction.top", "list of 2 numbers"),
    ("velocity-normal", ["foundation.velocity=[0.0, 1.0]"], "foundation.velocity", "tangential"),
    ("speed-table-short-after-T", ["foundation.speed_table=[[0.0, 1.0], [1.0, 1.0]]", "time.T=2.0"],
     "foundation.speed_table", "cover [0, time.T] = [0, 2.0]"),
    ("unknown-section", ["plot.dpi=300"], "plot", "unknown section"),
    ("unknown-key", ["mesh.maxH=0.1"], "mesh.maxH", "allowed: maxh, order, contact_maxh"),
    ("below-a-number", ["time.steps.x=1"], "time.steps.x", "not a table"),
]


@pytest.mark.parametrize("overrides, field, allowed", [c[1:] for c in OVERRIDE_CASES],
                         ids=[c[0] for c in OVERRIDE_CASES])
def test_malformed_override_names_field(paper_scene, overrides, field, allowed):
    with pytest.raises(SceneError) as info:
        paper_scene.replace(**dict(parse_override(item) for item in overrides))
    check_message(info.value, field, allowed)


def test_invalid_toml_syntax(tmp_path):
    with pytest.raises(SceneError) as info:
        load_text(tmp_path, BASE.replace("gap = 0.2", "gap = = 0.2"))
    msg = str(info.value)
    assert msg.startswith("scene file:") and "not valid TOML" in msg and "\n" not in msg
    assert "line" in msg  # tomllib's position of the error


def test_missing_file(tmp_path):
    with pytest.raises(SceneError) as info:
        load_scene(tmp_path / "nope.toml")
    msg = str(info.value)
    assert msg.startswith("scene file:") and "does not exist" in msg and "nope.toml" in msg


def test_unreadable_file(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes(BASE.replace('"base"', '"b\xe4se"').encode("latin-1"))
    with pytest.raises(SceneError, match=r"^scene file: cannot read"):
        load_scene(path)


@pytest.mark.parametrize("text", ["time.steps", "time.steps 10", "=10", " =10"])
def test_override_without_equals(text):
    with pytest.raises(SceneError) as info:
        parse_override(text)
    msg = str(info.value)
    assert msg.startswith(f"--set {text}:") and "KEY=VALUE" in msg and "\n" not in msg


@pytest.mark.parametrize("text, expected", [
    ("mesh.maxh=0.05", ("mesh.maxh", 0.05)),
    ("time.steps = 10", ("time.steps", 10)),
    ("wear.integrator=implicit", ("wear.integrator", "implicit")),
    ('wear.integrator="implicit"', ("wear.integrator", "implicit")),
    ("loads.traction.top=[0.0, -0.2]", ("loads.traction.top", [0.0, -0.2])),
    ("solver.method=full", ("solver.method", "full")),
])
def test_parse_override(text, expected):
    assert parse_override(text) == expected


# ---------------------------------------------------------------- valid scenes


def test_paper_scene_has_the_paper_data():
    s = load_scene(PAPER)
    assert s.name == "paper_strip" and s.dim == 2
    assert s.geometry.kind == "strip" and s.geometry.size == (3.0, 1.0) and s.geometry.dirichlet == ("left",)
    assert s.material.lame == (1.0, 1.0)                              # λ = η = 1
    assert s.contact.law == "linear" and s.contact.stiffness == 10.0   # p(r) = L r₊, L = 10
    assert s.contact.gap == 0.2 and s.contact.friction == 1.0 and s.contact.wear == 1.5
    assert s.contact.direction == (0.0, -1.0)
    assert s.foundation.velocity == (1.0, 0.0) and s.foundation.speed_table == ()
    assert dict(s.loads.traction) == {"top": (0.0, -0.1), "right": (0.0, -0.1)}
    assert s.loads.body_force is None and s.loads.time_table == ()
    assert s.time.T == 1.0 and s.time.steps == 100 and isinstance(s.time.steps, int)
    assert s.dt == pytest.approx(0.01)
    assert s.wear.integrator == "explicit" and s.solver.method == "condensed"


def test_replace_with_dotted_keys(paper_scene):
    s = paper_scene.replace(**{"time.steps": 10, "contact.gap": 0.1, "loads.traction.top": [0.0, -0.2],
                               "wear.integrator": "implicit"})
    assert s.time.steps == 10 and s.dt == pytest.approx(0.1) and s.contact.gap == 0.1
    assert dict(s.loads.traction) == {"top": (0.0, -0.2), "right": (0.0, -0.1)}
    assert s.wear.integrator == "implicit"
    # everything else unchanged, and the original is untouched (frozen)
    assert s.replace(**{"time.steps": 100, "contact.gap": 0.2, "loads.traction.top": [0.0, -0.1],
                        "wear.integrator": "explicit"}) == paper_scene
    assert paper_scene.time.steps == 100 and paper_scene.contact.gap == 0.2
    with pytest.raises(ValidationError, match="frozen"):
        paper_scene.time.steps = 3  # type: ignore[misc]


def test_replace_revalidates_cross_field_rules(paper_scene):
    s = paper_scene.replace(**{"foundation.speed_table": [[0.0, 0.0], [1.0, 1.0]]})
    assert s.foundation.speed_table == ((0.0, 0.0), (1.0, 1.0))
    with pytest.raises(SceneError, match=r"^foundation\.speed_table: .*\[0, 2\.0\]"):
        s.replace(**{"time.T": 2.0})
    with pytest.raises(SceneError, match=r"^solver\.method: "):
        s.replace(**{"wear.integrator": "trapezoidal", "solver.method": "full"})
    assert s.replace(**{"solver.method": "full"}).solver.method == "full"  # explicit is fine
    # switching material parametrisation needs the old keys replaced as a whole table
    e = s.replace(**{"material": {"young": 2.6, "poisson": 0.3}})
    assert e.material.lame == pytest.approx((1.5, 1.0))


def test_overrides_from_strings(paper_scene):
    items = ["mesh.maxh=0.25", "time.steps=4", "wear.integrator=trapezoidal", "contact.friction=0"]
    s = paper_scene.replace(**dict(parse_override(i) for i in items))
    assert s.mesh.maxh == 0.25 and s.time.steps == 4 and s.wear.integrator == "trapezoidal"
    assert s.contact.friction == 0.0


RICH = {
    "name": "rich",
    "geometry": {"kind": "box", "size": [1.0, 0.5, 0.5], "dirichlet": ["left", "back"]},
    "mesh": {"maxh": 0.2, "order": 1},
    "material": {"young": 3.0, "poisson": 0.25},
    "contact": {"law": "power", "exponent": 2.0, "stiffness": 5.0, "gap": 0.1, "friction": 0.3,
                "wear": 0.5, "direction": [0.0, 0.0, -2.0]},
    "foundation": {"velocity": [1.0, 0.5, 0.0], "speed_table": [[0.0, 0.0], [0.5, 1.0], [2.0, 1.0]]},
    "loads": {"traction": {"top": [0.0, 0.0, -0.1], "front": [0.0, 0.01, 0.0]},
              "body_force": [0.0, 0.0, -1.0], "time_table": [[0.0, 0.0], [2.0, 1.0]]},
    "time": {"T": 2.0, "steps": 8},
    "wear": {"integrator": "trapezoidal"},
    "solver": {"method": "condensed", "tolerance": 1e-9, "max_iterations": 20},
    "output": {"every": 2},
}


@pytest.mark.parametrize("which", ["paper", "rich"])
def test_to_dict_from_dict_round_trip(paper_scene, which):
    scene = paper_scene if which == "paper" else Scene.from_dict(RICH)
    data = scene.to_dict()
    assert Scene.from_dict(data) == scene
    assert Scene.from_dict(json.loads(json.dumps(data))) == scene  # what result.save writes
    assert Scene.from_dict(scene.to_dict()).to_dict() == data


def test_rich_scene_values():
    s = Scene.from_dict(RICH)
    assert s.dim == 3 and s.geometry.dirichlet == ("left", "back")
    assert s.contact.direction == (0.0, 0.0, -1.0)  # normalised
    assert s.material.lame_lambda is None and s.material.young == 3.0
    assert s.output.every == 2 and s.solver.max_iterations == 20


def test_whole_float_steps_become_int(tmp_path):
    s = load_text(tmp_path, edit("steps = 10", "steps = 10.0"))
    assert s.time.steps == 10 and isinstance(s.time.steps, int)
    assert s.name == "base"
    assert load_text(tmp_path, edit('name = "base"\n', "")).name == "scene"  # file stem


def test_lame_defaults(tmp_path):
    """As documented: λ and η default to 1 each, also when [material] is left out."""
    assert load_text(tmp_path, edit("lame_mu = 1.0", "lame_mu = 2.0")).material.lame == (1.0, 2.0)
    assert load_text(tmp_path, edit("lame_mu = 1.0", "")).material.lame == (1.0, 1.0)
    assert load_text(tmp_path, edit("[material]\nlame_lambda = 1.0\nlame_mu = 1.0", "")).material.lame == (1.0, 1.0)


def test_oblique_direction_with_tangential_velocity_is_accepted(tmp_path):
    s = load_text(tmp_path, edit("direction = [0.0, -1.0]", "direction = [0.6, -0.8]"))
    assert s.contact.direction == pytest.approx((0.6, -0.8))


@pytest.mark.parametrize("young, poisson", [(2.6, 0.3), (210e3, 0.3), (1.0, 0.0), (5.0, -0.5), (1.0, 0.49)])
def test_young_poisson_to_lame(young, poisson):
    s = Scene.from_dict({"material": {"young": young, "poisson": poisson}})
    lam, mu = s.material.lame
    assert lam == pytest.approx(young * poisson / ((1 + poisson) * (1 - 2 * poisson)), rel=1e-14)
    assert mu == pytest.approx(young / (2 * (1 + poisson)), rel=1e-14)
    # inverse relations E = μ(3λ + 2μ)/(λ + μ), ν = λ / (2(λ + μ))
    assert mu * (3 * lam + 2 * mu) / (lam + mu) == pytest.approx(young, rel=1e-12)
    assert lam / (2 * (lam + mu)) == pytest.approx(poisson, abs=1e-12)


def test_young_poisson_known_value():
    lam, mu = Scene.from_dict({"material": {"young": 2.6, "poisson": 0.3}}).material.lame
    assert math.isclose(lam, 1.5) and math.isclose(mu, 1.0)


def test_published_json_schema_is_current():
    """geometries/scene.schema.json (what editors read) is the declared schema; regenerate with `ngwear schema`."""
    from conftest import ROOT

    from ngwear.model.scene import json_schema
    published = json.loads((ROOT / "geometries" / "scene.schema.json").read_text())
    assert published == json_schema()
    assert published["properties"]["contact"]["$ref"].endswith("/Contact")
    gap = published["$defs"]["Contact"]["properties"]["gap"]
    assert gap["exclusiveMinimum"] == 0 and gap["type"] == "number"


# ---------------------------------------------------------------- defaults after the overrides


def test_a_turning_disc_does_not_translate_unless_told():
    """``foundation.velocity`` defaults to (1, 0, …) without ``angular_velocity`` and to 0 with it (3D and 2D)."""
    pin = load_scene("pin_on_disc").to_dict()
    del pin["foundation"]["velocity"]
    disc = Scene.from_dict(pin)
    assert disc.foundation.velocity == (0.0, 0.0, 0.0) and disc.foundation.angular_velocity == (0.0, 0.0, 10.0)
    strip = load_scene(PAPER).to_dict()
    del strip["foundation"]["velocity"]
    assert Scene.from_dict(strip).foundation.velocity == (1.0, 0.0)
    turned = Scene.from_dict(strip).replace(**{"foundation.angular_velocity": 2.0, "foundation.center": [1.5, -3.0]})
    assert turned.foundation.velocity == (0.0, 0.0)                 # the default escaped: filled after the override
    told = Scene.from_dict({**strip, "foundation": {"velocity": [0.5, 0.0], "angular_velocity": 2.0}})
    assert told.foundation.velocity == (0.5, 0.0)


def test_an_override_repairs_a_bad_value_of_the_file(tmp_path):
    """``--set`` (``load_scene``'s overrides) applies to the file's keys before they are checked."""
    path = tmp_path / "bad.toml"
    path.write_text(BASE.replace("gap = 0.2", "gap = -1.0"))
    with pytest.raises(SceneError, match=r"^contact\.gap: must be > 0 \(got -1\.0\)$"):
        load_scene(path)
    assert load_scene(path, {"contact.gap": 0.001}).contact.gap == 0.001
    with pytest.raises(SceneError, match=r"^contact\.gap: must be > 0 \(got -2\)$"):
        load_scene(path, {"contact.gap": -2})


def test_replace_starts_from_the_keys_as_given_and_compares_by_value():
    """A scene is equal to its round trip through ``to_dict`` (every default named) and to one naming a default."""
    scene = Scene.from_dict({"geometry": {"kind": "strip", "size": [3.0, 1.0]}, "contact": {"wear": 0.5}})
    named = Scene.from_dict(scene.to_dict())
    assert named == scene
    assert scene.replace(**{"foundation.angular_velocity": 1.0}).foundation.velocity == (0.0, 0.0)
    assert named.replace(**{"foundation.angular_velocity": 1.0}).foundation.velocity == (1.0, 0.0)   # named: kept
