"""Cycle jumps against stop by stop on toy stop maps w ↦ w + Δw(w) with known worn-in states.

A rigid punch on a compliant layer stands for the body: p_i = L (δ + θ·x_i − d_i − w_i)₊ with the plate's translation δ
(and, tilting, its rotation θ) fixed by the force and moment balances, each stop integrated in small explicit steps
at the speed of a stop to rest.  On a turning disc the worn-in state is p·r = const (a uniform increment), under a
tilting plate on a translating counterface it is p linear (an affine increment), and without a plate (a clamped
body) the wear decays towards the layer's depth with no periodic state at all.  Over 300 stops the jumps must keep
the worn volume within 1 % and the smallest remaining thickness within 2 % of stop by stop, with far fewer stops
simulated.
"""
import numpy as np
import pytest

from ngwear.runs.jumps import PRESSURE_CHANGE, CycleJumps, accurate_stops, non_rigid, rigid_modes, room, settled

STOPS, SUBSTEPS, THICKNESS = 300, 20, 1.0


class Punch:
    """A rigid punch (a plate, tilting or not, or clamped) on a layer of stiffness L over points x with weights m."""

    def __init__(self, x, m, speed, kappa, stiffness=100.0, force=1.0, couple=0.0, plate=True, tilt=False, depth=0.02,
                 crown=0.0):
        self.x, self.m, self.speed, self.kappa, self.L = x, m, speed, kappa, stiffness
        self.force, self.couple, self.plate, self.tilt, self.depth = force, couple, plate, tilt, depth
        self.d0 = crown * x ** 2                                    # a crowned face: its centre touches first
        self.modes = rigid_modes(np.column_stack([x, np.zeros_like(x)]), [0.0, -1.0], plate, tilt)

    def pressure(self, w):
        if not self.plate:                                          # clamped: the layer pressed by a fixed depth
            return self.L * np.maximum(self.depth - w, 0.0)
        modes = self.modes
        target = np.array([self.force, self.couple][:modes.shape[1]])
        # all points in contact (checked): L Eᵀ M (E a − w) = target, a the plate's motion
        a = np.linalg.solve(modes.T @ (self.m[:, None] * modes), target / self.L + modes.T @ (self.m * (w + self.d0)))
        p = self.L * (modes @ a - self.d0 - w)
        assert (p > 0).all(), "the toy keeps every point in contact"
        return p

    def stop(self, w):
        """Δw of a stop to rest: s_v = 1 − t, t ∈ [0, 1], in SUBSTEPS explicit steps."""
        start = w
        for j in range(SUBSTEPS):
            factor = 1 - (j + 0.5) / SUBSTEPS
            w = w + self.kappa * self.speed * factor / SUBSTEPS * self.pressure(w)
        return w - start

    @property
    def rate(self):
        """c_i = κ s_i L, s_i = ½ ‖v_i‖ the sliding distance of a stop to rest."""
        return self.kappa * 0.5 * self.speed * self.L


def run(toy, jumps=None, stops=STOPS):
    """(w after the stops, the stops simulated)."""
    w, k, simulated = np.zeros(len(toy.m)), 0, 0
    modes = toy.modes
    while k < stops:
        increment = toy.stop(w)
        w, simulated = w + increment, simulated + 1
        if jumps is not None:
            jumps.simulated(k, 0, increment)
            n = jumps.length(stops - k - 1, toy.rate, modes, toy.m, to_limit=THICKNESS - w)
            if n:
                w, k = w + n * increment, k + n
                jumps.jumped()
        k += 1
    return w, simulated


def disc():
    r = np.linspace(0.6, 1.0, 41)
    m = r * 0.01
    m[[0, -1]] /= 2
    return Punch(r, m, speed=r, kappa=4e-4, force=m.sum())


def translating():
    x = np.linspace(-0.5, 0.5, 41)
    m = np.full(41, 1 / 40)
    m[[0, -1]] /= 2
    return Punch(x, m, speed=np.ones(41), kappa=3e-4, couple=-0.3 * 0.2, tilt=True, crown=0.01)


def clamped():
    x = np.linspace(0.0, 1.0, 41)
    m = np.full(41, 1 / 40)
    return Punch(x, m, speed=1 + x, kappa=5e-6, plate=False)     # 0.05 % per stop: slow enough to jump


