"""Scenes: plain frozen data describing one contact-with-wear simulation.

A scene is read from TOML with nested tables (``[geometry]``, ``[mesh]``, ``[material]``,
``[contact]``, ``[foundation]``, ``[loads]``, ``[time]``, ``[wear]``, ``[solver]``, ``[output]``).
Every key is declared once below, with its type, its range and a line of documentation; pydantic
validates against the declaration, :func:`_message` turns the first violation into a one-line
:class:`SceneError` naming the dotted key and the allowed range, and the same declaration is
published as a JSON Schema (:func:`json_schema`) and as the README's scene reference
(:func:`reference_table`).  Rules that tie keys together (vector lengths by dimension, boundary
names by geometry, ranges that depend on other keys) are checked in :meth:`Scene._cross_checks`.
``Scene.replace(**{"time.steps": 10})`` overrides fields with the dotted keys that
``ngwear run --set time.steps=10`` accepts.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal, get_args, get_origin

from pydantic import (
    AllowInfNan,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    Strict,
    ValidationError,
    field_validator,
    model_validator,
)
from pydantic.fields import FieldInfo

Number = Annotated[float, Strict(), AllowInfNan(False)]


def _integral(value: Any) -> Any:
    """A whole float (``10.0``) is taken as the integer it is; anything else is left to the int check."""
    return int(value) if isinstance(value, float) and value.is_integer() else value


Whole = Annotated[int, BeforeValidator(_integral), Strict()]
Flag = Annotated[bool, Strict()]
Vector = tuple[Number, ...]
Table = tuple[tuple[Number, Number], ...]


class SceneError(ValueError):
    """A scene field is missing, of the wrong type or out of range (message names the field)."""


@dataclass(frozen=True)
class Kind:
    """What a geometry kind fixes: dimension, default size, named boundaries, default clamping.

    The part files (``step``, ``mesh``) fix none of these: the file gives dimension and boundaries.
    """

    dim: int | None
    size: tuple[float, ...] | None
    boundaries: tuple[str, ...] | None
    dirichlet: tuple[str, ...]


KINDS = {
    "strip": Kind(2, (3.0, 1.0), ("left", "right", "top", "contact"), ("left",)),
    "box": Kind(3, (1.0, 0.5, 0.5), ("left", "right", "front", "back", "top", "contact"), ("left",)),
    "half_disk": Kind(2, (1.0,), ("top", "contact"), ("top",)),
    "pad": Kind(3, (0.6, 1.0, 60.0, 0.15), ("contact", "back", "inner", "outer", "leading", "trailing"), ()),
    "pin": Kind(3, (0.1, 0.3), ("contact", "back", "side"), ()),
    "step": Kind(None, None, None, ()),
    "mesh": Kind(None, None, None, ()),
}
PIN_KEYS = ("position", "end", "end_radius")


def key(default: Any, doc: str, *, shown: str | None = None, allowed: str | None = None, **limits) -> Any:
    """A declared scene key: default, one line of documentation, limits; ``shown``/``allowed`` for the table."""
    extra = {k: v for k, v in (("shown", shown), ("allowed", allowed)) if v is not None}
    return Field(default, description=doc, json_schema_extra=extra or None, **limits)


class Section(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class Geometry(Section):
    """Body shape: a built-in kind with its ``size``, or the user's part from ``file`` (see :mod:`ngwear.model.cad`)."""

    kind: Literal["strip", "box", "half_disk", "pad", "pin", "step", "mesh"] = key(
        "strip", "`strip` [0,Lx]×[0,Ly] (2D); `box` [0,Lx]×[0,Ly]×[0,Lz]; `half_disk` the lower half of the disk "
        "of radius R centred at (0, R) (2D); `pad` an annular-sector brake pad r_i ≤ r ≤ r_o, |φ| ≤ angle/2, "
        "0 ≤ z ≤ thickness (faces contact z = 0, back, inner, outer, leading φ = −angle/2, trailing); `pin` a "
        "cylinder of radius a from z = 0 up to z = length (faces contact, back, side); `step` a STEP/IGES/BREP "
        "file; `mesh` a Netgen .vol or Gmsh .msh file")
    size: Vector | None = key(None, "`strip` [Lx, Ly], `box` [Lx, Ly, Lz], `half_disk` [R], `pad` [r_inner, "
                              "r_outer, angle_deg, thickness], `pin` [a, length]; not for files",
                              shown="[3, 1] / [1, 0.5, 0.5] / [1] / [0.6, 1, 60, 0.15] / [0.1, 0.3]",
                              allowed="lengths > 0")
    dirichlet: tuple[str, ...] | None = key(None, "clamped boundaries", shown="[left]; [top] (`half_disk`); [] "
                                            "(`pad`, `pin`, files)", allowed="named boundaries except `contact`")
    position: Vector | None = key(None, "`pin`: (x, y) of its axis on the disc", shown="(1, 0)",
                                  allowed="2 numbers")
    end: Literal["flat", "sphere"] | None = key(None, "`pin`: a flat end, or a spherical cap touching the disc at "
                                                "its lowest point (curved Γ_C, initial distance d₀)", shown="flat")
    end_radius: Number | None = key(None, "`pin` with `end = \"sphere\"`: the cap's radius R", shown="a",
                                    allowed=">= a")
    file: str | None = key(None, "`step`, `mesh`: the part file (relative to the scene file); its named "
                           "boundaries, one of them `contact`", shown="—", allowed="an existing file")

    @property
    def part(self):
        """The part file's dimension, boundaries and extent (None for the built-in kinds)."""
        if self.file is None:
            return None
        from .cad import describe
        return describe(self.file, self.kind)

    @property
    def dim(self) -> int:
        return KINDS[self.kind].dim or self.part.dim

    @property
    def boundaries(self) -> tuple[str, ...]:
        return KINDS[self.kind].boundaries or self.part.boundaries

    @property
    def extent(self) -> float:
        """The part's largest dimension (the bound of ``mesh.maxh``)."""
        return _extent(self.kind, self.size, self.part)


