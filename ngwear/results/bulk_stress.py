"""The stress in the body for a frame: σ = F(ε(u)) of each region's law and its von Mises value.

σ is a 3 × 3 tensor (ParaView's nine components): in 2D (plane strain, ε₃₃ = ε₁₃ = ε₂₃ = 0) the in-plane block of
the law's σ with σ₃₃ from the law (:meth:`~ngwear.model.materials.Law.out_of_plane`: C₃₃ₖ ε_k of a linear law,
λ tr ε + β min(tr ε, 0) of the compaction law) and σ₁₃ = σ₂₃ = 0; a 2D ``energy`` law ψ(ε) of the in-plane strain
does not define σ₃₃, and its regions get σ₃₃ = 0 (:func:`unknown_normal` names them).  The von Mises stress is

    σ_vM = √(3/2 s : s),      s = σ − (tr σ / 3) I.

For the frames, :class:`BulkStress` projects σ element by element onto the polynomials of degree p − 1 (L², one
local solve per element): exact for linear laws, whose σ of u ∈ P_p is in P_{p−1}, and for any law on P1 elements
(ε constant), the L² best fit of a nonlinear law's σ on P2.  NGSolve evaluates the law at the elements' integration
points all at once; σ_vM is that of the projected tensor.  It is computed for the frames alone: no step pays for it.
"""
from __future__ import annotations

import ngsolve as ngs

from ..model.materials import region_laws, strain


class BulkStress:
    """σ of displacement ``u`` (a GridFunction the frames change) in ``tensor``, and ``von_mises`` of it.

    :meth:`update` projects σ of the current ``u``; ``exact`` is σ itself (a CoefficientFunction, each region's law
    on its elements).
    """

    def __init__(self, scene, mesh: ngs.Mesh, u: ngs.GridFunction):
        eps = strain(u)
        self.exact = mesh.MaterialCF({region: full_tensor(law, eps) for region, law in region_laws(scene).items()})
        self.tensor = ngs.GridFunction(ngs.MatrixValued(ngs.L2(mesh, order=scene.mesh.order - 1), dim=3))
        self.von_mises = von_mises(self.tensor)

    def update(self) -> None:
        """Project σ of the current displacement."""
        self.tensor.Set(self.exact)


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
