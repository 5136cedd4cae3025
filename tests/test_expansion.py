"""Thermal expansion as a load (ngwear/numerics/expansion.py, ngwear/model/thermal.py) against closed forms.

A free bar heated uniformly lengthens by α ΔT L (3D; (1 + ν) α ΔT L in plane strain), a bar held at both ends
carries −E α ΔT (3D; −E α ΔT / (1 − ν) in plane strain), a temperature linear in x strains a free body without
stress (its thermal strain is compatible), and β = C : (α I) of each law.
"""
import ngsolve as ngs
import numpy as np
import pytest
import scipy.sparse.linalg as spla

from ngwear.model.materials import Compaction, Isotropic, TransverselyIsotropic, region_laws
from ngwear.model.scene import Scene
from ngwear.model.scene_mesh import build_mesh
from ngwear.model.thermal import thermal_stress
from ngwear.numerics.expansion import ThermalLoad
from ngwear.numerics.forms import elastic_form
from ngwear.numerics.stiffness import assembled

E, NU, ALPHA, RISE, START = 200.0, 0.3, 1e-3, 50.0, 20.0
BAR = {3: ("box", [1.0, 0.2, 0.2]), 2: ("strip", [1.0, 0.2])}


def bar(dim, order, **material):
    kind, size = BAR[dim]
    return Scene.from_dict({"geometry": {"kind": kind, "size": size}, "mesh": {"maxh": 0.1, "order": order},
                            "material": {"young": E, "poisson": NU, "conductivity": 1.0, "density": 1.0,
                                         "heat_capacity": 1.0, "expansion": ALPHA, **material},
                            "heat": {"model": "conduction", "partition": 1.0, "initial": START}})


def solved(scene, temperature, held: dict, pinned=()):
    """(u, mesh, law): the bar under the thermal load of ``temperature`` (a function of the nodes' coordinates).

    ``held``: NGSolve's per-component Dirichlet keys (dirichletx = "left", …); ``pinned``: DOFs held too.
    """
    mesh = build_mesh(scene)
    fes = ngs.VectorH1(mesh, order=scene.mesh.order, **held)
    space = ngs.H1(mesh, order=1)
    load = ThermalLoad(scene, fes, space)(temperature(np.array(mesh.ngmesh.Coordinates())))
    laws = region_laws(scene)
    K = assembled(elastic_form(fes, laws))
    free = np.array(list(fes.FreeDofs()), dtype=bool)
    free[list(pinned)] = False
    u = ngs.GridFunction(fes)
    u.vec.FV().NumPy()[free] = spla.spsolve(K[free][:, free].tocsc(), load[free])
    return u, mesh, laws["body"]


def uniform(nodes):
    return np.full(len(nodes), START + RISE)


@pytest.mark.parametrize("dim", [3, 2])
@pytest.mark.parametrize("order", [1, 2])
def test_a_free_bar_heated_uniformly_lengthens_by_alpha_rise_length(dim, order):
    """Held on its symmetry planes only: u_x(L) = α ΔT L (3D), (1 + ν) α ΔT L (plane strain: ε₃₃ = 0)."""
    planes = {"dirichletx": "left", "dirichlety": "front", "dirichletz": "contact"} if dim == 3 else {
        "dirichletx": "left", "dirichlety": "contact"}
    u, mesh, _ = solved(bar(dim, order), uniform, planes)
    stretch = ALPHA * RISE * (1.0 if dim == 3 else 1 + NU)
    corner = (1.0, 0.2, 0.2)[:dim]
    assert u(mesh(*corner))[0] == pytest.approx(stretch, rel=1e-12)
    assert np.allclose(u(mesh(*corner)), stretch * np.array(corner), rtol=1e-12, atol=0)


@pytest.mark.parametrize("dim", [3, 2])
@pytest.mark.parametrize("order", [1, 2])
def test_a_bar_held_at_both_ends_carries_minus_young_alpha_rise(dim, order):
    """Ends held along x, free sideways: σ_xx = −E α ΔT (3D), −E α ΔT / (1 − ν) (plane strain), nothing else."""
    planes = {"dirichletx": "left|right", "dirichlety": "front", "dirichletz": "contact"} if dim == 3 else {
        "dirichletx": "left|right", "dirichlety": "contact"}
    scene = bar(dim, order)
    u, mesh, law = solved(scene, uniform, planes)
    beta = ngs.CF(tuple(thermal_stress(law, ALPHA).ravel()), dims=(dim, dim))
    stress = law.stress(ngs.Sym(ngs.Grad(u))) - RISE * beta
    expected = np.zeros((dim, dim))
    expected[0, 0] = -E * ALPHA * RISE / (1.0 if dim == 3 else 1 - NU)
    for x in (0.05, 0.5, 0.93):
        point = mesh(*(x, 0.13, 0.07)[:dim])
        assert np.allclose(np.reshape(stress(point), (dim, dim)), expected, rtol=0, atol=1e-10 * E * ALPHA * RISE)