class MeshSpec(Section):
    """Netgen mesh size, polynomial order, refinement of Γ_C and grading."""

    maxh: Number | None = key(None, "Netgen's largest element size (not for `geometry.kind = \"mesh\"`)",
                              shown="0.1; a tenth of a file's part", allowed="(0, size of the part]")
    order: Whole = key(1, "polynomial order", ge=1, le=2, allowed="1, 2")
    contact_maxh: Number | None = key(None, "mesh size on Γ_C; for `half_disk` on the arc within "
                                      "`mesh.contact_zone` of its lowest point", shown="`mesh.maxh`",
                                      allowed="(0, maxh]")
    contact_zone: Number | None = key(None, "`half_disk` only: horizontal half-width of the arc refined to "
                                      "`mesh.contact_maxh`", shown="R/4", allowed="(0, R]")
    grading: Number | None = key(None, "Netgen's grading: how fast elements grow away from fine edges (0.1 "
                                 "resolves the field under a Hertz contact)", shown="0.3", ge=0.1, le=1.0)


class Material(Section):
    """Hooke's law σ = 2η ε + λ tr(ε) I, from Lamé (λ, η) or from Young's modulus E and Poisson ν."""

    lame_lambda: Number | None = key(None, "Lamé λ (Hooke: σ = 2η ε + λ tr ε I)", shown="1", ge=0)
    lame_mu: Number | None = key(None, "Lamé η", shown="1", gt=0)
    young: Number | None = key(None, "Young's modulus E (instead of Lamé, with `material.poisson`)", gt=0)
    poisson: Number | None = key(None, "Poisson's ratio ν", gt=-1, le=0.499)

    @property
    def lame(self) -> tuple[float, float]:
        """(λ, η); converts (E, ν) when those are given."""
        if self.young is not None:
            e, nu = self.young, self.poisson
            return e * nu / ((1 + nu) * (1 - 2 * nu)), e / (2 * (1 + nu))
        return self.lame_lambda, self.lame_mu


class Contact(Section):
    """Normal compliance p, soft-layer thickness g, friction μ, wear κ, contact direction ν (a unit vector)."""

    law: Literal["linear", "power"] = key("linear", "compliance p: `linear` L r₊, `power` L r₊^e")
    stiffness: Number = key(10.0, "L", gt=0)
    exponent: Number = key(1.0, "e (power law only)", ge=1, le=10)
    gap: Number = key(0.2, "g, thickness of the soft layer", gt=0)
    friction: Number = key(0.0, "μ", ge=0)
    wear: Number = key(0.0, "κ", ge=0)
    direction: Vector | None = key(None, "ν, the contact direction (outward normal of a flat Γ_C)",
                                   shown="(0, −1) / (0, 0, −1)", allowed="non-zero vector")

    @field_validator("direction")
    @classmethod
    def _unit(cls, direction: Vector | None) -> Vector | None:
        """ν is stored as a unit vector."""
        norm = math.sqrt(sum(v * v for v in direction)) if direction else 1.0
        if norm == 0:
            raise SceneError(f"contact.direction: must be a non-zero vector (got {list(direction)})")
        return tuple(v / norm for v in direction) if direction else direction


class Foundation(Section):
    """Foundation velocity v*(x, t) = s(t) (ω × (x − c) + velocity), s piecewise linear through ``speed_table``."""

    velocity: Vector | None = key(None, "v₀, the foundation's translation velocity", shown="(1, 0) / (1, 0, 0)",
                                  allowed="d numbers")
    angular_velocity: Vector | Number | None = key(
        None, "ω, the counterface's rotation (a disc): v* = s(t)(ω × (x − c) + v₀); a number in 2D", shown="0",
        allowed="3 numbers (3D), a number (2D)")
    center: Vector | None = key(None, "c, a point on the rotation axis", shown="origin", allowed="d numbers")
    speed_table: Table = key((), "v*(x, t) scaled by s(t), piecewise linear through [[t, s], …]",
                             shown="[] (s = 1)", allowed="covers [0, T]")


