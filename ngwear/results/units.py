"""The units of a run's numbers: SI when the scene declares ``units = "SI"``, none for a dimensionless scene.

A scene in SI gives lengths in m, forces in N, pressures and moduli in Pa and times in s; what a run computes
follows from them.  The contact points' weights m_i are areas (m²) in 3D and, in 2D (plane strain, per unit
thickness), lengths (m): so forces Σ m_i p_i are N in 3D and N/m in 2D, torques N·m and N·m/m, contact areas
m² and m, worn volumes Σ m_i w_i m³ and m².  :func:`units` maps the name of each number a run writes (a key of
``result.npz`` or ``summary.json``) to its unit; :func:`label` appends a unit to a plot's label.
"""
from __future__ import annotations

from .step_fields import STEP_FIELDS
from .whole_run import QUANTITIES as RUN

QUANTITIES = {"length": ("m", "m"), "time": ("s", "s"), "pressure": ("Pa", "Pa"), "force": ("N", "N/m"),
              "torque": ("N·m", "N·m/m"), "area": ("m²", "m"), "volume": ("m³", "m²"),
              "power": ("W", "W/m"), "energy": ("J", "J/m"), "mass": ("kg", "kg/m"), "angle": ("rad", "rad"),
              "velocity": ("m/s", "m/s"), "temperature": ("°C", "°C"), "temperature difference": ("K", "K"),
              "expansion": ("1/K", "1/K"),
              "line load": ("N/m", "N/m"), "wear coefficient": ("1/Pa", "1/Pa"), "compliance stiffness": ("Pa/m", "Pa/m")}
"""Each quantity's unit in 3D and in 2D (per unit thickness).  κ in w' = κ‖v*‖p is 1/Pa; L in p = L r₊ is Pa/m
(``Pa/m^e`` for the power law p = L r₊^e).  Temperatures are the scene's (`heat.ambient`, …): °C (a difference: K)."""

NAMES = {**{f.name: f.quantity for f in STEP_FIELDS if f.quantity}, **RUN, "contact_points": "length",
         "weights": "area", "fields": "length", "max_wear": "length", "max_penetration": "length", "gap": "length",
         "thickness": "length", **{f"remaining_thickness_{m}": "length" for m in ("min", "mean", "max")},
         **{f"taper_{m}": "length" for m in ("radial", "circumferential", "along")},
         "max_temperature_time": "time", "max_foundation_temperature": "temperature",
         "max_foundation_temperature_time": "time", "temperature_fields": "temperature"}
"""The quantity of each number a run writes: its per-step fields' (:mod:`ngwear.results.step_fields`) and the others
with a unit (the rest are counts, fractions, ratios or wall-clock seconds)."""


def unit(scene, quantity: str) -> str | None:
    """The unit of ``quantity`` (a key of :data:`QUANTITIES`) in ``scene``; None for a dimensionless scene."""
    if scene.units is None:
        return None
    if quantity == "compliance stiffness" and scene.contact.law == "power":
        return f"Pa/m^{scene.contact.exponent:g}"
    return QUANTITIES[quantity][0 if scene.dim == 3 else 1]


def suffix(scene, quantity: str) -> str:
    """`` unit`` of a quantity in an SI scene (to follow a number), nothing in a dimensionless one."""
    symbol = unit(scene, quantity)
    return "" if symbol is None else f" {symbol}"


def units(scene, names=NAMES) -> dict[str, str] | None:
    """``{name: unit}`` for the ``names`` of a run's numbers (default: all of :data:`NAMES`); None if dimensionless.

    ``plate_displacement`` in ``result.npz`` holds the plate's translation (m) and then its tilts (rad).
    """
    if scene.units is None:
        return None
    return {name: unit(scene, NAMES[name]) for name in names if name in NAMES}


def label(scene, text: str, quantity: str) -> str:
    """``text (unit)`` in an SI scene, ``text`` in a dimensionless one."""
    symbol = unit(scene, quantity)
    return text if symbol is None else f"{text} ({symbol})"
