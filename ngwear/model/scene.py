"""Scenes: plain frozen data describing one contact-with-wear simulation.

A scene is read from TOML with nested tables (``[geometry]``, ``[mesh]``, ``[material]``,
``[contact]``, ``[foundation]``, ``[loads]``, ``[time]``, ``[wear]``, ``[output]``) and validated
field by field; every error is a :class:`SceneError` whose one-line message names the dotted key
and the allowed range.  ``Scene.replace(**{"time.steps": 10})`` overrides fields with the same
dotted keys that ``ngwear run --set time.steps=10`` accepts.
"""
from __future__ import annotations

import copy
import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

GEOMETRY_KINDS = {"strip": 2, "box": 3, "half_disk": 2}
BOUNDARIES = {
    "strip": ("left", "right", "top", "contact"),
    "box": ("left", "right", "front", "back", "top", "contact"),
    "half_disk": ("top", "contact"),
}
DEFAULT_SIZES = {"strip": (3.0, 1.0), "box": (1.0, 0.5, 0.5), "half_disk": (1.0,)}
DEFAULT_DIRICHLET = {"strip": ("left",), "box": ("left",), "half_disk": ("top",)}
COMPLIANCE_LAWS = ("linear", "power")
WEAR_INTEGRATORS = ("explicit", "implicit", "trapezoidal")
SOLVERS = ("condensed", "full")


class SceneError(ValueError):
    """A scene field is missing, of the wrong type or out of range (message names the field)."""


@dataclass(frozen=True)
class Geometry:
    """Body shape of one of the kinds ``strip``, ``box``, ``half_disk``.

    ``strip`` = [0,Lx]×[0,Ly] (2D), ``box`` = [0,Lx]×[0,Ly]×[0,Lz] (3D), ``half_disk`` = lower half
    of the disk of radius R = size[0] centred at (0, R) (2D, Γ_C the arc).
    """

    kind: str = "strip"
    size: tuple[float, ...] = (3.0, 1.0)
    dirichlet: tuple[str, ...] = ("left",)

    @property
    def dim(self) -> int:
        return GEOMETRY_KINDS[self.kind]


@dataclass(frozen=True)
class MeshSpec:
    """Netgen mesh size ``maxh``, polynomial ``order`` (1 or 2) and whether to mesh the soft layer.

    ``contact_maxh`` (optional) is the mesh size on Γ_C; for ``half_disk`` only on the arc within
    ``contact_zone`` (horizontal half-width, default R/4) of the lowest point.  ``grading``
    (optional, Netgen's default 0.3) bounds how fast the element size grows away from Γ_C.
    """

    maxh: float = 0.1
    order: int = 1
    layer: bool = True
    contact_maxh: float | None = None
    contact_zone: float | None = None
    grading: float | None = None


@dataclass(frozen=True)
class Material:
    """Hooke's law σ = 2η ε + λ tr(ε) I, from Lamé (λ, η) or from Young's modulus E and Poisson ν."""

    lame_lambda: float | None = None
    lame_mu: float | None = None
    young: float | None = None
    poisson: float | None = None

    @property
    def lame(self) -> tuple[float, float]:
        """(λ, η); converts (E, ν) when those are given."""
        if self.young is not None:
            e, nu = self.young, self.poisson
            return e * nu / ((1 + nu) * (1 - 2 * nu)), e / (2 * (1 + nu))
        return self.lame_lambda, self.lame_mu


@dataclass(frozen=True)
class Contact:
    """Normal compliance p, soft-layer thickness g, friction μ, wear κ, contact direction ν."""

    law: str = "linear"
    stiffness: float = 10.0
    exponent: float = 1.0
    gap: float = 0.2
    friction: float = 0.0
    wear: float = 0.0
    direction: tuple[float, ...] = (0.0, -1.0)


@dataclass(frozen=True)
class Foundation:
    """Foundation velocity v*(t) = velocity · s(t), s piecewise linear through ``speed_table``."""

    velocity: tuple[float, ...] = (1.0, 0.0)
    speed_table: tuple[tuple[float, float], ...] = ()