class Plate(Section):
    """A rigid backing plate on a named boundary B, pressed by a force (force control).

    B moves rigidly: δ along ν (one unknown fixed by the force balance), tangentially held at 0;
    with ``tilt`` also rotating about the two axes ⟂ ν through B's centroid, at zero moment.
    """

    boundary: str = key(..., "the boundary B the plate is bonded to",
                        shown="—", allowed="a named boundary, not clamped, not `contact`")
    force: Vector = key(..., "force on the plate, scaled by `loads.time_table`; its component along ν presses "
                        "the body on the foundation", shown="—", allowed="d numbers")
    tilt: Flag = key(False, "let the plate tilt (two rotations ⟂ ν in 3D, one in 2D) at zero moment")


class Loads(Section):
    """Tractions per named boundary, a body force and a plate force, all scaled by the piecewise-linear ``time_table``."""

    traction: dict[str, Vector] = key({}, "f_N on a named boundary (`loads.traction.<boundary>`)", shown="none",
                                      allowed="non-clamped, non-contact boundaries")
    body_force: Vector | None = key(None, "f₀", shown="none", allowed="d numbers")
    time_table: Table = key((), "f(t) = f · s(t), piecewise linear", shown="[] (s = 1)", allowed="covers [0, T]")
    plate: Plate | None = Field(None, description="a rigid plate pressed by a force (force control)")


class TimeGrid(Section):
    """Time steps: uniform, t_j = j T / steps, or chosen by an error controller (``adaptive``)."""

    T: Number = key(1.0, "final time", gt=0)
    steps: Whole = key(100, "number of steps N (k = T/N); with `time.adaptive` the first step is T/N",
                       ge=1, le=1_000_000)
    adaptive: Flag = key(False, "choose the steps by an error estimate of the wear (see `time.tolerance`)")
    tolerance: Number = key(1e-3, "`adaptive`: the wear error to meet at T, relative to g", gt=0, le=0.5)
    min_step: Number | None = key(None, "`adaptive`: smallest step", shown="T·1e-8", allowed="(0, max_step]")
    max_step: Number | None = key(None, "`adaptive`: largest step", shown="T/10", allowed="(0, T]")


class WearSpec(Section):
    """Wear integrator: the paper's ``explicit`` (eq. 15), ``implicit`` (backward Euler), ``trapezoidal``."""

    integrator: Literal["explicit", "implicit", "trapezoidal"] | None = key(
        None, "`explicit` (paper eq. 15), `implicit` (backward Euler), `trapezoidal`",
        shown="explicit; trapezoidal with `time.adaptive`", allowed="explicit, implicit, trapezoidal")
    allow_unstable: Flag = key(False, "run an explicit update known to diverge (k·α·L > 2 at the uniform step, α "
                               "the largest κ‖v*‖, L the largest slope of p on [0, g]) instead of refusing it")


class SolverSpec(Section):
    """Nonlinear solver: ``condensed`` onto the contact points (fast) or ``full`` system (reference)."""

    method: Literal["condensed", "full"] = key(
        "condensed", "`condensed` (fast) or `full` (straightforward full-system Newton, reference; explicit wear "
        "only)")
    tolerance: Number = key(1e-10, "Newton stopping rule: relative merit", ge=1e-15, le=1e-2)
    max_iterations: Whole = key(50, "Newton iterations per step", ge=1, le=10_000)


class Output(Section):
    """When full fields are written and rendered (by time, whatever the steps), and checkpoints."""

    every: Number | None = key(None, "time between the frames whose full fields are written and rendered "
                               "(from t = 0, plus the last step)", shown="T/4", allowed="(0, T]")
    times: tuple[Number, ...] | None = key(None, "the frames' times (then `output.every` is not used)", shown="—",
                                           allowed="in [0, T], increasing")
    checkpoint_seconds: Number = key(60.0, "wall time between checkpoints of a run with an output folder "
                                     "(0: none)", ge=0)


SECTIONS = {"geometry": Geometry, "mesh": MeshSpec, "material": Material, "contact": Contact,
            "foundation": Foundation, "loads": Loads, "time": TimeGrid, "wear": WearSpec, "solver": SolverSpec,
            "output": Output}


