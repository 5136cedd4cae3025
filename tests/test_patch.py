"""The contact solve on the patch (numerics/systems/patch.py, columns.py): exact algebra, the dense path's numbers."""
from pathlib import Path

import numpy as np
import pytest

import ngwear
from ngwear.numerics import columns as columns_module
from ngwear.numerics.columns import Columns
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.systems import PATCH_SHARE, normal_response, patch_share, plate_rows
from ngwear.numerics.systems import patch as patch_module
from ngwear.numerics.systems.condensed import DenseSystem
from ngwear.numerics.systems.newton import PlateRows
from ngwear.numerics.systems.patch import PatchSystem
from ngwear.numerics.wear import PointLaw

ROOT = Path(__file__).resolve().parents[1]
FIELDS = ("normal_displacement", "wear", "pressure", "reaction", "plate_displacement")


class Compliance:
    """R(a, b) = A a + H b for columns, with a count of the right-hand sides."""

    def __init__(self, n, seed=0):
        rng = np.random.default_rng(seed)
        B = rng.standard_normal((n, n)) / n
        self.H = B @ B.T + np.diag(rng.uniform(0.5, 1.0, n)) / n
        self.A = self.H + 0.3 * rng.standard_normal((n, n)) / n ** 1.5
        self.rhs = 0

    def __call__(self, directed, normal):
        self.rhs += directed.shape[1]
        return self.A @ directed + self.H @ normal


def systems(n=40, plate=True, seed=0):
    """The same step problem as a dense DenseSystem and a PatchSystem (point compliances H_ii for both)."""
    R = Compliance(n, seed)
    rng = np.random.default_rng(seed + 1)
    m = rng.uniform(0.5, 1.5, n)
    rows = None
    if plate:
        rows = PlateRows(np.ones((n, 1)) + 0.1 * rng.standard_normal((n, 1)), rng.uniform(0.5, 1.5, (n, 1)),
                         np.zeros((1, 1)), np.array([3.0]))
    law = PointLaw(lambda z: 2.0 * np.maximum(z, 0.0), lambda z: 2.0 * (z >= 0))
    args = (m, rng.standard_normal(n) * 0.1, rng.uniform(0.0, 0.2, n), 0.3, law)
    dense = DenseSystem(R.H, R.A, *args, plate=rows)
    patch = PatchSystem(Columns(R, n), np.diag(R.H), *args, store={}, plate=rows)
    return dense, patch, R


def test_the_patch_solves_the_dense_newton_systems_through_its_updates():
    """M z = b on the patch with the base's LU updated (Woodbury) equals the dense LU's z, pattern after pattern.

    The patch grows, loses points, takes active points and changes p' against its base; beyond RANK changed
    columns the pattern becomes the base.  Columns are computed once each.
    """
    n = 60
    dense, patch, R = systems(n)
    rng = np.random.default_rng(5)
    in_contact = np.zeros(n, bool)
    in_contact[:8] = True
    bases = []
    for k in range(14):
        if k == 9:
            in_contact[:] = False
            in_contact[15:15 + patch_module.RANK + 5] = True          # more than RANK changes: a new base
        else:
            in_contact[rng.choice(n, 2)] = True
            in_contact[rng.choice(n, 1)] = False
        active = in_contact & (rng.uniform(size=n) < 0.2)
        dp = np.where(in_contact & ~active, rng.choice([1.0, 2.0], n), 0.0)
        b = rng.standard_normal(n + 1)
        z_dense = dense._solve(active, dp, b, np.zeros(n))
        z_patch = patch._solve(active, dp, b, np.zeros(n))
        assert np.abs(z_patch - z_dense).max() <= 1e-10 * np.abs(z_dense).max(), k
        bases.append(patch.store[patch_module.BASE])
    assert 2 <= len({id(base) for base in bases}) < len(bases)
    assert R.rhs == patch.columns.directed.size + patch.columns.normal.size        # each column once


def test_columns_are_exact_and_computed_once_nearest_to_contact_first(monkeypatch):
    """A a + H b from the columns of the supports; a small request is filled with the points nearest to contact."""
    monkeypatch.setattr(columns_module, "AHEAD", 6)
    n = 30
    R = Compliance(n, seed=3)
    cols = Columns(R, n)
    cols.clearance = -np.arange(n, dtype=float)                      # point 0 nearest to contact, then 1, 2, ...
    a, b = np.zeros(n), np.zeros(n)
    a[[10, 12]], b[[25]] = 1.5, -2.0
    assert np.allclose(cols(a, b), R.A @ a + R.H @ b, rtol=0, atol=1e-15)
    assert sorted(np.flatnonzero(cols.directed.slot >= 0)) == [0, 1, 2, 3, 10, 12]   # filled up to AHEAD
    assert list(np.flatnonzero(cols.normal.slot >= 0)) == [25]
    spent = R.rhs
    a[[0, 3]] = 0.25
    assert np.allclose(cols(a, 3 * b), R.A @ a + 3 * R.H @ b, rtol=0, atol=1e-15) and R.rhs == spent
    same = Columns(R, n, same=True)                                  # no friction: A = H, one store
    assert same.directed is same.normal


