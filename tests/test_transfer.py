"""Fields of one mesh on another of the same curved part (ngwear.numerics.transfer), as ``verify`` needs them.

Fine points of the pad's arcs, the pin's cylinder and spherical end and the half disk's arc lie outside the coarse
mesh; NGSolve's ``GridFunction.Set`` of a coarse function silently gives 0 there (shown below).  The transfer
evaluates the nearest element's polynomial: fields the coarse space holds exactly come through exactly.
"""
import ngsolve as ngs
import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.transfer import ContactTrace, Locator, StrainQuadrature, element_strains

PAIRS = {  # scene: (coarse, fine) size overrides
    "hertz": ({"mesh.maxh": 0.3, "mesh.contact_maxh": 0.05}, {"mesh.maxh": 0.1, "mesh.contact_maxh": 0.01}),
    "brake_pad": ({"mesh.maxh": 0.024}, {"mesh.maxh": 0.006}),
    "pin_on_disc": ({"mesh.maxh": 0.004, "mesh.contact_maxh": 0.0012}, {"mesh.maxh": 0.002, "mesh.contact_maxh": 0.0006}),
}


def pair(name, order):
    scene = ngwear.load_scene(ROOT / "geometries" / f"{name}.toml").replace(**{"mesh.order": order})
    coarse, fine = PAIRS[name]
    return Discretization(scene.replace(**coarse)), Discretization(scene.replace(**fine))


def field(dim, order):
    """A displacement the coarse space holds exactly: linear (P1), quadratic (P2)."""
    X = (ngs.x, ngs.y, ngs.z)[:dim]
    return ngs.CF(tuple((order - 1) * X[i] ** 2 + (i + 1) * X[(i + 1) % dim] + 0.5 for i in range(dim)))


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("name", list(PAIRS))
def test_strain_of_a_coarse_field_on_a_finer_mesh_is_exact(name, order):
    coarse, fine = pair(name, order)
    u, u_ref = ngs.GridFunction(coarse.fes), ngs.GridFunction(fine.fes)
    u.Set(field(coarse.scene.dim, order))
    u_ref.Set(field(coarse.scene.dim, order))
    quadrature = StrainQuadrature(fine.fes, 2 * order + 1)
    locator = Locator(coarse.mesh)
    vertices = fine.mesh.ngmesh.Coordinates()
    assert (locator.mesh(*vertices.T)["nr"] < 0).any(), "the fine mesh's vertices on curved faces are outside"
    exact = np.asarray(field(coarse.scene.dim, order)(fine.mesh(*vertices.T)))
    assert np.abs(np.asarray(u(locator(vertices))) - exact).max() < 1e-12
    error2 = quadrature.error2(u, quadrature.on(coarse.mesh), u_ref.vec.FV().NumPy())
    volume = quadrature.weights.sum()
    assert volume == pytest.approx(ngs.Integrate(ngs.CF(1), fine.mesh), rel=1e-12)       # every region
    assert np.sqrt(error2 / volume) < 1e-11


def test_ngsolve_set_from_another_mesh_is_silently_wrong_outside_it():
    """Why the transfer exists: Set of a coarse function is 0 at fine points outside the coarse half disk."""
    coarse, fine = pair("hertz", 1)
    u = ngs.GridFunction(coarse.fes)
    u.Set(field(2, 1))
    moved = ngs.GridFunction(fine.fes)
    moved.Set(u)
    points = fine.mesh.ngmesh.Coordinates()
    wrong = np.array([moved(fine.mesh(*p)) for p in points]) - np.array([u(Locator(coarse.mesh)(p[None])) for p in points])
    assert np.abs(wrong).max() > 1.0


@pytest.mark.parametrize("order", [1, 2])
def test_wear_on_the_pads_contact_face(order):
    """The flat contact face with curved edges: a linear wear comes through exactly, P1 and P2 (edge midpoints)."""
    coarse, fine = pair("brake_pad", order)
    trace = ContactTrace(coarse.mesh, coarse.points, order, reach=0.024)
    wear = lambda x: 1 + 3 * x[:, 0] - 2 * x[:, 1]  # noqa: E731
    assert np.abs(trace(wear(coarse.points.coords), fine.points.coords) - wear(fine.points.coords)).max() < 1e-12