class Scene(BaseModel):
    """A complete, validated simulation set-up.  Build with :func:`load_scene` or :meth:`from_dict`."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    name: str = Field("scene", description="name of the scene (output folder, titles)",
                      pattern=r"^[A-Za-z0-9][A-Za-z0-9._ -]*$", max_length=100)
    geometry: Geometry = Geometry()
    mesh: MeshSpec = MeshSpec()
    material: Material = Material()
    contact: Contact = Contact()
    foundation: Foundation = Foundation()
    loads: Loads = Loads()
    time: TimeGrid = TimeGrid()
    wear: WearSpec = WearSpec()
    solver: SolverSpec = SolverSpec()
    output: Output = Output()

    @property
    def dim(self) -> int:
        return self.geometry.dim

    @property
    def dt(self) -> float:
        return self.time.T / self.time.steps

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Scene:
        """Validate a nested dict (as read from TOML) into a Scene."""
        if not isinstance(data, dict):
            raise SceneError("scene: must be a table")
        try:
            return cls.model_validate(data)
        except ValidationError as err:
            errors = sorted(err.errors(), key=lambda e: e["type"] != "extra_forbidden")  # a typo first
            raise SceneError(_message(errors[0], data)) from None

    def to_dict(self) -> dict[str, Any]:
        """The nested-dict form that :meth:`from_dict` and TOML use (``wear.integrator`` only where it was named)."""
        data = self.model_dump(mode="json", exclude_none=True)
        if "integrator" not in self.wear.model_fields_set:
            data["wear"].pop("integrator")
        return data

    def replace(self, **dotted: Any) -> Scene:
        """A new scene with fields overridden by dotted keys, e.g. ``replace(**{"time.steps": 10})``."""
        data = self.to_dict()
        for name, value in dotted.items():
            set_dotted(data, name, value)
        return Scene.from_dict(data)

    # ---- kind-dependent defaults (before validation) and rules across keys (after) ----------------
    @model_validator(mode="before")
    @classmethod
    def _defaults(cls, data: Any) -> Any:
        """Fill the defaults that depend on the geometry kind and on other keys."""
        if not isinstance(data, dict):
            return data
        data = {name: dict(v) if isinstance(v, dict) else v for name, v in data.items()}
        g = data.get("geometry", {})
        if isinstance(g, dict) and "shape" in g:
            _store_shape(g)
        kind = KINDS.get(g.get("kind", "strip")) if isinstance(g, dict) else None
        if kind is None:
            return data
        part = _part(g)
        dim = kind.dim or (part.dim if part else 3)
        if kind.size is not None:
            _default(data, "geometry", "size", list(kind.size))
        if g.get("kind") == "pin":
            _default(data, "geometry", "position", [1.0, 0.0])
            _default(data, "geometry", "end", "flat")
            if g["end"] == "sphere" and isinstance(g.get("size"), list) and g["size"]:
                _default(data, "geometry", "end_radius", g["size"][0])
        if g.get("kind") != "mesh":
            _default(data, "mesh", "maxh", 0.1 if part is None else float(f"{part.extent / 10:.2g}"))
        _default(data, "geometry", "dirichlet", list(kind.dirichlet))
        _default(data, "contact", "direction", [0.0] * (dim - 1) + [-1.0])
        _default(data, "foundation", "velocity", [1.0] + [0.0] * (dim - 1))
        material = data.get("material", {})
        if isinstance(material, dict) and not {"young", "poisson"} & set(material):
            _default(data, "material", "lame_lambda", 1.0)
            _default(data, "material", "lame_mu", 1.0)
        final = data.get("time", {}).get("T", 1.0) if isinstance(data.get("time"), dict) else 1.0
        if isinstance(final, (int, float)) and not isinstance(final, bool) and final > 0:
            if not isinstance(data.get("output", {}), dict) or "times" not in data.get("output", {}):
                _default(data, "output", "every", final / 4)
            if isinstance(data.get("time", {}), dict) and data.get("time", {}).get("adaptive"):
                _default(data, "time", "min_step", final * 1e-8)
                _default(data, "time", "max_step", final / 10)
        return data

    @model_validator(mode="after")
    def _cross_checks(self) -> Scene:
        if self.wear.integrator is None:    # not named: the paper's explicit scheme, trapezoidal for adaptive steps
            adaptive = self.time.adaptive and self.solver.method == "condensed"
            resolved = WearSpec.model_construct(set(self.wear.model_fields_set), **{
                **self.wear.__dict__, "integrator": "trapezoidal" if adaptive else "explicit"})
            object.__setattr__(self, "wear", resolved)   # a new WearSpec: the field's default one is shared
        _check_geometry(self)
        _check_material(self.material)
        _check_contact(self)
        _check_motion(self)
        _check_loads(self)
        _check_time(self)
        if self.solver.method == "full" and self.wear.integrator != "explicit":
            raise SceneError(f"solver.method: 'full' supports only wear.integrator = 'explicit' "
                             f"(got {self.wear.integrator!r}; use solver.method = 'condensed')")
        return self


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
    geometry = data.get("geometry")
    if isinstance(geometry, dict) and isinstance(geometry.get("file"), str):
        geometry["file"] = str(path.parent / Path(geometry["file"]).expanduser())   # relative to the scene file
    return Scene.from_dict(data)


def set_dotted(data: dict[str, Any], name: str, value: Any) -> None:
    """Set ``data["a"]["b"] = value`` for ``name = "a.b"``; unknown sections are rejected later."""
    parts = name.split(".")
    node = data
    for part in parts[:-1]:
        child = node.setdefault(part, {})
        if not isinstance(child, dict):
            raise SceneError(f"{name}: '{part}' is not a table")
        node = child
    node[parts[-1]] = value


def parse_override(text: str) -> tuple[str, Any]:
    """``"mesh.maxh=0.05"`` → ``("mesh.maxh", 0.05)``; the value is read as a TOML value."""
    name, sep, raw = text.partition("=")
    if not sep or not name.strip():
        raise SceneError(f"--set {text}: expected KEY=VALUE, e.g. time.steps=10")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    return name.strip(), value


def json_schema() -> dict[str, Any]:
    """The scene schema as JSON Schema (for editors that complete and check scene files)."""
    schema = Scene.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "ngwear scene"
    return schema


def reference_table() -> str:
    """The README's scene reference: one Markdown row per key, from the declarations above."""
    rows = ["| key | meaning | default | allowed |", "|---|---|---|---|",
            "| `name` | name of the scene (output folder, titles) | file name | non-empty string |"]

    def table(model: type[BaseModel], prefix: str) -> None:
        for name, info in model.model_fields.items():
            base = _base_type(info.annotation)
            if isinstance(base, type) and issubclass(base, BaseModel):
                table(base, f"{prefix}{name}.")
                continue
            extra = info.json_schema_extra or {}
            default = extra.get("shown", _plain(info.default))
            rows.append(f"| `{prefix}{name}` | {info.description} | {default} | "
                        f"{extra.get('allowed') or _allowed(info)} |")

    for section, model in SECTIONS.items():
        table(model, f"{section}.")
    return "\n".join(rows)


