"""Plausibility of a scene in SI units: moduli, stiffnesses and wear coefficients far from engineering materials'.

In a scene with ``units = "SI"`` the numbers are in m, N, Pa and s.  A modulus, a contact stiffness or a wear
coefficient far outside what engineering materials have is most likely a slip of units (``young = 210`` for steel:
GPa meant, Pa given), which a small-strain run would turn into metres of displacement without a word.
:func:`warnings` names each such key, before the run; the run goes on (the values are valid, only unlikely).

The ranges are those of engineering materials widened tenfold on each side:

* moduli (``young``, ``lame_lambda``, ``lame_mu``, ``young_plane``, ``young_axis``, ``shear_axis``,
  ``compaction_modulus`` of ``[material]`` and its regions): solids span 1e5 Pa (polymer foams) to 1.2e12 Pa
  (diamond) on Ashby's modulus charts: outside [1e4, 1e13] Pa is warned of (λ and β may be 0: ν = 0, no
  compaction);
* the contact stiffness L: p(g) = L g^e is the pressure of the layer compressed through, its modulus times a strain
  of one: L g^e outside [1e4, 1e13] Pa;
* the wear coefficient κ, Archard's dimensional coefficient K/H in 1/Pa (= m³/(N·m)): from 1e-18 1/Pa (mild wear,
  1e-9 mm³/(N·m)) to 1e-9 1/Pa (severe abrasion, 1 mm³/(N·m)): outside [1e-19, 1e-8] 1/Pa (0: no wear).

* the friction coefficient μ: dry and lubricated pairs lie in [0, 1.5] (clean metals in vacuum excepted); outside
  it is warned of;
* temperatures (``heat.ambient``, ``heat.initial``, ``foundation.temperature``): ngwear's are °C; one between 253
  and 323 looks like a room temperature in kelvin (−20 to 50 °C);
* the loads, once the part is meshed (:func:`load_warnings`): the mean contact pressure of a plate's force over
  Γ_C, and a traction's magnitude, against the 10 kPa–100 MPa of contact pressures in engineering widened tenfold.

Fields given as expressions are not looked at (their values are known at the contact points only); arrays by their
smallest and largest value.
"""
from __future__ import annotations

MODULI = ("young", "lame_lambda", "lame_mu", "young_plane", "young_axis", "shear_axis", "compaction_modulus")
MAY_BE_ZERO = ("lame_lambda", "compaction_modulus")
MODULUS = (1e4, 1e13)
"""Pa: the moduli of engineering solids (1e5 to 1.2e12 Pa), widened tenfold."""
WEAR = (1e-19, 1e-8)
"""1/Pa: Archard's dimensional wear coefficients K/H of engineering pairs (1e-18 to 1e-9 1/Pa), widened tenfold."""
FRICTION = (0.0, 1.5)
"""μ of engineering pairs, dry or lubricated."""
KELVIN = (253.0, 323.0)
"""A temperature here, in °C, looks like −20 to 50 °C given in kelvin."""
PRESSURE = (1e3, 1e9)
"""Pa: contact pressures in engineering (10 kPa to 100 MPa), widened tenfold."""


def warnings(scene) -> list[str]:
    """One line for each modulus, stiffness or wear coefficient of an SI scene far outside engineering materials'."""
    if scene.units != "SI":
        return []
    out = []
    tables = {"material": scene.material, **{f"material.regions.{name}": table
                                            for name, table in scene.material.regions.items()}}
    moduli = "the moduli of engineering materials (1e5 Pa, foams, to 1.2e12 Pa, diamond)"
    for prefix, table in tables.items():
        for name in MODULI:
            value = getattr(table, name)
            if value is not None and not (value == 0 and name in MAY_BE_ZERO):
                out += _outside(f"{prefix}.{name} = {value:g} Pa", value, MODULUS, moduli, ("GPa or MPa", None))
    contact = scene.contact
    for value in _numbers(contact.stiffness):
        pressure = value * contact.gap ** contact.exponent
        out += _outside(f"contact.stiffness = {value:g} Pa/m^{contact.exponent:g} (L g^e = {pressure:.3g} Pa, the layer "
                        "compressed through)", pressure, MODULUS, moduli, ("GPa/m or MPa/m", None))
    for value in _numbers(contact.wear):
        if value:
            out += _outside(f"contact.wear = {value:g} 1/Pa", value, WEAR, "Archard's wear coefficients of engineering "
                            "pairs (1e-18 to 1e-9 1/Pa, 1e-9 to 1 mm³/(N·m))", (None, "mm³/(N·m)"))
    for value in _numbers(contact.friction):
        if not FRICTION[0] <= value <= FRICTION[1]:
            out.append(f"contact.friction = {value:g}: outside the [0, 1.5] of engineering pairs' μ (dry or "
                       "lubricated)")
    heat, temperature = scene.heat, scene.foundation.temperature
    temperatures = {"heat.ambient": heat.ambient, "heat.initial": heat.initial,
                    "foundation.temperature": temperature if isinstance(temperature, (int, float)) else None}
    for name, value in temperatures.items():
        if heat.model != "none" and value is not None and KELVIN[0] <= value <= KELVIN[1]:
            out.append(f"{name} = {value:g} °C looks like a temperature in kelvin ({value - 273.15:.4g} °C; "
                       "ngwear's temperatures are °C)")
    return out


