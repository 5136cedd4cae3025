"""Compliance products remembered across a run, and GCR with recycling on them (numerics/recycle.py)."""
from pathlib import Path

import numpy as np
import pytest

import ngwear
from ngwear.numerics import recycle, systems
from ngwear.numerics.discrete import Discretization
from ngwear.runs import loop

ROOT = Path(__file__).resolve().parents[1]


class Counted:
    """R(a, b) = A a + H b with a count of the products."""

    def __init__(self, A, H):
        self.A, self.H, self.products = A, H, 0

    def __call__(self, a, b):
        self.products += 1
        return self.A @ a + self.H @ b


def operator(n, seed=0, scale=0.1):
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((n, n)) * scale / np.sqrt(n)
    H = B @ B.T
    return Counted(H + 0.3 * rng.standard_normal((n, n)) * scale / n, H), rng


def test_memory_is_exact_and_pays_only_for_new_directions():
    R, rng = operator(40)
    memory = recycle.ComplianceMemory(R, 40)
    inputs = rng.standard_normal((2 * 40, 5))
    for y in inputs.T:
        assert np.allclose(memory(y[:40], y[40:]), R.A @ y[:40] + R.H @ y[40:], rtol=0, atol=1e-14)
    assert R.products == memory.products == 5
    y = inputs @ rng.standard_normal(5)                          # in the span: no product
    assert np.allclose(memory(y[:40], y[40:]), R.A @ y[:40] + R.H @ y[40:], rtol=0, atol=1e-13)
    assert R.products == 5
    y = y + 1e-3 * rng.standard_normal(80)                      # a new part: one product, for that part
    assert np.allclose(memory(y[:40], y[40:]), R.A @ y[:40] + R.H @ y[40:], rtol=0, atol=1e-13)
    assert R.products == 6 and memory.size == 6
    assert np.allclose(memory(np.zeros(40), np.zeros(40)), 0.0) and R.products == 6


def test_memory_drops_its_oldest_half_when_full():
    R, rng = operator(30)
    memory = recycle.ComplianceMemory(R, 30, capacity=8)
    for _ in range(9):
        y = rng.standard_normal(60)
        memory(y[:30], y[30:])
    assert memory.size == 5 and memory.generation == 1
    Y = memory.inputs[:, :memory.size]
    assert np.allclose(Y.T @ Y, np.eye(5), atol=1e-13)
    assert np.allclose(memory.images[:, :5], R.A @ Y[:30] + R.H @ Y[30:], atol=1e-13)


@pytest.mark.parametrize("plate", [0, 2], ids=["contact only", "bordered by a floating plate"])
def test_recycled_solves_are_exact_and_reuse_the_products(plate):
    """M z = b to atol for a fixed pattern: active and inactive points, and a plate's saddle-point border.

    A right-hand side in the span of those solved before costs no product.
    """
    n = 50
    R, rng = operator(n, seed=1)
    m, dp = rng.uniform(0.5, 1.5, n), np.full(n, 2.0)
    active = np.zeros(n, bool)
    active[:5] = True
    inactive = ~active
    w_a, w_b = m * dp * inactive, m * active
    psi = rng.standard_normal((n, plate))
    below = rng.standard_normal((plate, n)) * 0.1

    def image(u, response):
        out = np.empty_like(u)
        out[:n] = inactive * u[:n] + response - psi @ u[n:]
        out[n:] = below @ u[:n]                                   # no plate stiffness: a saddle point
        return out

    M = np.block([[np.diag(inactive * 1.0) + R.A * w_a + R.H * w_b, -psi], [below, np.zeros((plate, plate))]])
    scaling = np.ones(n + plate)
    scaling[:n][active] = 1 / m[active]
    solver = recycle.Recycler(recycle.ComplianceMemory(R, n))
    b1, b2 = rng.standard_normal((2, n + plate))
    for b in (b1, b2):
        z = solver.solve(b"pattern", (w_a, w_b), image, scaling, b, atol=1e-10)
        assert np.abs(M @ z - b).max() <= 1e-10
    spent = R.products
    z = solver.solve(b"pattern", (w_a, w_b), image, scaling, 2 * b1 - b2, atol=1e-10)
    assert np.abs(M @ z - (2 * b1 - b2)).max() <= 1e-10 and R.products == spent