def test_a_temperature_linear_in_x_strains_a_free_body_without_stress():
    """ε_th = α b x I is compatible (u_x = αb(x² − y² − z²)/2, u_y = αbxy, u_z = αbxz): P2 recovers it exactly."""
    b = 40.0
    scene = bar(3, 2)
    mesh = build_mesh(scene)
    origin = int(np.argmin(np.linalg.norm(np.array(mesh.ngmesh.Coordinates()), axis=1)))
    u, mesh, law = solved(scene, lambda nodes: START + b * nodes[:, 0], {"dirichlety": "front", "dirichletz": "contact"},
                          pinned=[origin])                      # u_x = 0 at the origin: the x translation held
    beta = ngs.CF(tuple(thermal_stress(law, ALPHA).ravel()), dims=(3, 3))
    stress = law.stress(ngs.Sym(ngs.Grad(u))) - b * ngs.x * beta
    size = np.sqrt(ngs.Integrate(ngs.InnerProduct(stress, stress), mesh) / 0.04)
    assert size < 1e-10 * E * ALPHA * b
    exact = ALPHA * b * np.array([(1.0 - 0.04 - 0.01) / 2, 0.2, 0.1])
    assert np.allclose(u(mesh(1.0, 0.2, 0.1)), exact, rtol=1e-10)


def test_thermal_stress_of_each_law():
    """β = C : (α I): (3λ + 2η) α I for Hooke (2D too), the same of an isotropic transversely isotropic law.

    The compaction law's is its compressed tangent's.
    """
    lam, eta = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    for dim in (2, 3):
        iso = thermal_stress(Isotropic(lam, eta, dim), ALPHA)
        assert np.allclose(iso, (3 * lam + 2 * eta) * ALPHA * np.eye(dim), rtol=1e-13)
        axis = (0.6, 0.8, 0.0)[:dim]
        same = TransverselyIsotropic(E, E, NU, NU, eta, axis)
        assert np.allclose(thermal_stress(same, ALPHA), iso, rtol=1e-12)
        packed = Compaction(lam, eta, 5 * eta, dim)
        assert np.allclose(thermal_stress(packed, ALPHA), (3 * (lam + 5 * eta) + 2 * eta) * ALPHA * np.eye(dim))
    stiff_axis = TransverselyIsotropic(E, 4 * E, NU, 0.2, eta, (0.0, 0.0, 1.0))
    beta = thermal_stress(stiff_axis, ALPHA)
    assert beta[2, 2] > beta[0, 0] == pytest.approx(beta[1, 1]) and np.allclose(beta, np.diag(np.diag(beta)))


def test_only_expanding_regions_load_the_body():
    """α_th = 0 everywhere: no matrix, a zero load; a backing without expansion takes no load of its own."""
    plain = bar(3, 1, expansion=0.0)
    mesh = build_mesh(plain)
    fes, space = ngs.VectorH1(mesh, order=1), ngs.H1(mesh, order=1)
    none = ThermalLoad(plain, fes, space)
    assert none.matrix is None and not none(np.full(space.ndof, 99.0)).any()
    backed = bar(2, 1).replace(**{"geometry.backing": 0.1, "material.regions": {"backing": {"expansion": 0.0}}})
    mesh = build_mesh(backed)
    fes, space = ngs.VectorH1(mesh, order=1), ngs.H1(mesh, order=1)
    load = ThermalLoad(backed, fes, space)(np.full(space.ndof, START + RISE)).reshape(2, -1)
    body = ngs.BitArray(mesh.Materials("body").Mask())
    touched = np.zeros(mesh.nv, dtype=bool)
    for el in mesh.Elements(ngs.VOL):
        touched[[v.nr for v in el.vertices]] |= body[el.index]
    assert np.abs(load[:, ~touched]).max() == 0 and np.abs(load[:, touched]).max() > 0
