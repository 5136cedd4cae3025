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

import numpy as np

from . import mandel
from .keys import SceneError


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


def partition(scene, contact_regions) -> float:
    """η, the body's share of the frictional heat: ``heat.partition``, or e_b / (e_b + e_f) for ``effusivity``.

    ``contact_regions``: the regions whose elements carry Γ_C; with ``effusivity`` they must share one e_b.
    """
    share = scene.heat.partition
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

