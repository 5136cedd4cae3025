"""The tables of a scene file and their keys, each declared once: type, range, documentation, what it invalidates.

The top-level keys ``name`` and ``units``, then ``[geometry]``, ``[mesh]``, ``[material]``, ``[contact]``,
``[foundation]``, ``[loads]`` (with ``plate``), ``[time]``, ``[wear]``, ``[solver]``, ``[output]`` (the run's
controls, declared in :mod:`ngwear.model.controls`), ``[heat]`` (in :mod:`ngwear.model.thermal`) and ``[programme]``
(its blocks of stops, in :mod:`ngwear.model.programme`).  Ranges
that depend on other keys are rules of :mod:`ngwear.model.rules`; the kinds of ``geometry.kind`` come from the registry
(:mod:`ngwear.model.kinds`).
"""
from __future__ import annotations

import math
from typing import Literal, get_args, get_origin

from pydantic import Field, create_model, field_validator

from . import shapes, user_parts  # noqa: F401 - they register the part kinds
from .coefficients import normalised
from .compliance import COMPLIANCES
from .controls import Output, SolverSpec, TimeGrid, WearSpec
from .keys import Flag, Level, Number, SceneError, Section, Table, Vector, Whole, key
from .kinds import KINDS, ordered
from .materials import LAWS, constants, groups, lame
from .programme import Programme
from .thermal import HeatSpec
from .wear_laws import WEAR_LAWS
from .wear_laws import constants as wear_constants

KindName = Literal[tuple(kind.name for kind in ordered())]
Coefficient = float | str | tuple[float, ...] | Table


class TopLevel(Section):
    """The keys outside the tables: the scene's name and its unit system."""

    name: str = key("scene", "name of the scene (output folder, titles)", reuse=Level.NOTHING, shown="file name",
                    allowed="letters, digits, `._ -` (at most 100)", pattern=r"^[A-Za-z0-9][A-Za-z0-9._ -]*$",
                    max_length=100)
    units: Literal["SI"] | None = key(None, "the unit system of the numbers: `SI` (m, N, Pa, s) puts units on the "
                                      "summary, the plots and the result files; absent: dimensionless (the paper's "
                                      "scenes)", reuse=Level.NOTHING, shown="— (dimensionless)", allowed="SI")


class Geometry(Section):
    """Body shape: a built-in kind with its ``size``, or the user's part from ``file`` (:mod:`ngwear.model.user_parts`)."""

    kind: KindName = key("strip", "; ".join(k.doc for k in ordered()), reuse=Level.MESH)
    size: Vector | None = key(None, ", ".join(k.size_doc for k in ordered() if k.size) + "; not for files",
                              reuse=Level.MESH, allowed="lengths > 0",
                              shown=" / ".join(str(list(k.size)).replace(".0,", ",").replace(".0]", "]")
                                               for k in ordered() if k.size))
    dirichlet: tuple[str, ...] | None = key(None, "clamped boundaries", reuse=Level.SPACE,
                                            shown="[left]; [top] (`half_disk`); [] (`pad`, `pin`, files)",
                                            allowed="named boundaries except `contact`")
    position: Vector | None = key(None, "`pin`: (x, y) of its axis on the disc", reuse=Level.MESH, shown="(1, 0)",
                                  allowed="2 numbers")
    end: Literal["flat", "sphere"] | None = key(None, "`pin`: a flat end, or a spherical cap touching the disc at "
                                                "its lowest point (curved Γ_C, initial distance d₀)",
                                                reuse=Level.MESH, shown="flat")
    end_radius: Number | None = key(None, "`pin` with `end = \"sphere\"`: the cap's radius R", reuse=Level.MESH,
                                    shown="a", allowed="[a, a²/(2·10⁻³ size)]: a cap at least 10⁻³ of the pin deep")
    file: str | None = key(None, "`step`, `mesh`: the part file (relative to the scene file); its named "
                           "boundaries, one of them `contact`", reuse=Level.MESH, shown="—", allowed="an existing file")
    backing: Number | None = key(None, "`strip`, `box`, `pad`, `pin`: thickness t_b of a second region `backing` "
                                 "glued onto the face opposite Γ_C (a backing plate); the face between them is "
                                 "`interface`", reuse=Level.MESH, shown="none", allowed="> 0", gt=0)

    @property
    def part(self) -> user_parts.Part | None:
        """The part file's dimension, boundaries and extent (None for the built-in kinds; read before validation)."""
        return None if self.file is None else user_parts.describe(self.file, self.kind)

    @property
    def dim(self) -> int:
        return KINDS[self.kind].dim or self.part.dim

    @property
    def boundaries(self) -> tuple[str, ...]:
        return KINDS[self.kind].boundaries or self.part.boundaries

    @property
    def extent(self) -> float:
        """The part's largest dimension, its backing included (the bound of ``mesh.maxh``)."""
        if self.file is not None:
            return self.part.extent
        kind, size = KINDS[self.kind], list(self.size)
        if self.backing is not None:
            size[kind.thickness] += self.backing
        return kind.extent(size)

    @property
    def regions(self) -> tuple[str, ...]:
        """The names of the part's regions: ``body`` (which carries Γ_C) and ``backing``, or the file's."""
        if self.file is not None:
            return self.part.regions
        return ("body", "backing") if self.backing is not None else ("body",)


