"""The heat solver against closed forms under a prescribed flux (ngwear/numerics/heat.py, counterface.py).

The half-space under a uniform flux q (surface rise 2q√(t/π)/√(kρc), profile (2q/k)√(κt) ierfc(z/(2√(κt)))) on a
column whose back the heat has not reached, its orders in time and space; the discrete energy balance with and
without convection; the steady state through a convected face; the lumped counterface's approach to
T_∞ + (1 − η)Q/H_d with time constant C_d/H_d; checkpoints.
"""
import ngsolve as ngs
import numpy as np
import pytest
import scipy.sparse.linalg as spla
from scipy.special import erfc

from ngwear.model.keys import SceneError
from ngwear.model.scene import Scene
from ngwear.model.scene_mesh import build_mesh
from ngwear.model.thermal import partition
from ngwear.numerics.forms import displacement_space
from ngwear.numerics.heat import Heat, frictional_power
from ngwear.numerics.points import contact_points
from ngwear.numerics.stiffness import assembled

FINAL = 0.02       # the column's time: the heat has gone 4√(κT) = 0.57 of its height 1 deep
THERMAL = {"conductivity": 1.0, "density": 1.0, "heat_capacity": 1.0}


def scene_of(kind="strip", size=(0.02, 1.0), maxh=0.01, order=1, material=None, heat=None, **tables):
    """A scene of k = ρ = c = 1 and η = 1 unless ``material`` and ``heat`` say otherwise."""
    return Scene.from_dict({"geometry": {"kind": kind, "size": list(size)}, "mesh": {"maxh": maxh, "order": order},
                            "material": {**THERMAL, **(material or {})},
                            "heat": {"model": "conduction", "partition": 1.0, **(heat or {})}, **tables})


def heat_of(scene):
    """(Heat, mesh) of a scene on its mesh and contact points."""
    mesh = build_mesh(scene)
    return Heat(scene, mesh, contact_points(displacement_space(mesh, scene), scene.dim, scene.mesh.order)), mesh


def column(maxh, steps, q=1.0):
    """The half-space column after ``steps`` uniform steps to FINAL: (surface temperatures per step, heat, depths)."""
    heat, mesh = heat_of(scene_of(maxh=maxh))
    surface = []
    for _ in range(steps):
        heat.advance(FINAL / steps, np.full(len(heat.weights), q))
        surface.append(heat.surface_temperature())
    return np.array(surface), heat, np.array(mesh.ngmesh.Coordinates())[:, 1]


def surface_exact(t, q=1.0):
    return 2 * q * np.sqrt(np.asarray(t) / np.pi)


def profile_exact(z, t, q=1.0):
    x = z / (2 * np.sqrt(t))
    return 2 * q * np.sqrt(t) * (np.exp(-x * x) / np.sqrt(np.pi) - x * erfc(x))


def test_half_space_surface_rise_and_profile_within_three_percent():
    """From the 5th step on the surface rise is within 3 % of 2q√(t/π)/e; at T the profile too; the back is cold."""
    steps = 20
    surface, heat, depth = column(0.01, steps)
    times = FINAL / steps * np.arange(1, steps + 1)
    error = np.abs(surface / surface_exact(times)[:, None] - 1)
    assert error[4:].max() < 0.03 and error[-1].max() < 0.01, error.max(axis=1)
    assert error[0].max() > 0.1               # the first step after the flux starts is backward Euler's worst
    scale = surface_exact(FINAL)
    assert np.abs(heat.temperature - profile_exact(depth, FINAL)).max() < 0.03 * scale
    assert heat.temperature[depth > 0.99].max() < 1e-5 * scale    # before the heat reaches the back
    assert heat.max_temperature() == pytest.approx(surface[-1].max(), rel=1e-12)


def test_half_space_converges_at_first_order_in_time():
    """Backward Euler: the surface error at T halves with the step (observed order 1)."""
    steps = np.array([10, 20, 40, 80])
    errors = [abs(column(0.005, n)[0][-1].mean() / surface_exact(FINAL) - 1) for n in steps]
    order = -np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert 0.95 < order < 1.05, (errors, order)


def test_half_space_converges_at_second_order_in_space():
    """P1: the L² error of the profile at T falls as h² (the time error removed by Richardson, 2 T_2N − T_N)."""
    sizes, errors = np.array([0.04, 0.02, 0.01, 0.005]), []
    for h in sizes:
        (_, coarse, depth), (_, fine, _) = column(h, 400), column(h, 800)
        error = 2 * fine.temperature - coarse.temperature - profile_exact(depth, FINAL)
        errors.append(np.sqrt(error @ fine.mass @ error / fine.capacity.sum()))
    order = np.polyfit(np.log(sizes), np.log(errors), 1)[0]
    assert 1.7 < order < 2.6, (errors, order)