def test_recalled_directions_keep_the_solve_exact_when_p_prime_spans_decades():
    """Every solve meets its tolerance in the true residual, where recalled images are combinations.

    Power-law-like slopes p' over six decades, active sets and patterns changing, products between solves.
    """
    n = 60
    R, rng = operator(n, seed=2)
    m = rng.uniform(0.5, 1.5, n)
    c = 1 / (np.diag(R.H) * m)
    solver = recycle.Recycler(recycle.ComplianceMemory(R, n))
    worst = 0.0
    for k in range(20):
        active = np.zeros(n, bool)
        active[:n // 3 + k % 3] = True
        inactive = ~active
        dp = 10.0 ** rng.uniform(-6, 0, n) * inactive
        w_a, w_b = m * dp, m * active
        M = np.diag(inactive * 1.0) + R.A * w_a + R.H * w_b
        scaling = np.where(active, c, 1.0)
        for _ in range(3):
            solver.memory(m * rng.standard_normal(n) * (dp > 0), m * rng.standard_normal(n) * active)
            b = rng.standard_normal(n)
            atol = 1e-12 * np.abs(b).max()
            z = solver.solve(active.tobytes() + dp.tobytes(), (w_a, w_b), lambda u, r: inactive * u + r, scaling, b,
                             atol)
            worst = max(worst, np.abs(M @ z - b).max() / atol)
    assert worst <= 1.0 + 1e-6, worst


def test_patterns_met_again_keep_their_spans_and_recall_only_the_new_inputs(monkeypatch):
    """A stop's steps cycle through patterns (p' follows the speed): each keeps its span, exact solves.

    A pattern met again recalls the inputs remembered since its last solve, not the whole memory.
    """
    n = 200
    R, rng = operator(n, seed=5)
    m = rng.uniform(0.5, 1.5, n)
    slopes = [np.full(n, s) * rng.uniform(0.8, 1.2, n) for s in (2.0, 1.2, 0.5)]
    solver = recycle.Recycler(recycle.ComplianceMemory(R, n))
    recalled, extend = [], recycle.Span.extend
    monkeypatch.setattr(recycle.Span, "extend", lambda span, X, W: (recalled.append(X.shape[1]), extend(span, X, W))[1])
    for cycle in range(4):
        for dp in slopes:
            solver.memory(m * dp * rng.standard_normal(n), np.zeros(n))    # a step's residual: one new input
            new = solver.memory.size - solver.spans[dp.tobytes()].used if dp.tobytes() in solver.spans else None
            recalled.clear()
            b = rng.standard_normal(n)
            z = solver.solve(dp.tobytes(), (m * dp, np.zeros(n)), lambda u, r: u + r, np.ones(n), b, atol=1e-12)
            assert np.abs(z + (R.A * (m * dp)) @ z - b).max() <= 1e-12
            if cycle:
                assert new is not None and 1 <= new == recalled[0] < solver.memory.size
            assert list(solver.spans)[-1] == dp.tobytes() and solver.spans[dp.tobytes()].used == solver.memory.size
    assert list(solver.spans) == [dp.tobytes() for dp in slopes]


def test_an_ill_conditioned_newton_matrix_is_reported_not_hidden(caplog):
    """A floating plate whose contact stiffness almost vanishes: the solve says how far it got."""
    n = 30
    R, rng = operator(n, seed=3)
    m = rng.uniform(0.5, 1.5, n)
    dp = np.zeros(n)
    dp[:3] = 1e-10 * np.array([1.0, 2.0, 3.0])
    inactive = np.ones(n, bool)

    def image(u, response):
        out = np.empty_like(u)
        out[:n] = u[:n] + response - u[n:]
        out[n:] = (m * dp) @ u[:n]
        return out

    solver = recycle.Recycler(recycle.ComplianceMemory(R, n))
    b = np.concatenate([rng.uniform(0.5, 1.0, n), [0.3]])
    with caplog.at_level("WARNING", logger="ngwear.numerics.recycle"):
        solver.solve(b"floating", (m * dp * inactive, np.zeros(n)), image, np.ones(n + 1), b, atol=1e-12)
    assert solver.shortfall > 1 and "ill-conditioned Newton matrix" in caplog.text


def test_a_run_reuses_products_and_equals_the_dense_solve(monkeypatch):
    """The brake pad's running-in, matrix-free: the same numbers as the dense contact solve.

    Over 30 steps it needs fewer back-substitutions than 3 per step (~10 per step from scratch).
    """
    scene = ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml").replace(**{
        "mesh.maxh": 0.006, "time.steps": 30, "time.T": 30.0, "output.every": 30.0})
    mesh = Discretization(scene).mesh
    krylov = Discretization(scene, mesh, contact_solve="krylov")
    products = []
    respond = systems.normal_response
    monkeypatch.setattr(systems, "normal_response", lambda disc, *a: (products.append(1), respond(disc, *a))[1])
    fast = ngwear.simulate(scene, discretization=krylov, progress=False)
    dense = ngwear.simulate(scene, discretization=Discretization(scene, mesh, contact_solve="dense"), progress=False)
    for name in ("normal_displacement", "wear", "pressure", "torque", "plate_displacement"):
        a, b = getattr(dense, name), getattr(fast, name)
        assert np.abs(a - b).max() < 1e-9 * np.abs(a).max(), name
    assert len(products) < 3 * 31, len(products)


def test_the_stops_of_a_programme_reuse_the_products_of_the_stops_before(monkeypatch):
    """The life pad's stops to rest, matrix-free: μ n* goes to 0 at each stop's end and back (two sets of products).

    Both are kept across the stops (``systems.KEPT``): a later stop pays a fraction of the first one's
    back-substitutions (each stop started from none before), and the run is the dense solve's.
    """
    scene = ngwear.load_scene(ROOT / "geometries" / "brake_pad_life.toml").replace(**{
        "programme.jump": False, "output.every": 100.0,
        "programme.stops": [{"count": 4, "duration": 5.0, "speed": [1.0, 0.0], "dwell": 30.0}]})
    mesh = Discretization(scene).mesh
    krylov = Discretization(scene, mesh, contact_solve="krylov")
    products, stops = [], []
    respond, solve = systems.normal_response, loop.advance
    monkeypatch.setattr(systems, "normal_response", lambda disc, *a: (products.append(1), respond(disc, *a))[1])
    monkeypatch.setattr(loop, "advance", lambda *a: (stops.append(len(products)), solve(*a))[1])
    fast = ngwear.simulate(scene, discretization=krylov, progress=False)
    monkeypatch.undo()
    dense = ngwear.simulate(scene, discretization=Discretization(scene, mesh, contact_solve="dense"), progress=False)
    for name in ("normal_displacement", "wear", "pressure", "plate_displacement"):
        a, b = getattr(dense, name), getattr(fast, name)
        assert np.abs(a - b).max() < 1e-9 * np.abs(a).max(), name
    per_stop = np.diff(np.append(stops, len(products))[::6])     # 6 solves a stop: its start and 5 steps
    assert per_stop[-1] <= per_stop[0] / 3, per_stop