class MeshSpec(Section):
    """Netgen mesh size, polynomial order, refinement of Γ_C and grading."""

    maxh: Number | None = key(None, "Netgen's largest element size (not for `geometry.kind = \"mesh\"`)",
                              reuse=Level.MESH, shown="0.1; a tenth of a file's part", allowed="(0, size of the part]")
    order: Whole = key(1, "polynomial order", reuse=Level.SPACE, ge=1, le=2, allowed="1, 2")
    contact_maxh: Number | None = key(None, "mesh size on Γ_C, or within `mesh.contact_zone` of it only",
                                      reuse=Level.MESH, shown="`mesh.maxh`", allowed="(0, maxh]")
    contact_zone: Number | None = key(None, "with `mesh.contact_maxh`: refine Γ_C only where it lies within this "
                                      "distance of `mesh.zone_center`, measured across `contact.direction` (the "
                                      "half-disk's horizontal half-width), growing smoothly (`mesh.grading`) away "
                                      "from it", reuse=Level.MESH, shown="R/4 (`half_disk`); none: all of Γ_C",
                                      allowed="(0, size of the part]")
    zone_center: Vector | None = key(None, "the point the zone is measured from", reuse=Level.MESH,
                                     shown="the part's first point of contact: the middle of a flat Γ_C (the pad's "
                                     "centre), the tip of a curved one (the pin's axis)", allowed="d numbers")
    grading: Number | None = key(None, "Netgen's grading: how fast elements grow away from fine edges (0.1 "
                                 "resolves the field under a Hertz contact)", reuse=Level.MESH, shown="0.3",
                                 ge=0.1, le=1.0)
    max_elements: Whole = key(2_000_000, "most elements Netgen may make: a part whose count, estimated from its size, "
                              "`mesh.maxh` and `mesh.contact_maxh`, is larger is refused before meshing (the default "
                              "fits a P1 run in 24 GB, see the guide)", reuse=Level.NOTHING, ge=1)


class MaterialBase(Section):
    """The keys of one material that do not depend on its law: the ``law``; :data:`MaterialLaw` adds the laws'."""

    law: Literal[tuple(LAWS)] | None = key(None, "; ".join(f"`{name}` {law.doc}" for name, law in LAWS.items()),
                                           reuse=Level.STIFFNESS, shown="linear")

    @property
    def kind(self) -> str:
        """The law (``linear`` when none is given)."""
        return self.law or next(iter(LAWS))

    @property
    def lame(self) -> tuple[float, float]:
        """(λ, η) of the isotropic constants; converts (E, ν) when those are given."""
        return lame(self)

    @property
    def given(self) -> bool:
        """Whether the table gives any constant (or ψ)."""
        return any(getattr(self, c.name) is not None for c in constants())


