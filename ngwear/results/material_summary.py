"""Each region's material as a run's summary reports it: its law, its constants, and m_F and L_F of H(F).

    (F(ε₁) − F(ε₂)) : (ε₁ − ε₂) ≥ m_F |ε₁ − ε₂|²,      |F(ε₁) − F(ε₂)| ≤ L_F |ε₁ − ε₂|.

The laws of :mod:`ngwear.model.materials` give m_F and L_F in closed form (Hooke: m_F = min(2η, 2η + dλ); compaction:
m_F = 2η, L_F = 2η + d(λ + β) for λ, β ≥ 0); a user's energy ψ has none, and its m_F ≈ min λ_min(D), L_F ≈
max |λ(D)| are estimated from the tangent D(ε) at the integration points of its region over the run's frames
(:func:`~ngwear.model.materials.estimate_moduli`; ``estimated`` counts the samples).  Constants are listed under
their scene keys (``young``, ``poisson``, …) and shown by :func:`describe` with their symbols.
"""
from __future__ import annotations

import numpy as np

from ..model.materials import region_laws, strain
from ..model.moduli import estimate_moduli, tangent_values

SYMBOLS = {"young": "E", "poisson": "ν", "lame_lambda": "λ", "lame_mu": "η", "young_plane": "E_plane",
           "young_axis": "E_axis", "poisson_plane": "ν_plane", "poisson_axis": "ν_axis", "shear_axis": "G_axis",
           "axis": "axis", "compaction_modulus": "β"}
"""The constants a summary lists (scene key → symbol); ``energy`` (a Python function) is not a number."""
MODULI = ("young", "lame_lambda", "lame_mu", "young_plane", "young_axis", "shear_axis", "compaction_modulus",
          "m_F", "L_F")
"""The entries that are moduli (Pa in an SI scene)."""


def region_materials(scene, disc=None, fields=()) -> dict[str, dict]:
    """``{region: {"law": …, <constant>: …, "m_F": …, "L_F": …}}`` of a scene's regions, in their order.

    An ``energy`` law gets m_F and L_F estimated over the displacement DOF vectors ``fields`` on ``disc`` (and
    ``estimated``, the number of sampled tangents); without them it has neither.
    """
    laws = region_laws(scene)
    out = {}
    for name, table in scene.material.by_region(scene.geometry.regions).items():
        entry = {"law": table.kind}
        for key in SYMBOLS:
            value = getattr(table, key)
            if value is not None:
                entry[key] = list(value) if key == "axis" else float(value)
        law = laws[name]
        if hasattr(law, "monotonicity"):
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
    def number(key, value):
        if key == "axis":
            return "(" + ", ".join(f"{c:g}" for c in value) + ")"
        return f"{value:.4g}" + (f" {unit}" if unit and key in MODULI else "")

    constants = " ".join(f"{SYMBOLS[k]}={number(k, v)}" for k, v in entry.items() if k in SYMBOLS)
    if "m_F" not in entry:
        moduli = "m_F, L_F not estimated (no strains)"
    else:
        how = f" (estimated at {entry['estimated']} points)" if "estimated" in entry else ""
        moduli = f"m_F = {number('m_F', entry['m_F'])}, L_F = {number('L_F', entry['L_F'])}{how}"
    return f"{entry['law']} {constants}; {moduli}" if constants else f"{entry['law']}; {moduli}"