# ---------------------------------------------------------------- part kinds


def _store_shape(g: dict) -> None:
    """``geometry.shape`` (a netgen.occ shape or a mesh, Python only) becomes a cached part file."""
    from .cad import PartError, store
    try:
        g["kind"], g["file"] = store(g.pop("shape"))
    except PartError as err:
        raise SceneError(str(err)) from None
    g.pop("size", None)


def _part(g: dict):
    """The described part file of a raw ``[geometry]`` table (None for built-in kinds); resolves its path."""
    if g.get("kind") not in ("step", "mesh"):
        return None
    file = g.get("file")
    if not isinstance(file, str) or not file:
        raise SceneError(f"geometry.file: must name a file for geometry.kind = {g['kind']!r} (got {file!r})")
    from .cad import PartError, describe
    g["file"] = str(Path(file).expanduser().resolve())
    try:
        return describe(g["file"], g["kind"])
    except PartError as err:
        raise SceneError(f"geometry.file: {err}") from None


def _extent(kind: str, size, part) -> float:
    """The part's largest dimension: of the file, or of the built-in shape from its size."""
    if part is not None:
        return part.extent
    if kind == "pad":
        return max(size[1], size[3])
    return max(size)


# ---------------------------------------------------------------- messages from declarations


def _default(data: dict, section: str, name: str, value: Any) -> None:
    sec = data.setdefault(section, {})
    if isinstance(sec, dict) and name not in sec:
        sec[name] = value


def _plain(value: Any) -> str:
    if value is None or value == () or value == {}:
        return "—"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, str):
        return value
    return f"{value:g}" if isinstance(value, float) else str(value)


def _limits(info: FieldInfo) -> tuple:
    """(lo, hi, lo_open, hi_open) of a declared field."""
    lo = hi = None
    lo_open = hi_open = False
    for m in info.metadata:
        for attr, is_lo, is_open in (("gt", True, True), ("ge", True, False), ("lt", False, True),
                                     ("le", False, False)):
            value = getattr(m, attr, None)
            if value is not None:
                if is_lo:
                    lo, lo_open = value, is_open
                else:
                    hi, hi_open = value, is_open
    return lo, hi, lo_open, hi_open


def range_text(lo=None, hi=None, lo_open=False, hi_open=False) -> str:
    """``> 0``, ``>= 1``, ``<= 2`` or ``in (0, 3.0]``."""
    if lo is not None and hi is not None:
        return f"in {'(' if lo_open else '['}{lo}, {hi}{')' if hi_open else ']'}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {lo}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {hi}"
    return ""


def _allowed(info: FieldInfo) -> str:
    """The allowed values of a declared field, as the reference table states them."""
    base = _base_type(info.annotation)
    if get_origin(base) is Literal:
        return ", ".join(get_args(base))
    if base is bool:
        return "bool"
    return range_text(*_limits(info)) or "—"