THERMAL_KEYS = {
    "conductivity": (Number | None, key(None, "k, the thermal conductivity (`heat.model = \"conduction\"`)",
                                        reuse=Level.NOTHING, shown="—", gt=0)),
    "heat_capacity": (Number | None, key(None, "c, the specific heat capacity (per unit mass)", reuse=Level.NOTHING,
                                         shown="—", gt=0)),
    "density": (Number | None, key(None, "ρ, the density (the heat capacity per volume is ρc; the summary's worn "
                                         "mass)", reuse=Level.NOTHING, shown="—", gt=0)),
    "expansion": (Number | None, key(None, "α_th, the linear thermal expansion coefficient: the thermal strain "
                                     "α_th (T − T₀) I loads the body (`heat.model = \"conduction\"`)",
                                     reuse=Level.NOTHING, shown="0", allowed="a number")),
    "max_temperature": (Number | None, key(None, "the highest temperature the material stands (`heat.model = "
                                           "\"conduction\"`): a run whose body passes it there says so, naming the "
                                           "region, the step and the temperature", reuse=Level.NOTHING,
                                           shown="none")),
}
"""A material's thermal keys: they hold for any law, and a region without its own takes ``[material]``'s."""
THERMAL = tuple(THERMAL_KEYS)

MaterialLaw = create_model("MaterialLaw", __base__=MaterialBase, __module__=__name__,
                           __doc__="One material: its ``law`` and constants (σ = F(ε), paper H(F)); see "
                                   ":mod:`ngwear.model.materials`.",
                           **{c.name: c.declaration() for c in constants()}, **THERMAL_KEYS)
"""One material's table: :class:`MaterialBase`, the constants the laws declare (:mod:`ngwear.model.materials`) and
the thermal keys."""


class Material(MaterialLaw):
    """``[material]``, the material of every region; ``[material.regions.NAME]`` (the same keys) overrides it."""

    regions: dict[str, MaterialLaw] = key({}, "`material.regions.<region>`: the material of one region (a table of "
                                          "the keys above), merged over `[material]`; another law, or constants "
                                          "given another way, replace `[material]`'s", reuse=Level.STIFFNESS,
                                          shown="none",
                                          allowed="the part's regions (`body`, `backing`, a file's)")

    def by_region(self, names) -> dict[str, MaterialLaw]:
        """The material of each of the regions ``names``: its own table merged over this default."""
        default = self.model_dump(exclude_none=True, exclude={"regions"})
        mine = {k for group in groups() if set(group) & set(default) for k in group}
        every = {c.name for c in constants()}
        out = {}
        for name in names:
            own = self.regions[name].model_dump(exclude_none=True) if name in self.regions else {}
            alien = {k for k in own if k in every and k not in mine}
            replaced = own.get("law", default.get("law")) != default.get("law") or alien
            thermal = {k: v for k, v in default.items() if k in THERMAL}
            out[name] = MaterialLaw.model_validate({**thermal, **own} if replaced else {**default, **own})
        return out


class ContactLaw(Section):
    """The compliance p of ``[contact]``: its ``law`` and stiffness L; :data:`ContactLawKeys` adds the laws' own keys."""

    law: Literal[tuple(COMPLIANCES)] = key(next(iter(COMPLIANCES)), "compliance p: " + ", ".join(
        f"`{name}` {law.doc}" for name, law in COMPLIANCES.items()), reuse=Level.NOTHING)
    stiffness: Coefficient = key(10.0, "L, a number or a field over Γ_C (as `contact.friction`)", reuse=Level.NOTHING,
                                 allowed="> 0 at every contact point")


ContactLawKeys = create_model("ContactLawKeys", __base__=ContactLaw, __module__=__name__,
                              **{c.name: c.declaration() for law in COMPLIANCES.values() for c in law.constants})
"""The compliance's keys: :class:`ContactLaw` and those the laws declare (:mod:`ngwear.model.compliance`)."""