def test_block_responses_equal_single_ones(paper_scene):
    """``normal_response`` for k columns: one back-substitution with k right-hand sides, the k single products."""
    disc = Discretization(paper_scene.replace(**{"mesh.maxh": 0.3}))
    n, contact = disc.points.n, disc.contact
    directions = disc.condensation.nu[None, :] + contact.friction_directions(contact.coefficients, 1.0)
    rng = np.random.default_rng(0)
    normal, directed = rng.standard_normal((2, n, 3))
    block = normal_response(disc, normal, directed, directions)
    single = np.column_stack([normal_response(disc, normal[:, k], directed[:, k], directions)
                              for k in range(3)])
    assert np.abs(block - single).max() <= 1e-13 * np.abs(single).max()


@pytest.fixture(scope="module")
def pin():
    """The pin on a disc as shipped (380 points), 20 steps of 0.6 s: today matrix-free, its patch 8 % of Γ_C."""
    scene = ngwear.load_scene(ROOT / "geometries" / "pin_on_disc.toml").replace(**{
        "time.steps": 20, "time.T": 12.0, "output.every": 12.0})
    return scene, Discretization(scene).mesh


def test_the_pin_on_its_patch_equals_the_dense_solve_in_a_newton_step_a_step(pin, monkeypatch):
    """Same numbers as the dense path to the solver's tolerance, one Newton iteration a step.

    From rest too (the rigid predictor); the columns of the points in contact and a block's filling only.
    """
    scene, mesh = pin
    dense = ngwear.simulate(scene, discretization=Discretization(scene, mesh, contact_solve="dense"), progress=False)
    disc = Discretization(scene, mesh)
    assert disc.matrix_free and patch_share(disc) <= PATCH_SHARE
    rhs = []
    respond = normal_response
    monkeypatch.setattr("ngwear.numerics.systems.normal_response",
                        lambda disc, *a: (rhs.append(np.shape(a[0])[1]), respond(disc, *a))[1])
    fast = ngwear.simulate(scene, discretization=disc, progress=False)
    assert dense.completed and fast.completed
    for name in FIELDS:
        a, b = getattr(dense, name), getattr(fast, name)
        assert np.abs(a - b).max() <= 1e-9 * np.abs(a).max(), name
    assert max(r.iterations for r in fast.newton) == 1 and dense.newton[0].iterations > 5
    touched = np.logical_or.reduce(fast.pressure > 0).sum()
    assert touched < 0.15 * disc.points.n and sum(rhs) <= touched + columns_module.AHEAD * len(rhs)
    assert (np.diff(fast.wear, axis=0) >= 0).all() and (fast.normal_displacement - disc.condensation.d0 <=
                                                         scene.contact.gap).all()


def test_the_rigid_predictor_balances_the_plate_force(pin):
    """From rest the body moves rigidly until the contact carries the plate's force (no product)."""
    scene, mesh = pin
    disc = Discretization(scene, mesh)
    contact, law = disc.contact, disc.contact.law
    cond, n = disc.condensation, disc.points.n
    rows = plate_rows(disc, cond.plate.directed(
        cond.nu[None, :] + contact.friction_directions(contact.coefficients, 1.0)), 1.0)
    R = Compliance(n)
    system = PatchSystem(Columns(R, n), cond.compliance_estimate, disc.points.weights, disc.loads.s_load, cond.d0,
                         scene.contact.gap, PointLaw(law, law.derivative), {}, rows)
    x, lam = system.start(np.zeros(n + 1), np.zeros(n))
    force = disc.points.weights @ law(x[:n] - cond.d0)
    assert force == pytest.approx(10.0, rel=1e-9) and R.rhs == 0       # the plate's 10 N along ν, no column
    assert 0 < np.count_nonzero(law(x[:n] - cond.d0)) < 0.15 * n


@pytest.mark.parametrize("name, settings", [
    ("paper_strip", {}),                                              # the layer wears through: active points
    ("hertz", {}),                                                    # Signorini: every point in contact active
    ("brake_pad", {"time.steps": 10, "time.T": 10.0, "output.every": 10.0}),   # a plate, all of Γ_C in contact
    ("pin_on_disc", {"loads.plate.force": [0.0, 0.0, -1000.0], "time.steps": 3, "time.T": 1.8,
                     "output.every": 1.8}),                           # the predictor stops at the foundation
])
def test_the_patch_equals_the_dense_solve_where_points_are_active(name, settings):
    scene = ngwear.load_scene(ROOT / "geometries" / f"{name}.toml").replace(**settings)
    mesh = Discretization(scene).mesh
    dense, patch = (ngwear.simulate(scene, discretization=Discretization(scene, mesh, contact_solve=mode),
                                    progress=False) for mode in ("dense", "patch"))
    assert dense.completed and patch.completed
    assert sum(r.iterations for r in patch.newton) <= sum(r.iterations for r in dense.newton)
    for field in FIELDS:
        a, b = getattr(dense, field), getattr(patch, field)
        if a.size:
            assert np.abs(a - b).max() <= 1e-9 * max(np.abs(a).max(), 1e-300), field


def test_auto_solves_on_the_patch_only_where_it_is_a_part_of_the_contact_face(pin):
    """The rigid body's patch: 8 % of the pin's Γ_C, all of the pad's."""
    scene, mesh = pin
    assert 0.05 < patch_share(Discretization(scene, mesh)) < 0.15
    pad = ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml")
    assert patch_share(Discretization(pad)) == 1.0
