"""Each region's material as a run's summary reports it: its law, its constants, and m_F and L_F of H(F).

    (F(ε₁) − F(ε₂)) : (ε₁ − ε₂) ≥ m_F |ε₁ − ε₂|²,      |F(ε₁) − F(ε₂)| ≤ L_F |ε₁ − ε₂|.

The laws of :mod:`ngwear.model.materials` give m_F and L_F in closed form (Hooke: m_F = min(2η, 2η + dλ); compaction:
m_F = 2η, L_F = 2η + d(λ + β) for λ, β ≥ 0); a law marked ``estimated`` (a user's energy ψ) has none, and its
m_F ≈ min λ_min(D), L_F ≈ max |λ(D)| are estimated from the tangent D(ε) at the integration points of its region over
the run's frames (:func:`~ngwear.model.moduli.estimate_moduli`; ``estimated`` counts the samples).  Constants are
listed under their scene keys (``young``, ``poisson``, …) and shown by :func:`describe` with the symbols their laws
declare (moduli in Pa in an SI scene).
"""
from __future__ import annotations

import numpy as np

from ..model.keys import Vector
from ..model.materials import constants, region_laws, strain
from ..model.moduli import estimate_moduli, tangent_values


def region_materials(scene, disc=None, fields=()) -> dict[str, dict]:
    """``{region: {"law": …, <constant>: …, "m_F": …, "L_F": …}}`` of a scene's regions, in their order.

    An ``energy`` law gets m_F and L_F estimated over the displacement DOF vectors ``fields`` on ``disc`` (and
    ``estimated``, the number of sampled tangents); without them it has neither.
    """
    laws = region_laws(scene)
    out = {}
    for name, table in scene.material.by_region(scene.geometry.regions).items():
        entry = {"law": table.kind}
        for constant in listed():
            value = getattr(table, constant.name)
            if value is not None:
                entry[constant.name] = list(value) if constant.type is Vector else float(value)
        law = laws[name]
        if not law.estimated:
            entry.update(m_F=float(law.monotonicity), L_F=float(law.lipschitz))
        elif disc is not None and len(fields):
            moduli = estimated(law, name, disc, fields)
            entry.update(m_F=moduli.monotonicity, L_F=moduli.lipschitz, estimated=moduli.samples)
        out[name] = entry
    return out


def estimated(law, region: str, disc, fields):
    """m_F and L_F of ``law`` sampled at the integration points of ``region`` for each displacement of ``fields``."""
    mesh = disc.mesh
    tangents = [tangent_values(law, strain(disc.gridfunction(u)), mesh, definedon=mesh.Materials(region))
                for u in fields]
    return estimate_moduli(np.concatenate(tangents))


def describe(entry: dict, unit: str | None = None) -> str:
    """``transversely_isotropic E_plane=2e+09 … axis=(0, 0, -1); m_F = …, L_F = …`` (moduli in ``unit``)."""
    symbols = {c.name: c.symbol for c in listed()}
    moduli = {c.name for c in listed() if c.modulus} | {"m_F", "L_F"}

    def number(key, value):
        if isinstance(value, list):
            return "(" + ", ".join(f"{c:g}" for c in value) + ")"
        return f"{value:.4g}" + (f" {unit}" if unit and key in moduli else "")

    given = " ".join(f"{symbols[k]}={number(k, v)}" for k, v in entry.items() if k in symbols)
    if "m_F" not in entry:
        bounds = "m_F, L_F not estimated (no strains)"
    else:
        how = f" (estimated at {entry['estimated']} points)" if "estimated" in entry else ""
        bounds = f"m_F = {number('m_F', entry['m_F'])}, L_F = {number('L_F', entry['L_F'])}{how}"
    return f"{entry['law']} {given}; {bounds}" if given else f"{entry['law']}; {bounds}"


def listed():
    """The constants a summary lists (those with a symbol), in the order the laws declare them."""
    return [c for c in constants() if c.symbol is not None]