def test_points_far_from_the_body_are_refused():
    coarse, _ = pair("brake_pad", 1)
    with pytest.raises(ValueError, match=r"^points: .* is not in the body"):
        Locator(coarse.mesh, reach=1e-3)(np.array([[0.125, 0.0, -0.01]]))


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("name", ["hertz", "brake_pad"])
def test_on_the_reference_mesh_the_gram_matrix_gives_the_rules_error(name, order):
    """A run on the reference's own mesh (loaded again: another Mesh object) is compared by eᵀ G e, no points."""
    _, fine = pair(name, order)
    again = Discretization(fine.scene)
    quadrature = StrainQuadrature(fine.fes, 2 * order + 1)
    assert quadrature.on(again.mesh) is None
    rng = np.random.default_rng(1)
    u, u_ref = ngs.GridFunction(again.fes), rng.standard_normal(fine.fes.ndof)
    u.vec.FV().NumPy()[:] = u_ref + 1e-3 * rng.standard_normal(fine.fes.ndof)
    by_points = quadrature.error2(u, quadrature.mips, u_ref)
    assert by_points > 0
    assert quadrature.error2(u, None, u_ref) == pytest.approx(by_points, rel=1e-11)


@pytest.mark.parametrize("name", ["hertz", "brake_pad"])
def test_p1_strains_by_element_are_ngsolves_at_the_points(name):
    """P1: each quadrature point takes its element's constant strain (element_strains), as NGSolve evaluates it there."""
    coarse, fine = pair(name, 1)
    quadrature = StrainQuadrature(fine.fes, 2 if coarse.scene.dim == 3 else 3)
    at = quadrature.on(coarse.mesh)
    rng = np.random.default_rng(2)
    u, u_ref = ngs.GridFunction(coarse.fes), rng.standard_normal(fine.fes.ndof)
    u.vec.FV().NumPy()[:] = rng.standard_normal(coarse.fes.ndof)
    quadrature.ref.vec.FV().NumPy()[:] = u_ref
    strain = lambda gf, mips: np.asarray(ngs.Sym(ngs.Grad(gf))(mips)).reshape(len(mips), -1)  # noqa: E731
    diff = strain(u, at) - strain(quadrature.ref, quadrature.mips)
    by_points = float(quadrature.weights @ np.einsum("ij,ij->i", diff, diff))
    assert element_strains(coarse.fes) is not None
    assert quadrature.error2(u, at, u_ref) == pytest.approx(by_points, rel=1e-12)
    assert element_strains(pair(name, 2)[0].fes) is None                     # P2: ε varies over an element


def test_element_strains_only_where_the_strain_is_constant_per_simplex():
    """None (NGSolve evaluates at the points) for a curved mesh, quadrilaterals, an interleaved or partial space."""
    from netgen.geom2d import unit_square
    from netgen.occ import Box, Glue, OCCGeometry

    left, right = Box((0, 0, 0), (1, 1, 1)), Box((1, 0, 0), (2, 1, 1))
    left.mat("a"), right.mat("b")
    box = ngs.Mesh(OCCGeometry(Glue([left, right]), dim=3).GenerateMesh(maxh=0.5))
    assert element_strains(ngs.VectorH1(box, order=1, dirichlet=".*")) is not None
    assert element_strains(ngs.VectorH1(box, order=1, interleaved=True)) is None
    assert element_strains(ngs.VectorH1(box, order=1, definedon=box.Materials("a"))) is None
    triangles = ngs.Mesh(unit_square.GenerateMesh(maxh=0.3))
    assert element_strains(ngs.VectorH1(triangles, order=1)) is not None
    assert element_strains(ngs.VectorH1(ngs.Mesh(unit_square.GenerateMesh(maxh=0.3, quad_dominated=True)), order=1)) is None
    triangles.Curve(2)
    assert element_strains(ngs.VectorH1(triangles, order=1)) is None