def _base_type(annotation):
    """The annotation without ``| None`` and without ``Annotated`` metadata."""
    args = [a for a in get_args(annotation) if a is not type(None)]
    if args and get_origin(annotation) is not Literal and get_origin(annotation) not in (tuple, dict):
        annotation = args[0] if len(args) == 1 else annotation
    while get_origin(annotation) is Annotated:
        annotation = get_args(annotation)[0]
    return annotation


def _field(loc: tuple) -> tuple[str, FieldInfo | None, type[BaseModel] | None]:
    """Dotted name, declaration and owning table of an error location (list indices dropped).

    The location is followed through nested tables (``loads.plate.force``) and into the entries of
    a table of vectors (``loads.traction.top``); a location that ends on a table has no declaration.
    """
    names = [p for p in loc if isinstance(p, str)]
    model, info, used = Scene, None, []
    for part in names:
        used.append(part)
        if model is None:                      # an entry of a dict-valued key: declared by the key
            break
        info = model.model_fields.get(part)
        if info is None:
            break
        base = _base_type(info.annotation)
        if isinstance(base, type) and issubclass(base, BaseModel):
            model, info = base, None
        elif get_origin(base) is dict:
            model = None
        else:
            break
    owner = model if info is None else None
    return ".".join(used) or "scene", info, owner


def _raw(data: Any, dotted: str) -> Any:
    node = data
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def _dim_of(data: Any) -> int | None:
    g = data.get("geometry") if isinstance(data, dict) else None
    kind = KINDS.get(g.get("kind", "strip")) if isinstance(g, dict) else KINDS["strip"]
    return kind.dim if kind and kind.dim else None


def _what(info: FieldInfo, name: str, data: Any) -> tuple[str, str]:
    """(What the value must be, its range), e.g. ("a number", "> 0") or ("a list of 2 numbers", "")."""
    base = _base_type(info.annotation)
    rng = _maxh_range(data) if name == "mesh.maxh" else range_text(*_limits(info))
    if name.startswith("loads.traction."):
        base = Vector
    if get_origin(base) is Literal:
        return "one of " + ", ".join(get_args(base)), ""
    if base is bool:
        return "true or false", ""
    if name == "name":
        return "a plain name of at most 100 letters, digits, '.', '_', '-' or spaces, not a path", ""
    if base is str:
        return "a non-empty string", ""
    if name == "loads.traction":
        return "a table of boundary = [vector]", ""
    if base == Table:
        return "a list of [t, factor] pairs", ""
    if get_origin(base) is tuple:
        if get_args(base)[0] is str:
            return "a list of boundary names", ""
        kind = KINDS.get(_raw(data, "geometry.kind") or "strip")
        sizes = {"geometry.size": len(kind.size) if kind and kind.size else None, "geometry.position": 2}
        count = sizes.get(name, _dim_of(data))
        return (f"a list of {count} numbers" if count else "a list of numbers"), ""
    return ("a whole number" if base is int else "a number"), rng


def _maxh_range(data: Any) -> str:
    kind, size = _raw(data, "geometry.kind") or "strip", _raw(data, "geometry.size")
    if kind in KINDS and isinstance(size, list) and size and all(isinstance(v, (int, float)) for v in size):
        return range_text(0, _extent(kind, size, None), lo_open=True)
    return "> 0"


def _message(err: dict, data: Any) -> str:
    """One line for the first pydantic error: the dotted key, what it must be, what it got."""
    cause = (err.get("ctx") or {}).get("error")
    if isinstance(cause, SceneError):
        return str(cause)
    name, info, owner = _field(err["loc"])
    kind = err["type"]
    if kind == "extra_forbidden":
        table = _field(err["loc"][:-1])[2] or Scene
        what = "section" if table is Scene else "key"
        return f"{name}: unknown {what} (allowed: {', '.join(table.model_fields)})"
    if kind == "missing":
        return f"{name}: missing ({info.description if info else 'a table'})"
    got = _raw(data, name)
    if info is None or owner is not None:
        return f"{name}: must be a table (got {got!r})"
    what, rng = _what(info, name, data)
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        return f"{name}: must be {rng} (got {got!r})"
    if kind == "finite_number":
        return f"{name}: must be {'finite' if what.startswith('a list') else f'a finite {what[2:]} {rng}'.strip()}" \
               f" (got {got!r})"
    return f"{name}: must be {f'{what} {rng}'.strip()} (got {got!r})"


# ---------------------------------------------------------------- rules across keys


