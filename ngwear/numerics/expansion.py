"""Thermal expansion as a load on the displacement space: the elastic factorisation stays.

With the thermal strain ε_th = α_th (T − T₀) I of each region, a linear law σ = C (ε(u) − ε_th) makes the
body's equations a(u, v) = ℓ(v) + f_th(v) − (contact), with the load

    f_th(v) = Σ_r ∫_r (T − T₀) β_r : ε(v) dx,    β_r = C_r : (α_r I)  (:func:`ngwear.model.thermal.thermal_stress`),

which is G (T − T₀) for the temperature's DOF vector T (P1) and the matrix G_ij = Σ_r ∫_r φ_j β_r : ε(v_i) dx
assembled once per mesh: a step's thermal load is one sparse product.  A nonlinear law takes the load of its
tangent at ε = 0 (the stiffness K₀ its step solver starts from): exact while a region stays on that branch of a
piecewise-linear law — for the compaction law the compressed one, where a pressed, heated layer is (a free,
heated body of it would expand by (2η + 3λ + 3β)/(2η + 3λ) too much) — and to first order in the strain for
``energy`` (3D only).  The exact σ = F(ε(u) − ε_th) belongs in the bulk iteration's remainder
(:mod:`ngwear.numerics.fixed_point`): K₀ u + n(u) = ℓ + f_th − (contact) with f_th as here and
n(u) = ∫ (F − C₀)(ε(u) − ε_th) : ε(v) dx, C₀ the tangent at ε = 0.
"""
from __future__ import annotations

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from ..model.materials import region_laws
from ..model.thermal import region_properties, thermal_stress


class ThermalLoad:
    """f_th = G (T − T₀) on the displacement space ``fes`` for temperatures T in the P1 ``space`` of the same mesh.

    Parameters
    ----------
    scene : Scene
        The laws and α_th of its regions, T₀ (``heat.initial``).
    fes : ngsolve.FESpace
        The displacement space.
    space : ngsolve.FESpace
        The temperature's space (:attr:`ngwear.numerics.heat.Heat.space`).

    Attributes
    ----------
    matrix : scipy.sparse.csr_matrix or None
        G (fes.ndof × space.ndof); None when no region expands (α_th = 0 everywhere): the load is 0.
    """

    def __init__(self, scene, fes: ngs.FESpace, space: ngs.FESpace):
        self.start, self.ndof = scene.heat.start, fes.ndof
        laws, props = region_laws(scene), region_properties(scene)
        moduli = {r: thermal_stress(law, props[r].expansion) for r, law in laws.items() if props[r].expansion}
        self.matrix = _coupling(fes, space, moduli) if moduli else None

    def __call__(self, temperature: np.ndarray) -> np.ndarray:
        """f_th for the temperature DOF vector T: G (T − T₀)."""
        if self.matrix is None:
            return np.zeros(self.ndof)
        return self.matrix @ (np.asarray(temperature, dtype=float) - self.start)


def _coupling(fes: ngs.FESpace, space: ngs.FESpace, moduli: dict) -> sp.csr_matrix:
    """G_ij = Σ_r ∫_r φ_j β_r : ε(v_i) dx (``moduli``: {region: β_r, d × d}), as CSR."""
    theta, v = space.TrialFunction(), fes.TestFunction()
    dim = fes.mesh.dim
    form = ngs.BilinearForm(trialspace=space, testspace=fes)
    for region, beta in moduli.items():
        tensor = ngs.CF(tuple(float(b) for b in np.ravel(beta)), dims=(dim, dim))
        form += theta * ngs.InnerProduct(tensor, ngs.Sym(ngs.Grad(v))) * ngs.dx(definedon=fes.mesh.Materials(region))
    form.Assemble()
    values, columns, pointers = form.mat.CSR()
    return sp.csr_matrix((np.array(values), np.array(columns), np.array(pointers)), shape=(fes.ndof, space.ndof))