@dataclass(frozen=True)
class Loads:
    """Tractions per named boundary and a body force, all scaled by the piecewise-linear ``time_table``."""

    traction: tuple[tuple[str, tuple[float, ...]], ...] = ()
    body_force: tuple[float, ...] | None = None
    time_table: tuple[tuple[float, float], ...] = ()


@dataclass(frozen=True)
class TimeGrid:
    """Uniform time grid t_j = j T / steps, j = 0..steps."""

    T: float = 1.0
    steps: int = 100


@dataclass(frozen=True)
class WearSpec:
    """Wear integrator: the paper's ``explicit`` (eq. 15), ``implicit`` (backward Euler), ``trapezoidal``."""

    integrator: str = "explicit"


@dataclass(frozen=True)
class SolverSpec:
    """Nonlinear solver: ``condensed`` onto the contact points (fast) or ``full`` system (reference)."""

    method: str = "condensed"
    tolerance: float = 1e-10
    max_iterations: int = 50


@dataclass(frozen=True)
class Output:
    """Steps whose full displacement field is written and rendered: every ``every``-th and the last."""

    every: int = 25


@dataclass(frozen=True)
class Scene:
    """A complete, validated simulation set-up.  Build with :func:`load_scene` or :meth:`from_dict`."""

    name: str = "scene"
    geometry: Geometry = field(default_factory=Geometry)
    mesh: MeshSpec = field(default_factory=MeshSpec)
    material: Material = field(default_factory=lambda: Material(1.0, 1.0))
    contact: Contact = field(default_factory=Contact)
    foundation: Foundation = field(default_factory=Foundation)
    loads: Loads = field(default_factory=Loads)
    time: TimeGrid = field(default_factory=TimeGrid)
    wear: WearSpec = field(default_factory=WearSpec)
    solver: SolverSpec = field(default_factory=SolverSpec)
    output: Output = field(default_factory=Output)

    @property
    def dim(self) -> int:
        return self.geometry.dim

    @property
    def dt(self) -> float:
        return self.time.T / self.time.steps

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Scene:
        """Validate a nested dict (as read from TOML) into a Scene."""
        return _build(data)

    def to_dict(self) -> dict[str, Any]:
        """The nested-dict form that :meth:`from_dict` and TOML use."""
        return _to_plain(self)

    def replace(self, **dotted: Any) -> Scene:
        """A new scene with fields overridden by dotted keys, e.g. ``replace(**{"time.steps": 10})``."""
        data = self.to_dict()
        for key, value in dotted.items():
            set_dotted(data, key, value)
        return _build(data)


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene TOML file."""
    path = Path(path)
    if not path.is_file():
        raise SceneError(f"scene file: {path} does not exist")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise SceneError(f"scene file: cannot read {path} ({err})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError(f"scene file: {path} is not valid TOML ({err})") from None
    data.setdefault("name", path.stem)
    return _build(data)


def set_dotted(data: dict[str, Any], key: str, value: Any) -> None:
    """Set ``data["a"]["b"] = value`` for ``key = "a.b"``; unknown sections are rejected later."""
    parts = key.split(".")
    node = data
    for part in parts[:-1]:
        child = node.setdefault(part, {})
        if not isinstance(child, dict):
            raise SceneError(f"{key}: '{part}' is not a table")
        node = child
    node[parts[-1]] = value


def parse_override(text: str) -> tuple[str, Any]:
    """``"mesh.maxh=0.05"`` → ``("mesh.maxh", 0.05)``; the value is read as a TOML value."""
    key, sep, raw = text.partition("=")
    if not sep or not key.strip():
        raise SceneError(f"--set {text}: expected KEY=VALUE, e.g. time.steps=10")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    return key.strip(), value


# ---------------------------------------------------------------- validation helpers


def _to_plain(obj: Any) -> Any:
    if hasattr(obj, "__dataclass_fields__"):
        out = {}
        for f in fields(obj):
            value = getattr(obj, f.name)
            if value is None:
                continue
            if f.name == "traction":
                value = {name: list(vec) for name, vec in value}
            out[f.name] = _to_plain(value)
        return out
    if isinstance(obj, tuple):
        return [_to_plain(v) for v in obj]
    return copy.deepcopy(obj)


def _section(data: dict, name: str, allowed: tuple[str, ...]) -> dict:
    sec = data.get(name, {})
    if not isinstance(sec, dict):
        raise SceneError(f"{name}: must be a table (got {sec!r})")
    for key in sec:
        if key not in allowed:
            raise SceneError(f"{name}.{key}: unknown key (allowed: {', '.join(allowed)})")
    return sec


def _number(sec: dict, prefix: str, key: str, default: Any, *, lo=None, hi=None,
            lo_open=False, integer=False) -> Any:
    value = sec.get(key, default)
    name = f"{prefix}.{key}"
    if value is None:
        return None
    kind = "a whole number" if integer else "a number"
    rng = _range_text(lo, hi, lo_open)
    what = f"{kind} {rng}" if rng else kind
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(f"{name}: must be {what} (got {value!r})")
    if isinstance(value, float) and not math.isfinite(value):
        raise SceneError(f"{name}: must be a finite {what.removeprefix('a ')} (got {value!r})")
    if integer and isinstance(value, float) and not value.is_integer():
        raise SceneError(f"{name}: must be {what} (got {value!r})")
    if lo is not None and (value < lo or (lo_open and value == lo)):
        raise SceneError(f"{name}: must be {rng} (got {value!r})")
    if hi is not None and value > hi:
        raise SceneError(f"{name}: must be {rng} (got {value!r})")
    return int(value) if integer else float(value)


def _range_text(lo, hi, lo_open) -> str:
    if lo is not None and hi is not None:
        return f"in {'(' if lo_open else '['}{lo}, {hi}]"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {lo}"
    if hi is not None:
        return f"<= {hi}"
    return ""


def _vector(sec: dict, prefix: str, key: str, default: Any, dim: int) -> tuple[float, ...] | None:
    value = sec.get(key, default)
    name = f"{prefix}.{key}"
    if value is None:
        return None
    if (not isinstance(value, (list, tuple)) or len(value) != dim
            or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value)):
        raise SceneError(f"{name}: must be a list of {dim} numbers (got {value!r})")
    if not all(math.isfinite(v) for v in value):
        raise SceneError(f"{name}: must be finite (got {value!r})")
    return tuple(float(v) for v in value)


def _table(sec: dict, prefix: str, key: str, T: float) -> tuple[tuple[float, float], ...]:
    value = sec.get(key, [])
    name = f"{prefix}.{key}"
    ok = isinstance(value, (list, tuple)) and all(
        isinstance(row, (list, tuple)) and len(row) == 2
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in row)
        for row in value)
    if not ok:
        raise SceneError(f"{name}: must be a list of [t, factor] pairs (got {value!r})")
    times = [row[0] for row in value]
    if any(b < a for a, b in zip(times, times[1:])):
        raise SceneError(f"{name}: times must be non-decreasing (got {times})")
    if value and (times[0] > 0 or times[-1] < T):
        raise SceneError(f"{name}: must cover [0, time.T] = [0, {T}] (got {times[0]} to {times[-1]})")
    return tuple((float(t), float(f)) for t, f in value)


def _choice(sec: dict, prefix: str, key: str, default: str, allowed: tuple[str, ...]) -> str:
    value = sec.get(key, default)
    if value not in allowed:
        raise SceneError(f"{prefix}.{key}: must be one of {', '.join(allowed)} (got {value!r})")
    return value


def _names(fields_of) -> tuple[str, ...]:
    return tuple(f.name for f in fields(fields_of))


def _build(data: dict[str, Any]) -> Scene:
    if not isinstance(data, dict):
        raise SceneError("scene: must be a table")
    top = tuple(f.name for f in fields(Scene))
    for key in data:
        if key not in top:
            raise SceneError(f"{key}: unknown section (allowed: {', '.join(top)})")
    name = data.get("name", "scene")
    if not isinstance(name, str) or not name:
        raise SceneError(f"name: must be a non-empty string (got {name!r})")

    g = _section(data, "geometry", _names(Geometry))
    kind = _choice(g, "geometry", "kind", "strip", tuple(GEOMETRY_KINDS))
    dim = GEOMETRY_KINDS[kind]
    default_size = DEFAULT_SIZES[kind]
    size = _vector(g, "geometry", "size", default_size, len(default_size))
    if min(size) <= 0:
        raise SceneError(f"geometry.size: every length must be > 0 (got {list(size)})")
    dirichlet = g.get("dirichlet", list(DEFAULT_DIRICHLET[kind]))
    boundaries = BOUNDARIES[kind]
    if isinstance(dirichlet, str):
        dirichlet = [dirichlet]
    if not isinstance(dirichlet, list) or not dirichlet:
        raise SceneError(f"geometry.dirichlet: must be a non-empty list of boundary names (got {dirichlet!r})")
    for b in dirichlet:
        if b not in boundaries or b == "contact":
            allowed = ", ".join(x for x in boundaries if x != "contact")
            raise SceneError(f"geometry.dirichlet: unknown or non-Dirichlet boundary {b!r} (allowed: {allowed})")
    geometry = Geometry(kind, size, tuple(dirichlet))

    m = _section(data, "mesh", _names(MeshSpec))
    maxh = _number(m, "mesh", "maxh", 0.1, lo=0, lo_open=True, hi=max(size))
    order = _number(m, "mesh", "order", 1, lo=1, hi=2 if dim == 2 else 1, integer=True)
    flat = kind != "half_disk"
    layer = m.get("layer", flat)
    if not isinstance(layer, bool):
        raise SceneError(f"mesh.layer: must be true or false (got {layer!r})")
    if layer and not flat:
        raise SceneError(f"mesh.layer: must be false for geometry.kind = {kind!r} "
                         "(the soft layer is meshed only under a flat Γ_C)")
    contact_maxh = _number(m, "mesh", "contact_maxh", None, lo=0, lo_open=True, hi=maxh)
    if "contact_zone" in m and flat:
        raise SceneError(f"mesh.contact_zone: only for geometry.kind = 'half_disk' (got kind {kind!r})")
    contact_zone = _number(m, "mesh", "contact_zone", None, lo=0, lo_open=True, hi=size[0])
    grading = _number(m, "mesh", "grading", None, lo=0.1, hi=1.0)
    mesh = MeshSpec(maxh, order, layer, contact_maxh, contact_zone, grading)

    mat = _section(data, "material", _names(Material))
    lame = [k for k in ("lame_lambda", "lame_mu") if k in mat]
    engineering = [k for k in ("young", "poisson") if k in mat]
    if lame and engineering:
        raise SceneError(f"material.{engineering[0]}: cannot be combined with material.{lame[0]} "
                         "(give either lame_lambda and lame_mu, or young and poisson)")
    if engineering:
        missing = [k for k in ("young", "poisson") if k not in mat]
        if missing:
            raise SceneError(f"material.{missing[0]}: missing (young and poisson go together)")
        material = Material(young=_number(mat, "material", "young", None, lo=0, lo_open=True),
                            poisson=_number(mat, "material", "poisson", None, lo=-1, lo_open=True, hi=0.499))
    else:
        lam = _number(mat, "material", "lame_lambda", 1.0, lo=0)
        mu = _number(mat, "material", "lame_mu", 1.0, lo=0, lo_open=True)
        material = Material(lame_lambda=lam, lame_mu=mu)

    c = _section(data, "contact", _names(Contact))
    law = _choice(c, "contact", "law", "linear", COMPLIANCE_LAWS)
    default_dir = (0.0, -1.0) if dim == 2 else (0.0, 0.0, -1.0)
    direction = _vector(c, "contact", "direction", default_dir, dim)
    norm = math.sqrt(sum(v * v for v in direction))
    if norm == 0:
        raise SceneError(f"contact.direction: must be a non-zero vector (got {list(direction)})")
    contact = Contact(
        law=law,
        stiffness=_number(c, "contact", "stiffness", 10.0, lo=0, lo_open=True),
        exponent=_number(c, "contact", "exponent", 1.0, lo=1, hi=10),
        gap=_number(c, "contact", "gap", 0.2, lo=0, lo_open=True),
        friction=_number(c, "contact", "friction", 0.0, lo=0),
        wear=_number(c, "contact", "wear", 0.0, lo=0),
        direction=tuple(v / norm for v in direction),
    )
    if law == "linear" and "exponent" in c and c["exponent"] != 1:
        raise SceneError(f"contact.exponent: must be 1 with contact.law = 'linear' (got {c['exponent']!r})")

    t = _section(data, "time", _names(TimeGrid))
    time = TimeGrid(_number(t, "time", "T", 1.0, lo=0, lo_open=True),
                    _number(t, "time", "steps", 100, lo=1, hi=1_000_000, integer=True))

    f = _section(data, "foundation", _names(Foundation))
    velocity = _vector(f, "foundation", "velocity", (1.0, 0.0) if dim == 2 else (1.0, 0.0, 0.0), dim)
    foundation = Foundation(velocity, _table(f, "foundation", "speed_table", time.T))
    nu = contact.direction
    vn = sum(a * b for a, b in zip(velocity, nu))
    speed = math.sqrt(sum(v * v for v in velocity))
    tangential = math.sqrt(sum((v - vn * n) ** 2 for v, n in zip(velocity, nu)))
    if contact.friction > 0 and tangential <= 1e-12 * speed:
        raise SceneError("foundation.velocity: must have a non-zero part tangential to contact.direction "
                         f"when contact.friction > 0 (got {list(velocity)})")
    if contact.wear > 0 and speed == 0:
        raise SceneError(f"foundation.velocity: must be non-zero when contact.wear > 0 (got {list(velocity)})")

    ld = _section(data, "loads", _names(Loads))
    traction = ld.get("traction", {})
    if not isinstance(traction, dict):
        raise SceneError(f"loads.traction: must be a table of boundary = [vector] (got {traction!r})")
    pairs = []
    for bname, vec in traction.items():
        if bname not in boundaries or bname == "contact" or bname in geometry.dirichlet:
            allowed = ", ".join(x for x in boundaries if x != "contact" and x not in geometry.dirichlet)
            raise SceneError(f"loads.traction.{bname}: unknown or non-Neumann boundary (allowed: {allowed})")
        if vec is None:
            raise SceneError(f"loads.traction.{bname}: must be a list of {dim} numbers (got None)")
        pairs.append((bname, _vector(traction, "loads.traction", bname, None, dim)))
    loads = Loads(tuple(pairs), _vector(ld, "loads", "body_force", None, dim),
                  _table(ld, "loads", "time_table", time.T))

    w = _section(data, "wear", _names(WearSpec))
    wear = WearSpec(_choice(w, "wear", "integrator", "explicit", WEAR_INTEGRATORS))

    s = _section(data, "solver", _names(SolverSpec))
    solver = SolverSpec(_choice(s, "solver", "method", "condensed", SOLVERS),
                        _number(s, "solver", "tolerance", 1e-10, lo=1e-15, hi=1e-2),
                        _number(s, "solver", "max_iterations", 50, lo=1, hi=10_000, integer=True))
    if solver.method == "full" and wear.integrator != "explicit":
        raise SceneError(f"solver.method: 'full' supports only wear.integrator = 'explicit' "
                         f"(got {wear.integrator!r}; use solver.method = 'condensed')")

    o = _section(data, "output", _names(Output))
    output = Output(_number(o, "output", "every", max(1, time.steps // 4), lo=1, integer=True))

    return Scene(name, geometry, mesh, material, contact, foundation, loads, time, wear, solver, output)