@pytest.mark.parametrize("kind, size, order", [("strip", (1.0, 0.4), 1), ("strip", (1.0, 0.4), 2),
                                               ("box", (1.0, 0.5, 0.3), 2)])
def test_adiabatic_energy_balance_closes_to_round_off(kind, size, order):
    """∫ρc(T − T₀) = Σ Δt η Σ m_i q_i at every step, for any flux over Γ_C, P2's midpoints and changing steps too."""
    scene = scene_of(kind, size, maxh=0.25, order=order, heat={"partition": 0.7, "initial": 15.0},
                     material={"density": 7.0})
    heat, _ = heat_of(scene)
    rng, supplied = np.random.default_rng(1), 0.0
    for dt in (0.1, 0.1, 0.02, 0.3, 0.02, 0.1):
        q = rng.uniform(0.0, 5.0, len(heat.weights))
        heat.advance(dt, q)
        supplied += dt * 0.7 * heat.weights @ q
        balance = heat.balance()
        assert balance.supplied == pytest.approx(supplied, rel=1e-14)
        assert abs(balance.residual) < 1e-13 * supplied and balance.convected == 0
        assert heat.heat_flux == pytest.approx(0.7 * heat.weights @ q, rel=1e-14)
    assert len(heat._factors) == 3                  # one factorisation per step size


def test_convected_energy_balance_closes_and_reaches_the_steady_state():
    """With convection on the top: the balance includes the convected heat; the steady state is 1D's closed form.

    Flux q in at y = 0, h (T − T_∞) = q out at y = L: T(L) = T_∞ + q/h, T(0) = T(L) + qL/k.
    """
    q, h, k, ambient, length = 2.0, 4.0, 0.5, 10.0, 0.5
    scene = scene_of(size=(0.2, length), maxh=0.05, material={"conductivity": k},
                     heat={"convection": [{"boundary": "top", "coefficient": h}], "ambient": ambient})
    heat, mesh = heat_of(scene)
    for dt in (0.05,) * 10 + (1e3,) * 3:
        heat.advance(dt, np.full(len(heat.weights), q))
        balance = heat.balance()
        assert abs(balance.residual) < 1e-13 * balance.supplied
    assert balance.convected > 0.5 * balance.supplied          # most of the heat left through the top
    depth = np.array(mesh.ngmesh.Coordinates())[:, 1]
    steady = ambient + q / h + q * (length - depth) / k
    assert np.abs(heat.temperature - steady).max() < 1e-9 * steady.max()


@pytest.mark.parametrize("kind, size, maxh, dt", [("box", (1.0, 0.5, 0.3), 0.1, 1e-4), ("box", (1.0, 0.5, 0.3), 0.15, 1e-3),
                                                  ("strip", (1.0, 0.4), 0.1, 1e-4)])
def test_the_bounded_step_keeps_every_temperature_above_its_start_where_the_consistent_one_undershoots(kind, size, maxh, dt):
    """A flux switched on, steps short against h²/κ: no node below T₀, where the consistent scheme undershoots.

    Backward Euler with the consistent M and K (``heat.scheme = "consistent"``) cools nodes below T₀ = 0 (by 0.2 % of
    the peak and more); the bounded step keeps every node at or above it, the heat balance to round-off, the same
    heat.
    """
    heat, _ = heat_of(scene_of(kind=kind, size=size, maxh=maxh, heat={"scheme": "bounded"}))
    u, v = heat.space.TnT()
    M = assembled(ngs.BilinearForm(u * v * ngs.dx, symmetric=True))
    K = assembled(ngs.BilinearForm(ngs.grad(u) * ngs.grad(v) * ngs.dx, symmetric=True))
    q = np.ones(len(heat.weights))
    solve, consistent = spla.factorized((M + dt * K).tocsc()), np.zeros(M.shape[0])
    for _ in range(5):
        consistent = solve(M @ consistent + dt * heat.evaluation.T @ (heat.weights * q))
        heat.advance(dt, q)
        assert heat.temperature.min() >= -1e-14 * heat.temperature.max()
        assert abs(heat.balance().residual) < 1e-12 * heat.balance().supplied
    assert consistent.min() < -2e-3 * consistent.max(), "the consistent scheme undershoots here"
    assert heat.capacity @ heat.temperature == pytest.approx(np.ones(M.shape[0]) @ M @ consistent, rel=1e-12)


