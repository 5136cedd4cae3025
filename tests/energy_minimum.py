"""A reference solver for nonlinear elasticity with normal compliance: NGSolve's Newton on the total energy.

    Π(u) = Σ_regions ∫ ψ(ε(u)) dx − ∫ f₀·u dx − Σ_b ∫_b f_b·u da + ∫_ΓC P(u·ν − d) da,      P' = p,

minimised over the displacements that vanish on the Dirichlet boundaries of the space.  Its minimiser solves
a(u; v) + ∫_ΓC p(u·ν − d) v·ν da = ℓ(v): the paper's problem with the compliance alone (no friction, no wear, no
rigid layer), the check the condensed step solver must agree with.  The energy is one ``BilinearForm`` of
``Variation`` terms, so NGSolve derives residual (``Apply``) and tangent (``AssembleLinearization``) from it, and
the Newton iteration is NGSolve's own (``NewtonSolver``, with its energy line search).
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
from ngsolve.nonlinearsolvers import NewtonSolver

from ngwear.model.compliance import Compliance
from ngwear.model.materials import strain


@dataclass(frozen=True)
class Equilibrium:
    """One solve: converged, Newton iterations, NGSolve's error √⟨w, r⟩ after each, and the final energy Π."""

    converged: bool
    iterations: int
    errors: tuple[float, ...]
    energy: float


def energy_form(fes: ngs.FESpace, laws, *, body_force=None, tractions=None, compliance: Compliance | None = None,
                direction=None, distance=0.0, contact_measure=None) -> ngs.BilinearForm:
    """Π as a form of ``Variation`` terms.

    Parameters
    ----------
    laws
        A law of :mod:`ngwear.model.materials`, or ``{region: law}`` (each integrated over ``dx(region)``).
    body_force, tractions
        f₀ (a d-vector or CoefficientFunction) and ``{boundary: f_b}``.
    compliance, direction, distance, contact_measure
        p, ν (a d-vector), d (a number or CoefficientFunction, the distance to the foundation) and the measure of
        Γ_C (default ``ds("contact")``; :func:`ngwear.numerics.forms.contact_ds` for the nodal rule).
    """
    u = fes.TrialFunction()
    form = ngs.BilinearForm(fes, symmetric=True)
    for region, law in (laws.items() if isinstance(laws, dict) else [(None, laws)]):
        form += ngs.Variation(law.energy(strain(u)) * (ngs.dx(region) if region else ngs.dx))
    if body_force is not None:
        form += ngs.Variation(-ngs.InnerProduct(ngs.CF(body_force), u) * ngs.dx)
    for boundary, traction in (tractions or {}).items():
        form += ngs.Variation(-ngs.InnerProduct(ngs.CF(traction), u) * ngs.ds(boundary))
    if compliance is not None:
        r = ngs.InnerProduct(u, ngs.CF(tuple(direction))) - distance
        form += ngs.Variation(compliance.energy_cf(r) * (contact_measure or ngs.ds("contact")))
    return form


def minimise(form: ngs.BilinearForm, gfu: ngs.GridFunction, *, tol: float = 1e-10, maxit: int = 50,
             inverse: str = "sparsecholesky", linesearch: bool = True) -> Equilibrium:
    """Minimise the energy ``form`` from the initial guess ``gfu`` (updated in place) by NGSolve's Newton.

    The error is NGSolve's √⟨K⁻¹r, r⟩ (an energy norm of the residual r); converged when it drops below ``tol``.
    """
    errors = []
    status, iterations = NewtonSolver(form, gfu, inverse=inverse).Solve(
        maxit=maxit, maxerr=tol, linesearch=linesearch, printing=False,
        callback=lambda it, err: errors.append(float(err)))
    return Equilibrium(status == 0, iterations, tuple(errors), form.Energy(gfu.vec))
