"""The thermal constants of a scene: k, ρc and α_th per region, the partition η of the frictional heat, thermal stress.

Per region (``material.conductivity`` k, ``heat_capacity`` c, ``density`` ρ, ``expansion`` α_th, merged over
``[material]`` as the law's constants are) the heat equation ρc ∂T/∂t = ∇·(k∇T) and the thermal strain
ε_th = α_th (T − T₀) I.  The body takes the share η of the frictional heat (``heat.partition``), a number or
Charron's partition of two semi-infinite bodies in perfect contact,

    η = e_b / (e_b + e_f),    e = √(kρc) (the effusivity),

e_b of the region that carries Γ_C, e_f of the counterface (``foundation.conductivity``, ``density``,
``heat_capacity``).  A linear law's thermal stress per unit temperature rise is β = C : (α_th I) with the 3D
stiffness C; in 2D (plane strain, ε₃₃ = 0) its in-plane block, which the out-of-plane expansion loads through
C₁₃, C₂₃ (Hooke: β = (3λ + 2η) α_th I = E α_th / (1 − 2ν) I in 2D and 3D, λ and η the Lamé constants).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import field_validator

from . import mandel
from .coefficients import normalised
from .keys import Level, Number, SceneError, Section, key


@dataclass(frozen=True)
class Thermal:
    """One region's k, ρc (the heat capacity per volume) and α_th."""

    conductivity: float
    capacity: float
    expansion: float

    @property
    def effusivity(self) -> float:
        """The effusivity e = √(k ρc)."""
        return math.sqrt(self.conductivity * self.capacity)


def region_properties(scene) -> dict[str, Thermal]:
    """{region: Thermal} of a scene whose regions all give k, ρ and c (``heat.model = "conduction"``)."""
    return {name: Thermal(table.conductivity, table.density * table.heat_capacity, table.expansion or 0.0)
            for name, table in scene.material.by_region(scene.geometry.regions).items()}


def limited(scene) -> bool:
    """Whether the scene limits a temperature: ``material.max_temperature`` of a region, ``foundation.max_temperature``."""
    return scene.foundation.max_temperature is not None or any(
        table.max_temperature is not None for table in scene.material.by_region(scene.geometry.regions).values())


def partition(scene, contact_regions) -> float:
    """η, the body's share of the frictional heat: ``heat.partition``, or e_b / (e_b + e_f) for ``effusivity``.

    With ``heat.interface = "conductance"`` and no partition given: ½.

    ``contact_regions``: the regions whose elements carry Γ_C; with ``effusivity`` they must share one e_b.
    """
    share = scene.heat.partition
    if share is None and scene.heat.interface == "conductance":
        return 0.5                              # the faces' exchange evens out the split (docs/guide/heat.md)
    if share != "effusivity":
        return float(share)
    props, f = region_properties(scene), scene.foundation
    body = {props[name].effusivity for name in contact_regions}
    if len(body) != 1:
        raise SceneError(f"heat.partition: 'effusivity' needs one effusivity √(kρc) on Γ_C (the regions "
                         f"{', '.join(contact_regions)} carrying it differ); give a number")
    e_body, e_face = body.pop(), math.sqrt(f.conductivity * f.density * f.heat_capacity)
    return e_body / (e_body + e_face)


def thermal_stress(law, alpha: float) -> np.ndarray:
    """β = C : (α I), d × d: the stress that a free thermal strain α I (unit temperature rise) relieves.

    C is the law's tangent at ε = 0 (for a nonlinear law: the linear law its stiffness K₀ is built from; for the
    compaction law the compressed branch, on which a pressed, heated layer is), in 3D; in 2D the in-plane block of
    the 3D C acting on the 3D thermal strain (plane strain).
    """
    linear = law.tangent_at_zero()
    stress = mandel.from_mandel(linear.stiffness_3d @ (alpha * mandel.to_mandel(np.eye(3))))
    return stress[:linear.dim, :linear.dim]


# ---------------------------------------------------------------- the scene's [heat] table


class Convection(Section):
    """One entry of ``heat.convection``: −k ∂T/∂n = h (T − T_∞) on a named boundary."""

    boundary: str = key(..., "a named boundary of the part, not `contact`", reuse=Level.NOTHING)
    coefficient: Number = key(..., "h, the heat transfer coefficient", reuse=Level.NOTHING, ge=0)