def test_lumped_counterface_approaches_its_steady_temperature_with_its_time_constant():
    """C_d dT_f/dt = (1 − η)Q − H_d(T_f − T_∞): backward Euler's (1 + Δt/τ)^−n, → the exponential as Δt → 0."""
    capacity, cooling, ambient, share = 50.0, 2.0, 20.0, 0.25
    scene = scene_of(size=(1.0, 0.2), maxh=0.2, heat={"partition": share, "ambient": ambient},
                     foundation={"velocity": [1.0, 0.0], "thermal_mass": capacity, "cooling": cooling})
    tau, errors = capacity / cooling, []
    for steps in (50, 100, 200):
        heat, _ = heat_of(scene)
        q = np.full(len(heat.weights), 3.0)
        power, dt = heat.weights @ q, 3 * tau / steps
        limit = ambient + (1 - share) * power / cooling
        for n in range(1, steps + 1):
            heat.advance(dt, q)
            assert heat.foundation_temperature() == pytest.approx(
                limit - (limit - ambient) * (1 + dt / tau) ** -n, rel=1e-13)
        face = heat.counterface
        assert face.stored == pytest.approx(face.received - face.cooled, rel=1e-12)
        assert face.received == pytest.approx(3 * tau * (1 - share) * power, rel=1e-12)
        exact = limit - (limit - ambient) * np.exp(-3.0)
        errors.append(abs(heat.foundation_temperature() - exact))
    assert errors[0] / errors[1] == pytest.approx(2, rel=0.05) and errors[1] / errors[2] == pytest.approx(2, rel=0.05)
    assert errors[-1] < 2e-3 * (limit - ambient)


def test_given_counterface_temperature_follows_its_table():
    scene = scene_of(size=(1.0, 0.2), maxh=0.2, foundation={"velocity": [1.0, 0.0],
                                                             "temperature": [[0.0, 20.0], [2.0, 100.0]]},
                     time={"T": 2.0})
    heat, _ = heat_of(scene)
    assert heat.foundation_temperature() == 20.0
    heat.advance(0.5, np.ones(len(heat.weights)))
    assert heat.foundation_temperature() == pytest.approx(40.0)
    number, _ = heat_of(scene.replace(**{"foundation.temperature": 80.0}))
    number.advance(0.5, np.ones(len(number.weights)))
    assert number.foundation_temperature() == 80.0 and number.state["counterface"].size == 0


def test_effusivity_partition():
    """η = e_b/(e_b + e_f), e = √(kρc); the body takes η of the power, regions of different e on Γ_C are refused."""
    body, face = dict(conductivity=1.2, density=2000.0, heat_capacity=900.0), (50.0, 7200.0, 500.0)
    scene = scene_of(size=(1.0, 0.2), maxh=0.2, material=body, heat={"partition": "effusivity"},
                     foundation={"velocity": [1.0, 0.0], "conductivity": face[0], "density": face[1],
                                 "heat_capacity": face[2]})
    e_b, e_f = np.sqrt(1.2 * 2000 * 900), np.sqrt(np.prod(face))
    heat, _ = heat_of(scene)
    assert heat.partition == pytest.approx(e_b / (e_b + e_f), rel=1e-14)
    heat.advance(1.0, np.full(len(heat.weights), 2.0))
    assert heat.heat_flux == pytest.approx(heat.partition * 2.0 * heat.weights.sum(), rel=1e-14)
    backed = scene.replace(**{"geometry.backing": 0.05, "material.lame_lambda": 1.0, "material.lame_mu": 1.0,
                              "material.regions": {"backing": {"conductivity": 40.0}}})
    with pytest.raises(SceneError, match=r"^heat.partition: 'effusivity' needs one effusivity .* regions body, "
                                          r"backing carrying it differ"):
        partition(backed, ["body", "backing"])


@pytest.mark.parametrize("kind, size", [("strip", (1.0, 0.4)), ("box", (1.0, 0.5, 0.3))])
def test_surface_temperature_is_the_p1_field_at_the_contact_points(kind, size):
    """At P2's edge midpoints (and vertices) E T is the P1 field there: exact for a linear temperature."""
    scene = scene_of(kind, size, maxh=0.25, order=2)
    heat, mesh = heat_of(scene)
    points = contact_points(displacement_space(mesh, scene), scene.dim, 2)
    assert (points.edges >= 0).any() and (kind == "box" or (points.vertices >= 0).any())
    linear = lambda x: 3.0 + x[:, 0] - 2.0 * x[:, -1] + 0.5 * x[:, 1]   # noqa: E731
    heat.temperature = linear(np.array(mesh.ngmesh.Coordinates()))
    assert np.allclose(heat.surface_temperature(), linear(points.coords), rtol=0, atol=1e-12)