@pytest.mark.parametrize("toy", [disc, translating, clamped])
def test_jumps_agree_with_stop_by_stop(toy):
    model = toy()
    exact, everyone = run(model)
    jumped, simulated = run(model, CycleJumps(1e-3))
    assert everyone == STOPS and simulated < STOPS / 3, simulated
    volume = model.m @ jumped / (model.m @ exact)
    thinnest = (THICKNESS - jumped.max()) / (THICKNESS - exact.max())
    worn = (exact.max() - jumped.max()) / exact.max()
    assert abs(volume - 1) < 0.01 and abs(thinnest - 1) < 0.02 and abs(worn) < 0.02, (volume, thinnest, worn)


def test_the_worn_in_states_are_reached():
    """p·r = const on the disc (uniform increments), p affine under the tilting plate: the jumps' premise.

    Under the tilting plate the pressure's first moment balances the friction couple, Σ m p x = −μFh, so the
    affine worn-in pressure has the slope −μFh / Σ m x² (the closed form's μFh/I towards the leading edge).
    """
    model = disc()
    w, _ = run(model, stops=400)
    pr = model.pressure(w) * model.x
    assert np.std(pr) / np.mean(pr) < 1e-3
    model = translating()
    w, _ = run(model, stops=400)
    p = model.pressure(w)
    slope, mean = np.polyfit(model.x, p, 1)
    assert np.abs(p - (mean + slope * model.x)).max() < 1e-3 * p.mean()
    assert slope == pytest.approx(model.couple / (model.m @ model.x ** 2), rel=1e-3)


def test_settled_counts_the_stops_between():
    a = np.array([1.0, 2.0])
    assert settled(a * (1 + 5e-4), a, 1e-3) and not settled(a * (1 + 5e-3), a, 1e-3)
    assert settled(a * (1 + 5e-3), a, 1e-3, apart=10), "a change over 10 stops is a tenth per stop"
    assert not settled(np.zeros(2), np.zeros(2), 1e-3), "no wear, nothing to jump"


def test_the_bound_vanishes_for_a_rigid_increment_and_scales_with_the_rest():
    x = np.linspace(-1, 1, 11)
    weights = np.full(11, 0.2)
    points = np.column_stack([x, np.zeros(11)])
    modes = rigid_modes(points, [0.0, -1.0], plate=True, tilt=True)
    affine = 2.0 + 0.5 * x
    assert np.abs(non_rigid(affine, modes, weights)).max() < 1e-14
    assert accurate_stops(affine, np.full(11, 0.3), modes, weights) == np.inf
    bumped = affine + 0.01 * (x ** 2 - (x ** 2).mean())
    rest = non_rigid(bumped, modes, weights)
    assert accurate_stops(bumped, np.full(11, 0.3), modes, weights) == pytest.approx(
        PRESSURE_CHANGE * bumped.max() / (0.3 * np.abs(rest).max()))
    clamped = rigid_modes(points, [0.0, -1.0], plate=False, tilt=False)
    assert accurate_stops(affine, np.full(11, 0.3), clamped, weights) == pytest.approx(PRESSURE_CHANGE / 0.3)


def test_room_before_an_update_or_the_limit():
    increment = np.array([0.0, 0.1, 0.2])
    assert room(increment, np.array([5.0, 1.0, 1.0])) == pytest.approx(5.0)
    assert room(np.zeros(3), 1.0) == np.inf


def test_a_jump_never_crosses_the_block_or_the_limit():
    jumps = CycleJumps(1e-2)
    increment = np.array([0.1, 0.1])
    modes, weights, rate = np.ones((2, 1)), np.ones(2), np.full(2, 0.5)
    jumps.simulated(0, 0, increment)
    assert jumps.length(100, rate, modes, weights) == 0, "one stop alone has nothing to compare"
    jumps.simulated(1, 0, increment)
    assert jumps.length(100, rate, modes, weights) == 100
    assert jumps.length(100, rate, modes, weights, to_limit=np.array([0.75, 5.0])) == 7
    assert jumps.length(1, rate, modes, weights) == 0, "a jump of one stop is not worth it"
    jumps.simulated(2, 1, increment)
    assert jumps.length(100, rate, modes, weights) == 0, "a new block starts afresh"
