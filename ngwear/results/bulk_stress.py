"""The stress in the body for a frame: σ = F(ε(u)) of each region's law and its von Mises value.

σ is written as a 3 × 3 tensor (ParaView's nine components): in 2D (plane strain, ε₃₃ = ε₁₃ = ε₂₃ = 0) the in-plane
block of the law's σ with σ₃₃ from the law (:meth:`~ngwear.model.materials.Law.out_of_plane`: C₃₃ₖ ε_k of a linear
law, λ tr ε + β min(tr ε, 0) of the compaction law) and σ₁₃ = σ₂₃ = 0.  The von Mises stress of the 3 × 3 tensor is

    σ_vM = √(3/2 s : s),      s = σ − (tr σ / 3) I.

A 2D ``energy`` law ψ(ε) of the in-plane strain does not define σ₃₃: its regions get σ₃₃ = 0 (:func:`unknown_normal`
names them).  NGSolve evaluates both where VTKOutput asks (the frames' points): the cost is the frames' only.
"""
from __future__ import annotations

import ngsolve as ngs

from ..model.materials import region_laws, strain


def stress_fields(scene, mesh: ngs.Mesh, u: ngs.GridFunction) -> tuple[ngs.CoefficientFunction, ngs.CoefficientFunction]:
    """(σ as a 3 × 3 CoefficientFunction, σ_vM) of displacement ``u``, each region's law on its elements."""
    eps = strain(u)
    sigma = mesh.MaterialCF({region: full_tensor(law, eps) for region, law in region_laws(scene).items()})
    return sigma, von_mises(sigma)


def full_tensor(law, eps: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
    """σ of ``law`` at ε as a 3 × 3 tensor (2D: plane strain, σ₃₃ from the law or 0)."""
    sigma = law.stress(eps)
    if law.dim == 3:
        return sigma
    normal = law.out_of_plane(eps)
    return ngs.CF((sigma[0, 0], sigma[0, 1], 0, sigma[1, 0], sigma[1, 1], 0, 0, 0, 0 if normal is None else normal),
                  dims=(3, 3))


def von_mises(sigma: ngs.CoefficientFunction) -> ngs.CoefficientFunction:
    """√(3/2 s : s) of a 3 × 3 stress, s its deviator."""
    s = sigma - ngs.Trace(sigma) / 3 * ngs.Id(3)
    return ngs.sqrt(1.5 * ngs.InnerProduct(s, s))


def unknown_normal(scene) -> list[str]:
    """The regions of a 2D scene whose law does not define σ₃₃ (written 0)."""
    if scene.dim == 3:
        return []
    return [region for region, law in region_laws(scene).items() if law.out_of_plane(ngs.Id(2)) is None]