def test_state_restores_bit_for_bit():
    """A heat restored from another's state goes on bit for bit (T, the energy so far, the lumped counterface)."""
    scene = scene_of(size=(1.0, 0.3), maxh=0.1, heat={"partition": 0.6, "convection": [{"boundary": "top",
                                                                                          "coefficient": 1.0}]},
                     foundation={"velocity": [1.0, 0.0], "thermal_mass": 5.0, "cooling": 1.0})
    first, _ = heat_of(scene)
    flux = [np.linspace(1.0, 2.0 + k, len(first.weights)) for k in range(6)]
    for q in flux[:3]:
        first.advance(0.1, q)
    second, _ = heat_of(scene)
    second.restore({name: value.copy() for name, value in first.state.items()})
    for q in flux[3:]:
        first.advance(0.1, q)
        second.advance(0.1, q)
    assert np.array_equal(first.temperature, second.temperature) and first.balance() == second.balance()
    assert first.foundation_temperature() == second.foundation_temperature() and first.time == second.time


def test_frictional_power_and_a_bad_flux():
    assert np.array_equal(frictional_power(np.array([0.4, 0.0]), np.array([2.0, 3.0]), np.array([5.0, 5.0])),
                          [4.0, 0.0])
    heat, _ = heat_of(scene_of(size=(1.0, 0.2), maxh=0.2))
    with pytest.raises(ValueError, match="one frictional power per contact point"):
        heat.advance(0.1, np.ones(3))
    scene = scene_of(size=(1.0, 0.2), maxh=0.2)
    with pytest.raises(ValueError, match=r"heat: the scene has no temperature \(heat.model = 'none'\)"):
        heat_of(scene.replace(**{"heat.model": "none"}))


def conducting(h, **heat):
    """The half-space column under ``heat.interface = "conductance"`` with h_c = ``h`` (and ``heat``'s keys)."""
    return scene_of(maxh=0.01, heat={"interface": "conductance", "contact_conductance": h, **heat})


def test_a_face_held_by_a_contact_conductance_warms_as_the_half_space_of_carslaw_and_jaeger():
    """No friction, the counterface at T_f = 1, h_c = 5 (k = ρc = 1): θ(t) = T_f (1 − e^{h²t} erfc(h√t)) at the face.

    Within 3 % from the 5th step of 20, 1 % at the end; the body's heat is what the conductance gave, to round-off.
    """
    from scipy.special import erfcx
    heat, _ = heat_of(Scene.from_dict({**conducting(5.0).to_dict(), "foundation": {"temperature": 1.0}}))
    steps, touching = 20, np.ones(len(heat.weights), dtype=bool)
    surface = []
    for _ in range(steps):
        heat.advance(FINAL / steps, np.zeros(len(heat.weights)), touching)
        surface.append(heat.surface_temperature() @ heat.weights / heat.weights.sum())
        balance = heat.balance()
        assert balance.exchanged > 0 and abs(balance.residual) < 1e-12 * balance.exchanged
    times = FINAL / steps * np.arange(1, steps + 1)
    exact = 1 - erfcx(5.0 * np.sqrt(times))                   # e^{x²} erfc(x), x = h√t
    error = np.abs(np.array(surface) / exact - 1)
    assert error[4:].max() < 0.03 and error[-1] < 0.01, error
    untouched, _ = heat_of(Scene.from_dict({**conducting(5.0).to_dict(), "foundation": {"temperature": 1.0}}))
    untouched.advance(FINAL, np.zeros(len(heat.weights)), np.zeros(len(heat.weights), dtype=bool))
    assert np.all(untouched.temperature == 0.0), "no contact, no exchange"


def test_a_large_conductance_gives_the_faces_one_temperature_and_keeps_the_heat_of_both():
    """A lumped disc on the column heated by q = 1, η = ½ (the default), h_c = 1e6: the faces share one temperature.

    The disc's heat is what it received less what it gave, and body and disc hold every joule friction made, to
    round-off, whatever the split.
    """
    data = conducting(1e6, partition=None).to_dict()
    scene = Scene.from_dict({**data, "foundation": {"thermal_mass": 0.01, "cooling": 0.0}})
    assert scene.heat.partition is None
    heat, _ = heat_of(scene)
    assert heat.partition == 0.5
    touching, made = np.ones(len(heat.weights), dtype=bool), 0.0
    for _ in range(20):
        heat.advance(FINAL / 20, np.ones(len(heat.weights)), touching)
        made += FINAL / 20 * heat.power
    disc, face = heat.counterface, heat.surface_temperature()
    assert np.abs(face - disc.T).max() < 1e-3 * (disc.T - disc.start)
    assert disc.stored == pytest.approx(disc.received - disc.cooled - disc.given, rel=1e-12)
    assert heat.balance().stored + disc.stored == pytest.approx(made, rel=1e-12)
    assert abs(heat.balance().residual) < 1e-12 * made