def _check_geometry(scene: Scene) -> None:
    g, m, kind = scene.geometry, scene.mesh, KINDS[scene.geometry.kind]
    _check_size(g, kind)
    only = {"position": "pin", "end": "pin", "end_radius": "pin", "file": "step' or 'mesh"}
    for name, owner in only.items():
        if getattr(g, name) is not None and g.kind not in owner.split("' or '"):
            raise SceneError(f"geometry.{name}: only for geometry.kind = '{owner}' (got kind {g.kind!r})")
    boundaries = g.boundaries
    if "contact" not in boundaries:
        raise SceneError(f"geometry.file: {Path(g.file).name} has no boundary named 'contact' (its named "
                         f"boundaries: {', '.join(boundaries) or 'none'})")
    if not g.dirichlet and scene.loads.plate is None:
        raise SceneError("geometry.dirichlet: must name at least one boundary, or give loads.plate (a rigid plate "
                         "pressed along contact.direction) to hold the body (got [])")
    for b in g.dirichlet:
        if b not in boundaries or b == "contact":
            allowed = ", ".join(x for x in boundaries if x != "contact")
            raise SceneError(f"geometry.dirichlet: unknown or non-Dirichlet boundary {b!r} (allowed: {allowed})")
    if g.kind == "mesh":
        if m.maxh is not None or m.contact_maxh is not None or m.grading is not None:
            raise SceneError("mesh.maxh: not used with geometry.kind = 'mesh' (the file is the mesh; leave "
                             "mesh.maxh, mesh.contact_maxh and mesh.grading out)")
    elif not 0 < m.maxh <= g.extent:
        raise SceneError(f"mesh.maxh: must be {range_text(0, round(g.extent, 6), lo_open=True)} (got {m.maxh!r})")
    if m.contact_maxh is not None and not 0 < m.contact_maxh <= m.maxh:
        raise SceneError(f"mesh.contact_maxh: must be {range_text(0, m.maxh, lo_open=True)} (got {m.contact_maxh!r})")
    if m.contact_zone is not None:
        if g.kind != "half_disk":
            raise SceneError(f"mesh.contact_zone: only for geometry.kind = 'half_disk' (got kind {g.kind!r})")
        if not 0 < m.contact_zone <= g.size[0]:
            raise SceneError(f"mesh.contact_zone: must be {range_text(0, g.size[0], lo_open=True)} "
                             f"(got {m.contact_zone!r})")


def _check_size(g: Geometry, kind: Kind) -> None:
    """The size of a built-in kind (lengths, the pad's sector, the pin's cap); none for a file."""
    if kind.size is None:
        if g.size is not None:
            raise SceneError(f"geometry.size: not used with geometry.kind = {g.kind!r} (the file gives the shape)")
        return
    size = g.size
    if len(size) != len(kind.size):
        raise SceneError(f"geometry.size: must be a list of {len(kind.size)} numbers (got {list(size)})")
    if min(size) <= 0:
        raise SceneError(f"geometry.size: every length must be > 0 (got {list(size)})")
    if g.kind == "pad" and not (size[0] < size[1] and size[2] < 360):
        raise SceneError("geometry.size: must be [r_inner, r_outer, angle_deg, thickness] with r_inner < r_outer "
                         f"and angle_deg < 360 (got {list(size)})")
    if g.kind == "pin":
        _vector(g.position, "geometry.position", 2)
        radius, length = size
        if g.end == "sphere":
            if g.end_radius < radius:
                raise SceneError(f"geometry.end_radius: must be >= the pin's radius a = {radius} (got {g.end_radius})")
            cap = g.end_radius - math.sqrt(g.end_radius ** 2 - radius ** 2)
            if cap >= length:
                raise SceneError(f"geometry.size: the pin's length must exceed its cap's height {cap:.4g} (got "
                                 f"{list(size)})")
        elif g.end_radius is not None:
            raise SceneError("geometry.end_radius: only for geometry.end = 'sphere'")


def _check_time(scene: Scene) -> None:
    t, o = scene.time, scene.output
    if not t.adaptive:
        given = [k for k in ("min_step", "max_step") if getattr(t, k) is not None]
        if given:
            raise SceneError(f"time.{given[0]}: only with time.adaptive = true")
    elif not 0 < t.min_step <= t.max_step <= t.T:
        raise SceneError(f"time.max_step: must satisfy 0 < time.min_step <= time.max_step <= time.T = {t.T} "
                         f"(got {t.min_step!r}, {t.max_step!r})")
    if o.times is not None:
        if not o.times or any(b <= a for a, b in zip(o.times, o.times[1:])) or o.times[0] < 0 or o.times[-1] > t.T:
            raise SceneError(f"output.times: must be increasing times in [0, time.T] = [0, {t.T}] (got {list(o.times)})")
    elif not 0 < o.every <= t.T:
        raise SceneError(f"output.every: must be a time in (0, time.T] = (0, {t.T}] (got {o.every!r})")


def _check_material(mat: Material) -> None:
    lame = [k for k in ("lame_lambda", "lame_mu") if getattr(mat, k) is not None]
    engineering = [k for k in ("young", "poisson") if getattr(mat, k) is not None]
    if lame and engineering:
        raise SceneError(f"material.{engineering[0]}: cannot be combined with material.{lame[0]} "
                         "(give either lame_lambda and lame_mu, or young and poisson)")
    missing = [k for k in (("young", "poisson") if engineering else ("lame_lambda", "lame_mu"))
               if getattr(mat, k) is None]
    if missing:
        together = "young and poisson" if engineering else "lame_lambda and lame_mu"
        raise SceneError(f"material.{missing[0]}: missing ({together} go together)")