def load_warnings(scene, area: float) -> list[str]:
    """One line for each load of an SI scene whose contact pressure is far outside engineering's (:data:`PRESSURE`).

    ``area``: Γ_C's (m², or m per unit thickness in 2D).  A plate's force over it is the mean contact pressure it
    makes; a traction is itself a pressure on its boundary.
    """
    if scene.units != "SI":
        return []
    loads, out = scene.loads, []
    pressures = "contact pressures in engineering (10 kPa to 100 MPa)"
    if loads.plate is not None and area > 0:
        pressing = abs(sum(f * n for f, n in zip(loads.plate.force, scene.contact.direction)))
        out += _outside(f"loads.plate.force = {list(loads.plate.force)} (a mean contact pressure of "
                        f"{pressing / area:.3g} Pa over Γ_C)", pressing / area, PRESSURE, pressures, ("kN", None))
    for name, vector in loads.traction.items():
        size = max(abs(v) for v in vector)
        if size:
            out += _outside(f"loads.traction.{name} = {list(vector)} Pa", size, PRESSURE, pressures, ("MPa", None))
    return out


def _outside(what: str, value: float, bounds: tuple[float, float], range_of: str, units) -> list[str]:
    """``what`` is far below or above ``bounds``, with the unit (below, above) it was perhaps given in."""
    low, high = bounds
    if low <= value <= high:
        return []
    side, unit = ("below", units[0]) if value < low else ("above", units[1])
    return [f"{what}: far {side} {range_of}" + (f"; is it in {unit}? (units = \"SI\": Pa, m, N, s)" if unit else "")]


def _numbers(value) -> tuple[float, ...]:
    """The values of a coefficient known before the run: a number, or an array's extremes (an expression: none)."""
    if isinstance(value, (int, float)):
        return (float(value),)
    if isinstance(value, tuple) and value:
        return tuple(sorted({min(value), max(value)}))
    return ()


def softest(scene) -> tuple[str, float | None]:
    """(key, value): the modulus most likely behind strains too large, the smallest of the region softest along ν.

    Across the part the regions carry about the same stress σ_νν one after the other, so the region with the
    smallest modulus E_ν along ν (:func:`~ngwear.model.materials.young_along`) strains most, ε = σ/E_ν; of its
    moduli, the smallest given one (a slip of units makes one far smaller than the others).  The key is the region's
    own (``material.regions.backing.young``) or the default table's it inherits (``material.young``).
    """
    from .materials import region_laws, young_along

    laws = region_laws(scene)
    region = min(laws, key=lambda name: young_along(laws[name], scene.contact.direction))
    material = scene.material
    own = material.regions[region] if region in material.regions else None
    table = material.by_region([region])[region]
    given = [(getattr(table, name), name) for name in MODULI if getattr(table, name)]
    if not given:
        return f"material.regions.{region}" if own is not None else "material", None
    value, name = min(given)
    mine = own is not None and getattr(own, name, None) is not None
    return f"material.regions.{region}.{name}" if mine else f"material.{name}", value


def unlikely_modulus(scene, value: float | None) -> bool:
    """Whether ``value`` is a modulus of an SI scene far below engineering materials' (:data:`MODULUS`)."""
    return scene.units == "SI" and value is not None and value < MODULUS[0]
