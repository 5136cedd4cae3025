"""The nonlinear reference solver: columns with closed forms (compaction law, compliance foundation)."""
import ngsolve as ngs
import numpy as np
import pytest
from energy_minimum import energy_form, minimise
from netgen.occ import Box, Glue, OCCGeometry, Pnt, Rectangle, X, Y, Z

from ngwear.model.compliance import Linear
from ngwear.model.materials import Compaction, Isotropic, TransverselyIsotropic
from ngwear.numerics.forms import contact_ds

LAM, ETA, BETA, L, H = 1.0, 1.0, 100.0, 10.0, 2.0


def young(lam, eta, dim):
    """Uniaxial stress modulus of Hooke's law: E in 3D, the plane-strain E / (1 − ν²) in 2D."""
    return eta * (2 * eta + 3 * lam) / (eta + lam) if dim == 3 else 4 * eta * (eta + lam) / (2 * eta + lam)


def column(dim, on_rollers=False):
    """A column of height H on rollers at x = 0 (and y = 0 in 3D); bottom 'contact' (on rollers if asked), top 'top'."""
    if dim == 2:
        shape = Rectangle(1, H).Face()
        shape.edges.Min(Y).name, shape.edges.Max(Y).name, shape.edges.Min(X).name = "contact", "top", "left"
        shape.faces.name = "body"
    else:
        shape = Box(Pnt(0, 0, 0), Pnt(1, 1, H))
        shape.faces.Min(Z).name, shape.faces.Max(Z).name = "contact", "top"
        shape.faces.Min(X).name, shape.faces.Min(Y).name = "left", "front"
        shape.solids.name = "body"
    mesh = ngs.Mesh(OCCGeometry(shape, dim=dim).GenerateMesh(maxh=0.5))
    rollers = {"dirichletx": "left"} if dim == 2 else {"dirichletx": "left", "dirichlety": "front"}
    if on_rollers:
        rollers["dirichlet" + "xyz"[dim - 1]] = "contact"
    return ngs.VectorH1(mesh, order=1, **rollers)


@pytest.mark.parametrize("dim", [2, 3])
def test_compaction_column_on_a_compliant_foundation(dim):
    """Pressed by s on its top, resting on p(r) = L r₊: the compressed branch λ + β throughout, exact for P1.

    Homogeneous uniaxial compression: top displacement −s/L − s H / E(λ + β, η), lateral strain from ν(λ + β, η).
    """
    fes = column(dim)
    law = Compaction(LAM, ETA, BETA, dim)
    s = 0.3
    down = (0,) * (dim - 1) + (-1,)
    form = energy_form(fes, law, tractions={"top": ngs.CF((0,) * (dim - 1) + (-s,))}, compliance=Linear(L),
                       direction=down, contact_measure=contact_ds(dim, 1))
    gfu = ngs.GridFunction(fes)
    record = minimise(form, gfu, tol=1e-12)
    assert record.converged and record.iterations <= 4, record
    mesh = fes.mesh
    E = young(LAM + BETA, ETA, dim)
    top = gfu(mesh(*(0.5,) * (dim - 1), H))[-1]
    assert top == pytest.approx(-s / L - s * H / E, rel=1e-10)
    lateral = (LAM + BETA) / (2 * (LAM + BETA + ETA)) if dim == 3 else (LAM + BETA) / (LAM + BETA + 2 * ETA)
    side = gfu(mesh(*(1.0,) * (dim - 1), 1.0))[0]              # x = 1: lateral expansion ν_eff s / E
    assert side == pytest.approx(lateral * s / E, rel=1e-9)
    elastic = Isotropic(LAM + BETA, ETA, dim)                 # the same problem with Hooke(λ + β): the same answer
    check = ngs.GridFunction(fes)
    minimise(energy_form(fes, elastic, tractions={"top": ngs.CF((0,) * (dim - 1) + (-s,))},
                         compliance=Linear(L), direction=down), check, tol=1e-12)
    assert np.abs(check.vec.FV().NumPy() - gfu.vec.FV().NumPy()).max() < 1e-10 * abs(top)


@pytest.mark.parametrize("dim", [2, 3])
def test_compaction_column_in_tension_takes_the_soft_branch(dim):
    """Pulled by s on its top and held on rollers at the bottom: tr ε > 0, so β plays no part: E(λ, η)."""
    fes = column(dim, on_rollers=True)
    s = 0.2
    gfu = ngs.GridFunction(fes)
    record = minimise(energy_form(fes, Compaction(LAM, ETA, BETA, dim),
                                  tractions={"top": ngs.CF((0,) * (dim - 1) + (s,))}), gfu, tol=1e-12)
    assert record.converged
    top = gfu(fes.mesh(*(0.5,) * (dim - 1), H))[-1]
    assert top == pytest.approx(s * H / young(LAM, ETA, dim), rel=1e-10)


def test_regions_and_anisotropy_of_the_reference_solver():
    """Laws per region: two glued transversely isotropic blocks (axis along the column, ν_ap = 0) on a compliance.

    The top displacement is s (h₁/E_a1 + h₂/E_a2 + 1/L) (glued regions, exact for P1).
    """
    lower = Box(Pnt(0, 0, 0), Pnt(1, 1, 1))
    upper = Box(Pnt(0, 0, 1), Pnt(1, 1, H))
    lower.solids.name, upper.solids.name = "body", "backing"
    shape = Glue([lower, upper])
    shape.faces.Min(Z).name, shape.faces.Max(Z).name = "contact", "top"
    for face in shape.faces:
        if abs(face.center.x) < 1e-12:
            face.name = "left"
        if abs(face.center.y) < 1e-12:
            face.name = "front"
    mesh = ngs.Mesh(OCCGeometry(shape).GenerateMesh(maxh=0.5))
    fes = ngs.VectorH1(mesh, order=1, dirichletx="left", dirichlety="front")
    soft = TransverselyIsotropic(2.0, 1.0, 0.3, 0.0, 0.5, (0, 0, 1))
    stiff = TransverselyIsotropic(200.0, 100.0, 0.3, 0.0, 50.0, (0, 0, 1))
    s = 0.1
    gfu = ngs.GridFunction(fes)
    record = minimise(energy_form(fes, {"body": soft, "backing": stiff}, tractions={"top": (0, 0, -s)},
                                  compliance=Linear(L), direction=(0, 0, -1)), gfu, tol=1e-12)
    assert record.converged and record.energy < 0
    top = gfu(mesh(0.5, 0.5, H))[2]
    assert top == pytest.approx(-s * (1 / 1.0 + (H - 1) / 100.0 + 1 / L), rel=1e-10)
