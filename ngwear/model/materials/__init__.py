"""Elasticity laws σ = F(ε) (paper H(F)): strongly monotone with m_F, Lipschitz with L_F, each declared once.

    (F(ε₁) − F(ε₂)) : (ε₁ − ε₂) ≥ m_F |ε₁ − ε₂|²,      |F(ε₁) − F(ε₂)| ≤ L_F |ε₁ − ε₂|.

Every law here is hyperelastic, σ = ∂ψ/∂ε, with a symmetric tangent D(ε) = ∂σ/∂ε; in Mandel notation
(:mod:`ngwear.model.mandel`) m_F = inf_ε λ_min(D(ε)) and L_F = sup_ε max |λ(D(ε))|.  A law is one frozen dataclass,
a :class:`Law`, in a module of this package, registered with :func:`register`: it declares its ``material.law``
name, its constants (scene keys with ranges, documentation and summary symbols, :class:`~ngwear.model.keys.Constant`)
and the ways to give them, and it gives the numerics what they need (the protocol of :class:`Law`).  The scene's
``[material]`` table (:mod:`ngwear.model.sections`), its JSON Schema and reference, the rules of its constants
(:func:`check_table`), a run's summary (:mod:`ngwear.results.material_summary`) and the explorer's sliders all read
the declarations.  Laws: :mod:`.linear` (``linear``: Hooke; ``transversely_isotropic``; and
:class:`~.linear.Anisotropic`, a Mandel stiffness the scene does not name), :mod:`.compaction` (stiffer in
compression) and :mod:`.energy` (a user's ψ, differentiated by NGSolve).  2D is plane strain (ε₃₃ = ε₁₃ = ε₂₃ = 0).
A law that is not positive definite is refused with a :class:`SceneError` naming the scene key (``key`` is the
table, ``material`` or ``material.regions.NAME``).
"""
from __future__ import annotations

import numpy as np

from .. import mandel
from ..keys import Constant, SceneError
from . import compaction, energy, linear  # linear registers first (the others build on it): the default
from .compaction import Compaction
from .energy import Energy
from .law import LAWS, Law, register, strain
from .linear import Anisotropic, Isotropic, TransverselyIsotropic, lame


def constants() -> tuple[Constant, ...]:
    """Every constant of the registered laws, each once, in the order of registration (the ``[material]`` keys)."""
    return tuple(dict.fromkeys(c for law in LAWS.values() for c in law.constants()))


def groups() -> tuple[tuple[str, ...], ...]:
    """The constants that are given together: those in the same ways of the laws (optional ones in all of theirs).

    ``(lame_lambda, lame_mu)``, ``(young, poisson)``, … : a region's table that gives constants of other groups than
    ``[material]``'s replaces ``[material]``'s constants (:meth:`~ngwear.model.sections.Material.by_region`).
    """
    ways = {c.name: frozenset((law.name, i) for law in LAWS.values() for i, way in enumerate(law.ways)
                              if c in way or c in law.optional) for c in constants()}
    by_ways: dict[frozenset, list[str]] = {}
    for name, places in ways.items():
        by_ways.setdefault(places, []).append(name)
    return tuple(tuple(names) for names in by_ways.values())


def default_constants(given) -> dict[str, float]:
    """The default law's ``defaults`` (the paper's λ = η = 1) for a raw ``[material]`` giving the constants ``given``.

    None where it gives a constant that no way of those takes (E, ν, ψ, …).
    """
    defaults = next(iter(LAWS.values())).defaults
    along = {c.name for law in LAWS.values() for way in law.ways if set(defaults) <= {c.name for c in way}
             for c in way}
    return {} if ({c.name for c in constants()} - along) & set(given) else dict(defaults)


def takes(law: str, constant: str) -> bool:
    """Whether the law named ``law`` takes the constant ``constant`` (a ``[material]`` key)."""
    return any(c.name == constant for c in LAWS[law].constants())


def check_table(table, key: str) -> None:
    """Refuse a material table whose constants do not fit its law: one line naming the key (``key.young``)."""
    law = LAWS[table.kind]
    ways = [tuple(c.name for c in way) for way in law.ways]
    given = {c.name for c in constants() if getattr(table, c.name) is not None}
    allowed = {k for way in ways for k in way} | {c.name for c in law.optional}
    choices = "either " + ", or ".join(_listing(way) for way in ways) if len(ways) > 1 else _listing(ways[0])
    stray = sorted(given - allowed)
    if stray:
        raise SceneError(f"{key}.{stray[0]}: not a constant of material.law = {law.name!r} (give {choices})")
    common = set.intersection(*(set(way) for way in ways))
    used = [way for way in ways if (set(way) - common) & given]
    if len(used) > 1:
        first, second = (next(k for k in way if k in given and k not in common) for way in used[:2])
        raise SceneError(f"{key}.{second}: cannot be combined with {key}.{first} (give {choices})")
    way = used[0] if used else ways[0]
    missing = [name for name in way if name not in given]
    if missing:
        raise SceneError(f"{key}.{missing[0]}: missing ({_listing(way)} go together)")


def _listing(names) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return " and ".join([", ".join(names[:-1]), names[-1]] if len(names) > 1 else names)


def law_of(table, dim: int, direction, key: str = "material") -> Law:
    """The law of a checked material table (``direction``: the default axis of a transversely isotropic one)."""
    return LAWS[table.kind].of(table, dim, direction, key)


def region_laws(scene) -> dict:
    """{region: law} of a scene: each region's table over ``[material]``, the axis defaulting to ν."""
    material, direction = scene.material, scene.contact.direction
    return {name: law_of(table, scene.dim, direction, f"material.regions.{name}" if name in material.regions
                         else "material")
            for name, table in material.by_region(scene.geometry.regions).items()}


def young_along(law, direction) -> float:
    """E_n = 1 / (n⊗n : S : n⊗n), S = D(0)⁻¹: the modulus of a uniaxial stress along the unit vector n."""
    n = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    dyad = mandel.to_mandel(np.outer(n, n)[None])[0]
    return float(1.0 / (dyad @ np.linalg.solve(law.tangent_at_zero().matrix, dyad)))

__all__ = ["LAWS", "Anisotropic", "Compaction", "Energy", "Isotropic", "Law", "TransverselyIsotropic", "check_table",
           "compaction", "constants", "default_constants", "energy", "groups", "lame", "law_of", "linear",
           "region_laws", "register", "strain", "takes", "young_along"]