def _vector(value, name: str, dim: int) -> tuple[float, ...]:
    if value is None or len(value) != dim:
        raise SceneError(f"{name}: must be a list of {dim} numbers (got {list(value) if value else value!r})")
    return value


def _check_contact(scene: Scene) -> None:
    c = scene.contact
    _vector(c.direction, "contact.direction", scene.dim)
    if c.law == "linear" and c.exponent != 1:
        raise SceneError(f"contact.exponent: must be 1 with contact.law = 'linear' (got {c.exponent!r})")


def _check_motion(scene: Scene) -> None:
    f, c, T, nu = scene.foundation, scene.contact, scene.time.T, scene.contact.direction
    velocity = _vector(f.velocity, "foundation.velocity", scene.dim)
    if f.center is not None:
        _vector(f.center, "foundation.center", scene.dim)
    omega = f.angular_velocity
    if scene.dim == 2 and isinstance(omega, tuple):
        raise SceneError(f"foundation.angular_velocity: must be a number in 2D (got {list(omega)})")
    if scene.dim == 3 and omega is not None and (not isinstance(omega, tuple) or len(omega) != 3):
        raise SceneError(f"foundation.angular_velocity: must be a list of 3 numbers in 3D (got {omega!r})")
    _check_table(f.speed_table, "foundation.speed_table", T)
    vn = sum(a * b for a, b in zip(velocity, nu))
    speed = math.sqrt(sum(v * v for v in velocity))
    tangential = math.sqrt(sum((v - vn * n) ** 2 for v, n in zip(velocity, nu)))
    # a rotation slides Γ_C over the foundation when its axis is not parallel to the contact plane
    spin = abs(omega or 0.0) if scene.dim == 2 else abs(sum(a * b for a, b in zip(omega or (0, 0, 0), nu)))
    if c.friction > 0 and tangential <= 1e-12 * speed and spin == 0:
        raise SceneError("foundation.velocity: must have a non-zero part tangential to contact.direction "
                         "(or give foundation.angular_velocity about an axis along it) when contact.friction > 0 "
                         f"(got {list(velocity)})")
    if c.wear > 0 and speed == 0 and spin == 0:
        raise SceneError("foundation.velocity: must be non-zero (or give foundation.angular_velocity) when "
                         f"contact.wear > 0 (got {list(velocity)})")


def _check_table(table, name: str, T: float) -> None:
    times = [t for t, _ in table]
    if any(b < a for a, b in zip(times, times[1:])):
        raise SceneError(f"{name}: times must be non-decreasing (got {times})")
    if table and (times[0] > 0 or times[-1] < T):
        raise SceneError(f"{name}: must cover [0, time.T] = [0, {T}] (got {times[0]} to {times[-1]})")


def _check_loads(scene: Scene) -> None:
    loads, g = scene.loads, scene.geometry
    boundaries = g.boundaries
    for bname, vec in loads.traction.items():
        if bname not in boundaries or bname == "contact" or bname in g.dirichlet:
            allowed = ", ".join(x for x in boundaries if x != "contact" and x not in g.dirichlet)
            raise SceneError(f"loads.traction.{bname}: unknown or non-Neumann boundary (allowed: {allowed})")
        _vector(vec, f"loads.traction.{bname}", scene.dim)
    if loads.body_force is not None:
        _vector(loads.body_force, "loads.body_force", scene.dim)
    _check_table(loads.time_table, "loads.time_table", scene.time.T)
    if loads.plate is not None:
        _check_plate(scene, boundaries)


def _check_plate(scene: Scene, boundaries: tuple[str, ...]) -> None:
    plate, g = scene.loads.plate, scene.geometry
    taken = {"contact", *g.dirichlet, *scene.loads.traction}
    if plate.boundary not in boundaries or plate.boundary in taken:
        allowed = ", ".join(b for b in boundaries if b not in taken)
        raise SceneError(f"loads.plate.boundary: unknown, clamped, loaded or contact boundary {plate.boundary!r} "
                         f"(allowed: {allowed})")
    force = _vector(plate.force, "loads.plate.force", scene.dim)
    pressing = sum(f * n for f, n in zip(force, scene.contact.direction))
    floating = not g.dirichlet
    if floating and pressing <= 0:
        raise SceneError(f"loads.plate.force: must press the body onto the foundation (a positive component along "
                         f"contact.direction) when nothing is clamped (got {list(force)})")
    if floating and any(f < 0 for _, f in scene.loads.time_table):
        raise SceneError("loads.time_table: factors must be >= 0 when only the plate holds the body (a pulling "
                         "plate would lift the body off)")