class HeatSpec(Section):
    """Heat conduction in the body, ρc ∂T/∂t = ∇·(k∇T), heated on Γ_C by friction (see :mod:`ngwear.numerics.heat`)."""

    model: Literal["none", "conduction"] = key(
        "none", "`none`: no temperature (the paper's model); `conduction`: the temperature of the body, heated by "
        "the share η of the frictional power μ p ‖v*‖ on Γ_C", reuse=Level.NOTHING)
    partition: Number | Literal["effusivity"] | None = key(
        None, "η, the share of the frictional heat that enters the body (the rest the counterface): a number, or "
        "`effusivity`: η = e_b / (e_b + e_f), e = √(kρc) of the body's region on Γ_C and of the counterface "
        "(`foundation.conductivity`, `density`, `heat_capacity`)", reuse=Level.NOTHING,
        shown="— (needed with `conduction`)", allowed="in [0, 1], effusivity")
    convection: tuple[Convection, ...] = key(
        (), "[{ boundary, coefficient }, …]: convection −k ∂T/∂n = h (T − T_∞) on these boundaries; every other "
        "boundary is adiabatic", reuse=Level.NOTHING, shown="[] (all adiabatic)",
        allowed="named boundaries except `contact`, each once; h >= 0")
    ambient: Number = key(0.0, "T_∞, the surroundings' temperature (convection, the counterface's cooling)",
                          reuse=Level.NOTHING)
    initial: Number | None = key(None, "T₀, the initial temperature of the body and of a lumped counterface; the "
                                 "stress-free temperature of `material.expansion`", reuse=Level.NOTHING,
                                 shown="`heat.ambient`")
    interface: Literal["partition", "conductance"] = key(
        "partition", "how the frictional heat meets the counterface: `partition` (the body takes the share η of "
        "q = μ p ‖v*‖, whatever the faces' temperatures), `conductance` (q split by η at the interface, and the faces "
        "exchange h_c (T_f − T) where they touch, implicitly)", reuse=Level.NOTHING)
    contact_conductance: float | str | tuple[float, ...] | tuple[tuple[float, float], ...] | None = key(
        None, "`heat.interface = \"conductance\"`: h_c, the heat the touching faces exchange per unit area and "
        "degree (where they do not touch, none): a number or a field over Γ_C (as `contact.friction`: of x, y, z "
        "and the state p, T, v)", reuse=Level.NOTHING, shown="— (needed with `conductance`)",
        allowed=">= 0 at every contact point")
    scheme: Literal["consistent", "bounded"] = key(
        "consistent", "the heat's backward-Euler step: `consistent` (the consistent capacity and conduction, most "
        "accurate at the face; where a step is short against h²/κ a node may fall below T₀, which a run says), "
        "`bounded` (flux-corrected: no temperature below the lowest it started from or is cooled towards)",
        reuse=Level.NOTHING)

    @field_validator("contact_conductance", mode="before")
    @classmethod
    def _conductance(cls, value):
        """A number, an expression (its syntax checked) or a table of T, as a contact coefficient."""
        return None if value is None else normalised(value, "heat.contact_conductance")

    @field_validator("convection", mode="before")
    @classmethod
    def _convection(cls, entries):
        """A list of tables { boundary = name, coefficient = h >= 0 }, each refused by its index."""
        if not isinstance(entries, (list, tuple)):
            raise SceneError(f"heat.convection: must be a list of tables {{ boundary, coefficient }} (got {entries!r})")
        for i, entry in enumerate(entries):
            name = f"heat.convection[{i}]"
            if isinstance(entry, Convection):
                continue
            if not isinstance(entry, dict) or set(entry) != {"boundary", "coefficient"}:
                raise SceneError(f"{name}: must be a table {{ boundary = NAME, coefficient = h }} (got {entry!r})")
            h = entry["coefficient"]
            if not isinstance(entry["boundary"], str):
                raise SceneError(f"{name}.boundary: must be a boundary's name (got {entry['boundary']!r})")
            if isinstance(h, bool) or not isinstance(h, (int, float)) or not math.isfinite(h) or h < 0:
                raise SceneError(f"{name}.coefficient: must be a finite number >= 0 (got {h!r})")
        return entries

    @field_validator("partition", mode="before")
    @classmethod
    def _partition(cls, value):
        """A number in [0, 1] or ``"effusivity"``."""
        number = isinstance(value, (int, float)) and not isinstance(value, bool)
        if value is None or value == "effusivity" or (number and 0 <= value <= 1):
            return value
        raise SceneError(f"heat.partition: must be a number in [0, 1] or 'effusivity' (got {value!r})")

    @property
    def start(self) -> float:
        """T₀: ``heat.initial``, or ``heat.ambient`` when it is not given."""
        return self.ambient if self.initial is None else self.initial