class WearLawKey(ContactLawKeys):
    """The wear law of ``[contact]``; :data:`WearLawKeys` adds the laws' own keys (:mod:`ngwear.model.wear_laws`)."""

    wear_law: Literal[tuple(WEAR_LAWS)] = key(next(iter(WEAR_LAWS)), "the wear law: " + ", ".join(
        f"`{name}` {law.doc}" for name, law in WEAR_LAWS.items()), reuse=Level.NOTHING)


WearLawKeys = create_model("WearLawKeys", __base__=WearLawKey, __module__=__name__,
                           **{c.name: c.declaration() for c in wear_constants()})
"""The wear law's keys: :class:`WearLawKey` and those the laws declare."""


class Contact(WearLawKeys):
    """Normal compliance p, soft-layer thickness g, friction μ, wear κ, contact direction ν (a unit vector)."""

    gap: Number = key(0.2, "g, thickness of the soft layer", reuse=Level.NOTHING, gt=0)
    friction: Coefficient = key(0.0, "μ: a number, or a field over Γ_C: an expression in x, y, z with + − * / **, "
                                "sqrt, exp, log, sin, cos, atan2, hypot, abs, min, max, pi and where(condition, a, b) "
                                "(e.g. `where(hypot(x, y) < 0.12, 0.3, 0.45)`), which may also use the state of the "
                                "last step at the point: T (the surface temperature), p (the pressure), v (the sliding "
                                "speed); or a table [[T, value], …] of the temperature (piecewise linear, constant "
                                "beyond its ends); in Python also an array over the contact points or a function of "
                                "them", reuse=Level.NOTHING, allowed=">= 0 at every contact point")
    wear: Coefficient = key(0.0, "κ, a number or a field over Γ_C (as `contact.friction`)", reuse=Level.NOTHING,
                            allowed=">= 0 at every contact point")
    direction: Vector | None = key(None, "ν, the contact direction (outward normal of a flat Γ_C)",
                                   reuse=Level.DIRECTION, shown="(0, −1) / (0, 0, −1)", allowed="non-zero vector")

    @field_validator("friction", "wear", "stiffness", mode="before")
    @classmethod
    def _coefficient(cls, value, info):
        """A number, an expression (its syntax checked), a function's token or an array; ranges where known."""
        return normalised(value, info.field_name)

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

    velocity: Vector | None = key(None, "v₀, the foundation's translation velocity (a disc, "
                                  "`foundation.angular_velocity` given, does not translate unless this is given)",
                                  reuse=Level.NOTHING, shown="(1, 0) / (1, 0, 0); 0 with `angular_velocity`",
                                  allowed="d numbers")
    angular_velocity: Vector | Number | None = key(
        None, "ω, the counterface's rotation (a disc): v* = s(t)(ω × (x − c) + v₀); a number in 2D",
        reuse=Level.NOTHING, shown="0", allowed="3 numbers (3D), a number (2D)")
    center: Vector | None = key(None, "c, a point on the rotation axis", reuse=Level.NOTHING, shown="origin",
                                allowed="d numbers")
    speed_table: Table = key((), "v*(x, t) scaled by s(t), piecewise linear through [[t, s], …]", reuse=Level.NOTHING,
                             shown="[] (s = 1)", allowed="covers [0, T]")
    temperature: Number | Table | None = key(None, "`heat`: the counterface's given temperature T_f, a number or "
                                             "piecewise linear through [[t, T_f], …] (not with "
                                             "`foundation.thermal_mass`)", reuse=Level.NOTHING,
                                             shown="`heat.ambient`", allowed="a number, or a table covering [0, T]")
    thermal_mass: Number | None = key(None, "`heat`: C_d, the heat capacity of a lumped counterface (a disc) that "
                                      "takes the heat the body does not and cools: "
                                      "C_d dT_f/dt = (1 − η) Q − H_d (T_f − T_∞)", reuse=Level.NOTHING, shown="none",
                                      gt=0)
    cooling: Number | None = key(None, "`heat`: H_d, the lumped counterface's cooling (heat per unit time and degree)",
                                 reuse=Level.NOTHING, shown="—", allowed=">= 0, with `foundation.thermal_mass`", ge=0)
    conductivity: Number | None = key(None, "`heat.partition = \"effusivity\"`: the counterface's k",
                                      reuse=Level.NOTHING, shown="—", gt=0)
    density: Number | None = key(None, "`heat.partition = \"effusivity\"`: the counterface's ρ", reuse=Level.NOTHING,
                                 shown="—", gt=0)
    heat_capacity: Number | None = key(None, "`heat.partition = \"effusivity\"`: the counterface's c",
                                       reuse=Level.NOTHING, shown="—", gt=0)
    max_temperature: Number | None = key(None, "`heat`: the highest temperature the counterface stands: a run whose "
                                         "counterface passes it says so, with the step and the temperature",
                                         reuse=Level.NOTHING, shown="none")

    @field_validator("temperature", mode="before")
    @classmethod
    def _temperature(cls, value):
        """A finite number or a table of [t, T_f] pairs."""
        if value is None or (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)):
            return value
        rows = value if isinstance(value, (list, tuple)) else None
        if not rows or not all(isinstance(r, (list, tuple)) and len(r) == 2 and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in r) for r in rows):
            raise SceneError(f"foundation.temperature: must be a finite number or a table [[t, T], …] of finite "
                             f"numbers (got {value!r})")
        return value


