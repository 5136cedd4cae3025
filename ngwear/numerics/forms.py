"""NGSolve forms on the body and on Γ_C.

Elastic form  a(u, v) = ∫_Ω F(ε(u)) : ε(v) dx,  load  ℓ(v) = ∫_Ω f₀·v dx + Σ ∫_ΓN f_N·v da.

Contact form (the nonlinear boundary integrator, paper φ with fixed w):

    φ(w, u, v) = ∫_ΓC p(u_ν − d₀ − w) (v_ν + μ n*·v_τ) da,   u_ν = u·ν,   n* = n*(x),

integrated with the *nodal* rule of the element (:func:`contact_ds`): the integral is Σ_i m_i p_i (ν + μ n*)·v(x_i)
over the contact points x_i with weights m_i (:mod:`ngwear.numerics.points`).
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np

from ..model.compliance import Compliance
from ..model.scene import Scene
from .points import NODAL_WEIGHTS

_REFERENCE = {2: (ngs.SEGM, [(0.0,), (1.0,)], 1.0), 3: (ngs.TRIG, [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)], 0.5)}


def contact_ds(dim: int, order: int):
    """ds("contact") with the nodal integration rule of the contact elements (:data:`NODAL_WEIGHTS`)."""
    et, corners, measure = _REFERENCE[dim]
    vertex, midpoint = NODAL_WEIGHTS[dim, order]
    points, weights = (list(corners), [measure * vertex] * len(corners)) if vertex else ([], [])
    if order == 2:
        pairs = [(0, 1)] if dim == 2 else [(0, 1), (1, 2), (2, 0)]
        points += [tuple(0.5 * (np.array(corners[a]) + np.array(corners[b]))) for a, b in pairs]
        weights += [measure * midpoint] * len(pairs)
    return ngs.ds("contact", intrules={et: ngs.IntegrationRule(points, weights)})


def displacement_space(mesh: ngs.Mesh, scene: Scene) -> ngs.FESpace:
    """Vector H1 of the scene's order on the body (every region), clamped on the Dirichlet boundaries and the plate's."""
    plate = scene.loads.plate
    clamped = (*scene.geometry.dirichlet, *((plate.boundary,) if plate else ()))
    return ngs.VectorH1(mesh, order=scene.mesh.order, dirichlet="|".join(clamped))


def elastic_integrand(fes: ngs.FESpace, laws: dict):
    """Σ_r ∫_r σ_r(ε(u)) : ε(v) dx over the regions r with their laws ``{region: law}`` (nonlinear in u for some)."""
    u, v = fes.TnT()
    terms = [law.elastic_integrand(u, v) * ngs.dx(region) for region, law in laws.items()]
    return sum(terms[1:], terms[0])


def elastic_form(fes: ngs.FESpace, laws: dict) -> ngs.BilinearForm:
    """a(u, v) = Σ_r ∫_r D_r(0) ε(u) : ε(v) dx: the stiffness K₀, the laws' tangents at ε = 0 (symmetric, constant)."""
    return ngs.BilinearForm(elastic_integrand(fes, {r: law.tangent_at_zero() for r, law in laws.items()}),
                            symmetric=True)


def tangent_form(fes: ngs.FESpace, laws: dict, state: ngs.GridFunction) -> ngs.BilinearForm:
    """k(u, v) = Σ_r ∫_r D_r(ε(state)) ε(u) : ε(v) dx with the laws' tangents D_r at the displacement ``state``."""
    u, v = fes.TnT()
    eps = ngs.Sym(ngs.Grad(state))
    terms = [law.tangent_integrand(eps, u, v) * ngs.dx(region) for region, law in laws.items()]
    return ngs.BilinearForm(sum(terms[1:], terms[0]), symmetric=True)


def load_form(fes: ngs.FESpace, scene: Scene) -> ngs.LinearForm:
    """ℓ(v) = ∫ f₀·v dx + Σ_b ∫_b f_N·v da at unit time factor."""
    v = fes.TestFunction()
    f = ngs.LinearForm(fes)
    if scene.loads.body_force is not None:
        f += ngs.InnerProduct(ngs.CF(scene.loads.body_force), v) * ngs.dx
    for name, vec in scene.loads.traction.items():
        f += ngs.InnerProduct(ngs.CF(vec), v) * ngs.ds(name)
    return f


@dataclass
class ContactForm:
    """φ(w, u, ·) as an NGSolve form; ``w``, ``d0``, ``stiffness`` L and ``friction`` μ n* are nodal GridFunctions."""

    form: ngs.BilinearForm
    w: ngs.GridFunction
    d0: ngs.GridFunction
    stiffness: ngs.GridFunction
    friction: list


def contact_form(fes: ngs.FESpace, scene: Scene, law: Compliance, laws: dict | None) -> ContactForm:
    """The nonlinear boundary integrator (residual by ``Apply``, Jacobian by ``AssembleLinearization``).

    With ``laws`` ({region: law}) the elastic terms too: the whole residual of the full-system path.
    """
    dim, order = scene.dim, scene.mesh.order
    scal = ngs.H1(fes.mesh, order=order)
    w, d0, stiffness = ngs.GridFunction(scal), ngs.GridFunction(scal), ngs.GridFunction(scal)
    friction = [ngs.GridFunction(scal) for _ in range(dim)]
    nu = ngs.CF(scene.contact.direction)
    u, v = fes.TnT()
    form = ngs.BilinearForm(fes)
    if laws is not None:
        form += elastic_integrand(fes, laws)
    compression = ngs.InnerProduct(u, nu) - d0 - w
    direction = nu + ngs.CF(tuple(friction))
    form += law.cf(compression, stiffness) * ngs.InnerProduct(direction, v) * contact_ds(dim, order)
    return ContactForm(form, w, d0, stiffness, friction)
