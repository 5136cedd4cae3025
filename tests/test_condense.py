"""The condensation: PARDISO's Schur complement, the ν rows of G, and the dense / matrix-free contact solves."""
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

import ngwear
from ngwear.numerics import discrete
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.pardiso import Pardiso

ROOT = Path(__file__).resolve().parents[1]


def spd(n, seed=0):
    A = sp.random(n, n, density=0.03, random_state=seed)
    return (A @ A.T + 3 * sp.eye(n)).tocsr()


def test_pardiso_schur_complement_and_solve_are_exact():
    K = spd(300)
    c = np.array([299, 4, 150, 151, 7])
    factor = Pardiso(K, c)
    Kd, cs = K.toarray(), np.sort(c)
    i = np.setdiff1d(np.arange(300), cs)
    S = Kd[np.ix_(cs, cs)] - Kd[np.ix_(cs, i)] @ np.linalg.solve(Kd[np.ix_(i, i)], Kd[np.ix_(i, cs)])
    assert np.abs(factor.schur_complement - S).max() < 1e-13 * np.abs(S).max()
    b = np.random.default_rng(1).standard_normal((300, 2))
    x = factor.solve(b, lambda y: np.linalg.solve(S, y))
    assert np.abs(x - np.linalg.solve(Kd, b)).max() < 1e-12 * np.abs(x).max()
    assert np.abs(Pardiso(K).solve(b) - x).max() < 1e-12 * np.abs(x).max()


def test_a_given_ordering_factorises_as_metis_own_to_the_bit():
    """A geometry update's K (same pattern, other values) with the first K's ordering: as METIS's own, to the bit.

    METIS is skipped; a resumed run takes the ordering from its checkpoint.
    """
    K = spd(400)
    first = Pardiso(K)
    assert np.array_equal(np.sort(first.ordering), np.arange(400))
    moved = (K + sp.diags(np.linspace(0.5, 1.5, 400))).tocsr()
    b = np.random.default_rng(2).standard_normal((400, 3))
    own, given = Pardiso(moved), Pardiso(moved, ordering=first.ordering)
    assert np.array_equal(own.ordering, first.ordering) and np.array_equal(given.ordering, first.ordering)
    assert np.array_equal(given.solve(b), own.solve(b))
    assert np.abs(moved @ given.solve(b) - b).max() < 1e-12 * np.abs(b).max()
    assert Pardiso(K, np.array([3, 7])).ordering is None
    with pytest.raises(ValueError, match="ordering cannot be given with Schur rows"):
        Pardiso(K, np.array([3, 7]), first.ordering)


def test_normal_rows_are_the_nu_rows_of_the_point_compliance(paper_scene):
    """R_ijb = ν·G_ij·e_b with G = P K⁻¹ Pᵀ from plain solves; H = R ν, F = R n*."""
    disc = Discretization(paper_scene.replace(**{"mesh.maxh": 0.3}))
    n, d = disc.points.n, 2
    G = disc.points.P @ disc.elastic.operator.solve(disc.points.P.T.toarray())
    G = G.reshape(n, d, n, d)
    R = np.einsum("a,iajb->ijb", disc.condensation.nu, G)
    assert np.abs(disc.condensation.normal_rows - R).max() < 1e-12 * np.abs(R).max()
    n_star = disc.contact.motion.n_star(1.0)
    assert np.allclose(disc.condensation.friction_compliance(n_star), np.einsum("ijb,jb->ij", R, n_star), rtol=0,
                       atol=1e-12 * np.abs(R).max())
    H = disc.condensation.normal_compliance
    assert np.abs(H - H.T).max() < 1e-12 * np.abs(R).max()


def compare(scene, names=("normal_displacement", "wear", "pressure", "reaction")):
    mesh = Discretization(scene).mesh
    dense = ngwear.simulate(scene, discretization=Discretization(scene, mesh, contact_solve="dense"), progress=False)
    krylov = ngwear.simulate(scene, discretization=Discretization(scene, mesh, contact_solve="krylov"),
                             progress=False)
    assert dense.completed and krylov.completed
    for name in names:
        a, b = getattr(dense, name), getattr(krylov, name)
        assert np.abs(a - b).max() < 1e-9 * max(1.0, np.abs(a).max()), name
    return dense, krylov


def test_matrix_free_equals_dense_where_the_layer_wears_through(paper_scene):
    """2D paper scene: friction, wear through the layer (active points, reactions λ > 0)."""
    dense, _ = compare(paper_scene.replace(**{"mesh.maxh": 0.25, "time.steps": 20}))
    assert dense.reaction.max() > 0


@pytest.mark.parametrize("order", [1, 2], ids=["P1", "P2"])
def test_matrix_free_equals_dense_for_a_pad_on_a_disc(order):
    """3D brake pad held by a tilting plate alone, on a turning disc: friction along n*_i, plate rows."""
    scene = ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml").replace(**{
        "mesh.maxh": 0.012, "mesh.order": order, "time.steps": 5, "time.T": 5.0, "output.every": 5.0,
        "loads.plate.tilt": True})
    dense, krylov = compare(scene, ("normal_displacement", "wear", "pressure", "torque"))
    assert np.abs(dense.plate_displacement - krylov.plate_displacement).max() < 1e-9 * np.abs(
        dense.plate_displacement).max()


def test_auto_is_dense_below_the_limit_and_matrix_free_above(paper_scene, monkeypatch):
    scene = paper_scene.replace(**{"mesh.maxh": 0.3, "time.steps": 5, "wear.integrator": "implicit"})
    small = Discretization(scene)
    assert not small.matrix_free and small.elastic.operator.schur_complement is not None
    monkeypatch.setattr(discrete, "DENSE_LIMIT", len(small.body.contact_dofs) - 1)
    large = Discretization(scene, small.mesh)
    assert large.matrix_free and large.elastic.operator.schur_complement is None
    a = ngwear.simulate(scene, discretization=small, progress=False)
    b = ngwear.simulate(scene, discretization=large, progress=False)
    assert np.abs(a.wear - b.wear).max() < 1e-9 * a.wear.max()
    assert large.with_scene(scene.replace(**{"contact.friction": 0.2})).matrix_free


def test_auto_is_matrix_free_for_a_soft_layer_only(monkeypatch):
    """From SOFT_LIMIT contact DOFs a layer soft against the body (ρ = p' t / E < 1) goes matrix-free."""
    pad = Discretization(ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml").replace(**{"mesh.maxh": 0.012}))
    box = Discretization(ngwear.load_scene(ROOT / "geometries" / "box3d.toml").replace(**{"mesh.maxh": 0.25}))
    height = pad.scene.geometry.size[3] + pad.scene.geometry.backing      # the friction material and its backing
    assert pad.layer_ratio == pytest.approx(1e10 * height / 1e9) and box.layer_ratio == pytest.approx(10 * 0.5 / 2.5)
    assert not pad.matrix_free and not box.matrix_free
    monkeypatch.setattr(discrete, "SOFT_LIMIT", min(len(pad.body.contact_dofs), len(box.body.contact_dofs)) - 1)
    assert Discretization(pad.scene, pad.mesh).matrix_free and not Discretization(box.scene, box.mesh).matrix_free


def test_contact_solve_is_checked(paper_scene):
    with pytest.raises(ValueError, match="contact_solve"):
        Discretization(paper_scene, contact_solve="cg")