class Plate(Section):
    """A rigid backing plate on a named boundary B, pressed by a force (force control).

    B moves rigidly: δ along ν (one unknown fixed by the force balance), tangentially held at 0;
    with ``tilt`` also rotating about the two axes ⟂ ν through B's centroid, at zero moment.
    """

    boundary: str = key(..., "the boundary B the plate is bonded to", reuse=Level.SPACE,
                        shown="—", allowed="a named boundary, not clamped, not `contact`")
    force: Vector = key(..., "force on the plate, scaled by `loads.time_table`; its component along ν presses "
                        "the body on the foundation", reuse=Level.LOADS, shown="—", allowed="d numbers")
    tilt: Flag = key(False, "let the plate tilt (two rotations ⟂ ν in 3D, one in 2D) at zero moment",
                     reuse=Level.DIRECTION)


class Loads(Section):
    """Tractions per named boundary, a body force and a plate force, all scaled by the piecewise-linear ``time_table``."""

    traction: dict[str, Vector] = key({}, "f_N on a named boundary (`loads.traction.<boundary>`)", reuse=Level.LOADS,
                                      shown="none", allowed="non-clamped, non-contact boundaries")
    body_force: Vector | None = key(None, "f₀", reuse=Level.LOADS, shown="none", allowed="d numbers")
    time_table: Table = key((), "f(t) = f · s(t), piecewise linear", reuse=Level.NOTHING, shown="[] (s = 1)",
                            allowed="covers [0, T]")
    plate: Plate | None = Field(None, description="a rigid plate pressed by a force (force control)")


SECTIONS = {"geometry": Geometry, "mesh": MeshSpec, "material": Material, "contact": Contact,
            "foundation": Foundation, "loads": Loads, "time": TimeGrid, "wear": WearSpec, "heat": HeatSpec,
            "solver": SolverSpec, "output": Output, "programme": Programme}


def nested_table(info) -> type[Section] | None:
    """The section a field holds (``loads.plate``: :class:`Plate`), or None for a key (a table or list of tables too)."""
    if get_origin(info.annotation) in (dict, tuple):
        return None
    for candidate in (info.annotation, *get_args(info.annotation)):
        if isinstance(candidate, type) and issubclass(candidate, Section):
            return candidate
    return None


def declared_keys():
    """(dotted name, declaration) of every scene key, in file order: the top-level keys, then the tables' (nested too)."""
    def walk(model, prefix):
        for name, info in model.model_fields.items():
            table = nested_table(info)
            if table is None:
                yield f"{prefix}{name}", info
            else:
                yield from walk(table, f"{prefix}{name}.")

    yield from walk(TopLevel, "")
    for section, model in SECTIONS.items():
        yield from walk(model, f"{section}.")
