"""Heat in the time loop (ngwear/runs/heating.py): full runs against closed forms and hand-computed recursions.

A column pressed by a plate on a translating counterface (k = ρ = c = 1, η = 1, adiabatic sides): the surface rise
2q√(t/π)/√(kρc) of the half-space under the frictional flux q = μ p v; the energy balance at every step, adiabatic
and with convection; the lumped disc's recursion and time constant; Archard's discrete identity with κ(T) read from
the last step's temperature; μ(T) falling through a stop with a lumped body and a lumped disc against the
hand-computed friction force; the coupled time-step study (first order); a bit-identical resume; the one-line
refusal of a coefficient out of range; heat.model = "none" records no heat rows.
"""
import threading

import numpy as np
import pytest

import ngwear
from ngwear.model.examples import scene_file
from ngwear.model.scene import Scene
from ngwear.numerics.heat import Heat
from ngwear.numerics.systems import condensed
from ngwear.results.recording import Recording
from ngwear.results.result import ARRAYS
from ngwear.runs import heating

FINAL = 0.02       # the heat has gone 4√(κT) = 0.57 of the column's height 1 deep


def column(**changes):
    """The half-space column: 0.02 × 1, μ p v = 1 (μ small: the pressure is uniform; stiff: small strains), η = 1."""
    scene = Scene.from_dict({
        "geometry": {"kind": "strip", "size": [0.02, 1.0], "dirichlet": []}, "mesh": {"maxh": 0.01},
        "material": {"lame_lambda": 0.0, "lame_mu": 1000.0, "conductivity": 1.0, "density": 1.0, "heat_capacity": 1.0},
        "contact": {"law": "linear", "stiffness": 100.0, "gap": 0.5, "friction": 1e-3, "wear": 0.0,
                    "direction": [0.0, -1.0]},
        "foundation": {"velocity": [1000.0, 0.0]},
        "loads": {"plate": {"boundary": "top", "force": [0.0, -0.02]}},
        "heat": {"model": "conduction", "partition": 1.0},
        "time": {"T": FINAL, "steps": 20}})
    return scene.replace(**changes) if changes else scene


def balances(monkeypatch):
    """The body's heat balance after every heat step of the runs that follow (a list that fills)."""
    seen, original = [], Heat.advance

    def advance(heat, dt, generated, touching=None):
        out = original(heat, dt, generated, touching)
        seen.append(heat.balance())
        return out

    monkeypatch.setattr(Heat, "advance", advance)
    return seen


def test_half_space_surface_rise_through_a_run_within_three_percent(monkeypatch):
    """The frictional flux of the solved contact heats the column as the half-space: 2q√(t/π) within 3 % from step 5."""
    seen = balances(monkeypatch)
    result = ngwear.simulate(column(), progress=False)
    assert result.completed and result.steps == 20
    q = result.heat_flux / 0.02                                 # η Σ m μ p v / width: the mean flux
    assert np.allclose(q[1:], 1.0, rtol=1e-3)                   # μ p v = 1e-3 · 1 · 1000
    rise = 2 * q[1:] * np.sqrt(result.times[1:] / np.pi)
    mean = result.surface_temperature[1:] @ result.weights / result.weights.sum()
    error = np.abs(mean / rise - 1)
    assert error[4:].max() < 0.03 and error[-1] < 0.01 and error[0] > 0.1, error   # backward Euler: first step worst
    assert np.ptp(result.surface_temperature[-1]) < 0.01 * rise[-1]
    assert np.all(result.surface_temperature[0] == 0) and result.heat_flux[0] == pytest.approx(0.02, rel=1e-3)
    # adiabatic: ∫ρc (T − T₀) = Σ Δt η Q at every step, to round-off
    supplied = np.cumsum(np.diff(result.times) * result.heat_flux[1:])
    assert [b.supplied for b in seen] == pytest.approx(supplied, rel=1e-13)
    assert max(abs(b.residual) / b.supplied for b in seen) < 1e-12
    assert np.all(result.max_temperature >= result.surface_temperature.max(axis=1))


def test_energy_balance_with_convection_at_every_step(monkeypatch):
    seen = balances(monkeypatch)
    result = ngwear.simulate(column(**{"heat.convection": [{"boundary": "left", "coefficient": 50.0},
                                                           {"boundary": "right", "coefficient": 50.0}],
                                       "heat.ambient": 0.0}), progress=False)
    assert result.completed
    assert all(b.convected > 0 for b in seen[1:])
    assert max(abs(b.residual) / b.supplied for b in seen) < 1e-12
    assert seen[-1].convected > 1e-3 * seen[-1].supplied


def lumped_stop(steps=20, **changes):
    """A short, very conductive body on a lumped disc through a stop: v falls linearly from 1 to 0; μ(T) fades."""
    scene = Scene.from_dict({
        "geometry": {"kind": "strip", "size": [1.0, 0.1], "dirichlet": []}, "mesh": {"maxh": 0.05},
        "material": {"lame_lambda": 0.0, "lame_mu": 100.0, "conductivity": 1e4, "density": 1.0,
                     "heat_capacity": 2.0},
        "contact": {"law": "linear", "stiffness": 1e3, "gap": 0.5, "friction": "0.5 - 0.05 * T", "wear": 0.0,
                    "direction": [0.0, -1.0]},
        "foundation": {"velocity": [1.0, 0.0], "speed_table": [[0.0, 1.0], [4.0, 0.0]], "thermal_mass": 3.0,
                       "cooling": 0.5},
        "loads": {"plate": {"boundary": "top", "force": [0.0, -1.0]}},
        "heat": {"model": "conduction", "partition": 0.5, "ambient": 1.0},
        "time": {"T": 4.0, "steps": steps}})
    return scene.replace(**changes) if changes else scene


def test_fading_friction_through_a_stop_is_the_hand_computed_recursion():
    """μ(T) = 0.5 − 0.05 T from the last step's T: friction force, body and disc temperatures by hand.

    The body (capacity C_b = ρc·area = 0.2, k huge: one temperature) and the disc (C_d = 3, H_d = 0.5) share the
    power μ_j N v_j equally (η = ½), by backward Euler:  T_j = T_{j−1} + Δt η μ_j N v_j / C_b,
    T_d,j = (C_d T_d,j−1 + Δt ((1 − η) μ_j N v_j + H_d T_∞)) / (C_d + Δt H_d),  μ_j = 0.5 − 0.05 T_{j−1}.
    """
    result = ngwear.simulate(lumped_stop(), progress=False)
    assert result.completed
    times, dt, N = result.times, 4.0 / 20, 1.0
    body, disc, mu, force = [1.0], [1.0], [0.45], [0.45 * N]
    for t in times[1:]:
        v = 1 - t / 4
        mu.append(0.5 - 0.05 * body[-1])
        power = mu[-1] * N * v
        body.append(body[-1] + dt * 0.5 * power / 0.2)
        disc.append((3.0 * disc[-1] + dt * (0.5 * power + 0.5 * 1.0)) / (3.0 + dt * 0.5))
        force.append(mu[-1] * N if v > 0 else 0.0)
    assert np.allclose(result.surface_temperature, np.array(body)[:, None], rtol=2e-6)
    assert np.allclose(result.foundation_temperature, disc, rtol=2e-6)
    assert np.allclose(result.step_friction, np.array(mu)[:, None], rtol=2e-6)
    assert np.allclose(result.friction_force, force, rtol=2e-6)
    assert result.friction_force[-1] < 0.8 * result.friction_force[0]         # it faded



@pytest.mark.parametrize("conductance", [2.0, "4 * p"], ids=["number", "of-the-pressure"])
def test_a_contact_conductance_couples_the_body_and_the_disc_as_the_hand_computed_recursion(monkeypatch, conductance):
    """A contact conductance couples body and disc implicitly: the stop above, by hand, as a 2 × 2 system a step.

    ``heat.interface = "conductance"``, h_c = 2 or 4 p (of the last step's pressure, as μ(T) is of its T): the faces
    exchange G (T_d − T_b) besides their shares, G = Σ m_i h_c,i over the touching points; per step the system

        C_b (T_b − T_b') = Δt (η P + G (T_d − T_b)),   C_d (T_d − T_d') = Δt ((1 − η) P + H_d (T_∞ − T_d) − G (T_d − T_b)),

    and the body's balance, the exchange included, to round-off at every step.
    """
    seen = balances(monkeypatch)
    result = ngwear.simulate(lumped_stop(**{"heat.interface": "conductance", "heat.contact_conductance": conductance}),
                             progress=False)
    assert result.completed
    times, dt, N = result.times, 4.0 / 20, 1.0
    touching = result.pressure + result.reaction > 0
    body, disc = [1.0], [1.0]
    for j, t in enumerate(times[1:], start=1):
        h = np.full(len(result.weights), 2.0) if conductance == 2.0 else 4 * result.pressure[j - 1]
        power, G = (0.5 - 0.05 * body[-1]) * N * (1 - t / 4), (result.weights * h) @ touching[j]
        system = np.array([[0.2 + dt * G, -dt * G], [-dt * G, 3.0 + dt * (0.5 + G)]])
        b, d = np.linalg.solve(system, [0.2 * body[-1] + dt * 0.5 * power,
                                        3.0 * disc[-1] + dt * (0.5 * power + 0.5 * 1.0)])
        body.append(b), disc.append(d)
    assert np.allclose(result.surface_temperature, np.array(body)[:, None], rtol=2e-6)
    assert np.allclose(result.foundation_temperature, disc, rtol=2e-6)
    # the balance to the solves' round-off: cond(M + Δt A) ≈ Δt k / (ρc h²) = 0.2 · 1e4 / (2 · 0.05²) = 4e5
    assert all(b.exchanged != 0 for b in seen[1:]) and max(abs(b.residual) / b.stored for b in seen[1:]) < 1e-8
    apart = ngwear.simulate(lumped_stop(), progress=False)
    assert abs(result.surface_temperature[-1, 0] - result.foundation_temperature[-1]) < \
        abs(apart.surface_temperature[-1, 0] - apart.foundation_temperature[-1]), "the exchange evens them out"


def test_a_friction_of_temperature_keeps_newtons_factorisations_and_agrees_with_refactorising(monkeypatch):
    """μ(T) changes at every step: the Newton matrices of a reference μ are factorised once.

    They refine each step's (numerics.systems.condensed.Factors); the run agrees with one that factorises them for every μ to
    Newton's tolerance (1e-10 of its scale g).  Here μ falls by 11 %: with the reference kept within 50 % of it, one
    factorisation, and one at the last step, where the disc stops (n* = 0).
    """
    factorised, lu = [], condensed.sla.lu_factor
    monkeypatch.setattr(condensed.sla, "lu_factor", lambda *a, **k: factorised.append(1) or lu(*a, **k))
    monkeypatch.setattr(heating, "DRIFT", 0.5)
    kept = ngwear.simulate(lumped_stop(), progress=False)
    once = len(factorised)
    monkeypatch.setattr(condensed, "SWEEPS", 0)                      # no refinement: each μ's own factorisation
    fresh = ngwear.simulate(lumped_stop(), progress=False)
    assert kept.completed and fresh.completed and once == 2 and len(factorised) - once >= 20
    assert kept.step_friction[-1].max() < 0.9 * kept.step_friction[0].min()
    length = 1e-10 * 0.5                                          # Newton's merit: relative to g = 0.5 here
    assert np.abs(kept.normal_displacement - fresh.normal_displacement).max() <= length
    assert np.abs(kept.pressure - fresh.pressure).max() <= 1e3 * length      # p = L (s − d₀)
    for name in ("surface_temperature", "foundation_temperature", "step_friction", "friction_force"):
        assert np.allclose(getattr(kept, name), getattr(fresh, name), rtol=1e-10, atol=0), name


def test_a_programme_with_heat_cools_over_its_dwells_and_tabulates_each_stops_temperatures(monkeypatch):
    """The fading stop above twice (v: 1 → 0 over 4, 10 steps), a dwell of 6 after each: a hand recursion through all.

    The crossing slides nothing: the adiabatic body keeps its heat to round-off, the disc relaxes to T_∞ over the dwell
    by 15 backward-Euler steps of the stop's 0.4, (C_d / (C_d + Δt H_d))¹⁵ = (3 / 3.2)¹⁵ = 0.38 (e⁻¹ = 0.37 exactly,
    one step's ½ before), ``heat_flux`` is 0; in the stops the body and the disc
    follow the recursion of the single stop, μ_j = μ(T_{j−1}) (the crossing's row included).  The stop table's
    temperatures are the rows' at the stop's first and last rows and the maximum over them; its energy is ∫ F_t v dt
    with the μ each step used (it fades: the second stop dissipates less).
    """
    seen = balances(monkeypatch)
    data = lumped_stop().to_dict()
    data.pop("time")
    data["foundation"].pop("speed_table")
    data["output"].pop("every", None)
    scene = Scene.from_dict({**data, "programme": {"stops": [{"count": 2, "duration": 4.0, "speed": [1.0, 0.0],
                                                              "dwell": 6.0}], "steps_per_stop": 10}})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed and result.steps == 22 and result.times[11] == 10.0 and result.times[22] == 20.0
    crossing = seen[24]                         # row 11: 15 Heat.advance calls (seen[10:25]), which start at row 1
    assert len(seen) == 50 and crossing.supplied == seen[9].supplied and crossing.convected == seen[9].convected == 0
    # to the solve's round-off: cond(M + Δt A) ≈ Δt k / (ρc h²) = 0.4 · 1e4 / (2 · 0.05²) ≈ 1e6, 15 times
    assert crossing.stored == pytest.approx(seen[9].stored, rel=1e-8, abs=0)
    assert result.heat_flux[11] == 0 and result.heat_flux[12] > 0
    body, disc, mu = [1.0], [1.0], [0.45]
    for j in range(1, 23):                      # row 22: the last dwell, to the programme's end
        mu.append(0.5 - 0.05 * body[-1])
        steps, power = (15, 0.0) if j in (11, 22) else (1, mu[-1] * (1 - 0.1 * (j % 11)))    # N = 1
        body.append(body[-1] + 0.4 * 0.5 * power / 0.2)
        disc.append(disc[-1])
        for _ in range(steps):
            disc[-1] = (3.0 * disc[-1] + 0.4 * (0.5 * power + 0.5 * 1.0)) / (3.0 + 0.4 * 0.5)
    assert disc[11] - 1.0 == pytest.approx((3 / 3.2) ** 15 * (disc[10] - 1.0), rel=1e-12)
    assert np.allclose(result.max_temperature, body, rtol=2e-6)
    assert np.allclose(result.foundation_temperature, disc, rtol=2e-6)
    assert np.allclose(result.step_friction, np.array(mu)[:, None], rtol=2e-6)
    stops = result.stops
    assert list(stops.columns[-7:]) == ["temperature_start", "temperature_peak", "temperature_end",
                                        "foundation_temperature_start", "foundation_temperature_peak",
                                        "foundation_temperature_end", "simulated"]
    for stop, rows in ((0, slice(0, 11)), (1, slice(11, 22))):
        for name, values in (("temperature", result.max_temperature),
                             ("foundation_temperature", result.foundation_temperature)):
            assert stops.loc[stop, f"{name}_start"] == values[rows][0]
            assert stops.loc[stop, f"{name}_peak"] == values[rows].max()
            assert stops.loc[stop, f"{name}_end"] == values[rows][-1]
        times, v = result.times[rows], 1 - (result.times[rows] - result.times[rows][0]) / 4
        work = result.friction_force[rows] * v
        energy = np.sum(0.5 * (work[1:] + work[:-1]) * np.diff(times))
        assert stops.loc[stop, "energy"] == pytest.approx(energy, rel=1e-9)
    assert stops.loc[1, "temperature_start"] == pytest.approx(stops.loc[0, "temperature_end"], rel=1e-8)   # kept
    assert stops.loc[0, "foundation_temperature_peak"] > stops.loc[0, "foundation_temperature_end"]   # it cooled
    assert stops.loc[1, "energy"] < 0.95 * stops.loc[0, "energy"]                                      # fade
    assert result.foundation_temperature[22] < result.foundation_temperature[21] and result.heat_flux[22] == 0
    assert result.speed_factor[22] == result.load_factor[22] == 0.0                  # the last dwell cools the disc
    block, = result.summary()["blocks"]                 # one block: its peaks are the whole run's
    assert block["peak_face_temperature"] == result.surface_temperature.max()
    assert block["peak_track_temperature"] == pytest.approx(max(disc), rel=2e-6)



def test_a_cycle_jump_heats_the_body_and_the_disc_as_the_stops_it_applies(tmp_path, monkeypatch):
    """Eight fading stops (μ = 0.45, κ > 0), cycle jumps on: stops 4-6 are applied at once after stop 3.

    A jump takes the heat as it takes the wear, N cycles of the last simulated one (start to start): the adiabatic
    body, which every stop heats by the same 2.025, starts stop 7 at 1 + 7 · 2.025 (a crossing that only cooled
    started it at 1 + 4 · 2.025); the disc at its cooled state plus 3 × its change over stop 3's cycle; the heat's
    clock is the run's and the energy balance holds.  A run resumed in the stop the jump repeats goes on bit for bit.
    """
    seen = balances(monkeypatch)
    data = lumped_stop(**{"contact.wear": 1e-3, "contact.friction": 0.45}).to_dict()
    data.pop("time")
    data["foundation"].pop("speed_table")
    data["output"].pop("every", None)
    scene = Scene.from_dict({**data, "programme": {"stops": [{"count": 8, "duration": 4.0, "speed": [1.0, 0.0],
                                                              "dwell": 6.0}], "steps_per_stop": 10, "jump": True,
                                                   "jump_tolerance": 0.5}})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed and result.jumped.tolist() == [4, 5, 6] and result.times[44] == 70.0
    starts = result.max_temperature[[0, 11, 22, 33, 44]]                  # rows of the simulated stops' starts
    assert np.allclose(starts, 1 + 2.025 * np.array([0, 1, 2, 3, 7]), rtol=1e-8)
    disc = result.foundation_temperature
    cooled = 1.0 + (3 / 3.2) ** 15 * (disc[43] - 1.0)                     # stop 3's end over one dwell
    assert disc[44] == pytest.approx(cooled + 3 * (cooled - disc[33]), rel=1e-10)
    assert result.continuation["heat_heat"][0] == pytest.approx(result.times[-1], rel=1e-14)   # the heat's time
    assert abs(seen[-1].residual) < 1e-8 * seen[-1].supplied          # the dwells' solves: cond ≈ 1e6 each
    # the state of the stop the jump extrapolates from goes into a checkpoint: resumed after it, the same to the bit
    stop, original, count = threading.Event(), Recording.append, []

    def counting(recording, *step):
        original(recording, *step)
        count.append(1)
        if len(count) == 40:                                              # in stop 3, the cycle the jump repeats
            stop.set()

    monkeypatch.setattr(Recording, "append", counting)
    part = ngwear.simulate(scene, progress=False, checkpoint=tmp_path, stop=stop)
    monkeypatch.undo()
    resumed = ngwear.simulate(scene, progress=False, resume=tmp_path)
    assert part.status == "interrupted" and resumed.jumped.tolist() == [4, 5, 6]
    for name in ("max_temperature", "foundation_temperature", "surface_temperature", "wear"):
        assert np.array_equal(getattr(resumed, name), getattr(result, name)), name

def test_archards_discrete_identity_with_a_wear_coefficient_of_temperature():
    """Explicit: w_{j+1} = w_j + Δt κ(T_j) ‖v‖ p_j at every point, κ read from the last step's surface temperature."""
    result = ngwear.simulate(lumped_stop(**{"contact.wear": "1e-3 * (1 + exp((T - 3) / 2))", "contact.friction": 0.5,
                                            "foundation.speed_table": [[0.0, 1.0], [4.0, 1.0]]}), progress=False)
    assert result.completed
    kappa = 1e-3 * (1 + np.exp((result.surface_temperature[:-1] - 3) / 2))
    assert np.allclose(result.step_wear_coefficient[1:], kappa, rtol=1e-13)
    increment = np.diff(result.times)[:, None] * kappa * 1.0 * result.pressure[:-1]
    assert np.allclose(np.diff(result.wear, axis=0), increment, rtol=1e-10, atol=1e-16)
    assert result.step_wear_coefficient[-1].min() > 1.5 * result.step_wear_coefficient[0].max()  # hotter, faster


def test_the_coupling_converges_at_first_order_in_the_step():
    """μ(T) feeds back on the heat: the end temperature's error against 320 steps halves with the step."""
    ends = {n: ngwear.simulate(lumped_stop(steps=n), progress=False).surface_temperature[-1].mean()
            for n in (10, 20, 40, 320)}
    errors = [abs(ends[n] - ends[320]) for n in (10, 20, 40)]
    order = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all((0.85 < order) & (order < 1.15)), (errors, order)


def test_resume_is_bit_identical_with_heat(tmp_path, monkeypatch):
    scene = lumped_stop()
    full = ngwear.simulate(scene, progress=False)
    stop, original, count = threading.Event(), Recording.append, []

    def counting(recording, *step):
        original(recording, *step)
        count.append(1)
        if len(count) == 8:
            stop.set()

    monkeypatch.setattr(Recording, "append", counting)
    part = ngwear.simulate(scene, progress=False, checkpoint=tmp_path, stop=stop)
    monkeypatch.undo()
    assert part.status == "interrupted" and part.steps == 7
    resumed = ngwear.simulate(scene, progress=False, resume=tmp_path)
    for name in ("surface_temperature", "foundation_temperature", "max_temperature", "heat_flux", "step_friction",
                 "pressure"):
        assert np.array_equal(getattr(resumed, name), getattr(full, name)), name


def test_a_coefficient_out_of_range_stops_the_run_with_one_line_keeping_the_steps():
    result = ngwear.simulate(lumped_stop(**{"contact.friction": "0.45 - 10 * max(T - 1.5, 0)"}), progress=False)
    assert not result.completed and "\n" not in result.status and result.steps > 0
    assert result.status.startswith(f"step {result.steps + 1}: contact.friction: must be >= 0 at every contact point")
    assert "T = " in result.status and "at t = " in result.status


def test_no_heat_records_no_heat_rows(tmp_path):
    result = ngwear.simulate(column(**{"heat.model": "none", "time.steps": 2}), progress=False)
    assert tuple(result.rows) == ARRAYS and not any(key.startswith("heat_") for key in result.continuation)
    with pytest.raises(AttributeError, match="surface_temperature: not recorded"):
        result.surface_temperature


def test_a_study_sweeps_heat_keys_and_tabulates_the_highest_temperature():
    """The heat keys vary like any scene key (one group: they invalidate nothing); max_temperature is an output."""
    from ngwear.studies.outputs import outputs
    from ngwear.studies.study import study_from_dict

    study = study_from_dict({"scene": lumped_stop().to_dict(),
                             "grid": {"heat.partition": [0.25, 0.5], "foundation.cooling": [0.5, 2.0]}})
    assert [c.scene.heat.partition for c in study.cases] == [0.25, 0.25, 0.5, 0.5]
    assert len({c.group for c in study.cases}) == 1 and "max_temperature" in study.outputs
    hot, cool = (ngwear.simulate(study.cases[i].scene, progress=False) for i in (2, 0))
    assert outputs(hot)["max_temperature"] > outputs(cool)["max_temperature"] > 1.0   # more of the heat: hotter
    assert np.isnan(outputs(ngwear.simulate(column(**{"heat.model": "none", "time.steps": 2}),
                                            progress=False))["max_temperature"])


def test_thermal_expansion_lifts_a_force_controlled_plate_by_alpha_dT_H():
    """Heated, a body under a plate holding a force lifts the plate by α (T_j − T₀) H.

    One temperature (k huge), ν = 0; T_j the last step's (explicit); the force stays, and the recovered displacement
    carries the lift.
    """
    alpha, height = 1e-3, 0.1
    cold = ngwear.simulate(lumped_stop(**{"contact.friction": 0.5}), progress=False)
    hot = ngwear.simulate(lumped_stop(**{"contact.friction": 0.5, "material.expansion": alpha}), progress=False)
    assert hot.completed and np.allclose(hot.surface_temperature, cold.surface_temperature, rtol=1e-7)
    lift = hot.plate_displacement[1:, 0] - cold.plate_displacement[1:, 0]         # δ along ν = −y
    rise = hot.surface_temperature[:-1].mean(axis=1) - 1.0                        # T_j − T₀ of the step before
    assert np.allclose(lift, -alpha * rise * height, rtol=1e-4, atol=1e-12) and rise[-1] > 1
    assert np.allclose(hot.normal_force, cold.normal_force, rtol=1e-9)
    top = np.array([[0.5, height]])
    moved = hot.displacement_at(top, -1)[0, 1] - cold.displacement_at(top, -1)[0, 1]
    assert moved == pytest.approx(alpha * rise[-1] * height, rel=1e-3)


def test_the_explorer_shows_the_temperatures_and_sweeps_a_heat_key():
    """The summary names the highest temperature; the plots gain a row of temperatures, and lose it without heat."""
    from ngwear.views.explore import Explorer

    explorer = Explorer(lumped_stop(**{"contact.friction": 0.5}))
    before = explorer.result.max_temperature.max()
    assert f"max T {before:.4g} at t = " in explorer.summary()
    explorer.set(**{"heat.partition": 0.8})                       # more of the heat into the body: hotter
    result = explorer.result
    assert result.max_temperature.max() > before and "reuses everything" in explorer.summary()
    explorer.scrub(5)
    heated, lines = explorer.plots(), explorer.dashboard._lines
    x, shown = lines["surface_temperature"].get_data()
    order = np.argsort(result.contact_points[:, 0])
    assert np.array_equal(shown, result.surface_temperature[5, order]) and np.array_equal(x, np.sort(x))
    assert np.array_equal(lines["max_temperature"].get_ydata(), result.max_temperature)
    assert lines["now_heat"].get_xdata()[0] == result.times[5]
    explorer.set(**{"heat.model": "none"})
    cold = explorer.plots()
    assert heated.shape == (2 * cold.shape[0], cold.shape[1], 3) and "surface_temperature" not in explorer.dashboard._lines
    assert "max T" not in explorer.summary()


def test_the_dashboard_maps_the_temperature_of_a_pads_face():
    """3D: the contact face's points coloured by T over the two coordinates across ν (x, y for the pad)."""
    from ngwear.views.plots import Dashboard

    scene = ngwear.load_scene(scene_file("brake_pad")).replace(**{
        "mesh.maxh": 0.012, "time.T": 20.0, "time.steps": 4, "output.every": 20.0, "heat.model": "conduction",
        "heat.partition": 0.2, "material.conductivity": 1.2, "material.density": 2600.0,
        "material.heat_capacity": 1465.0})
    result = ngwear.simulate(scene, progress=False)
    board = Dashboard(size=(8, 2.5), dpi=80)
    image, face = board.image(result, -1), board._lines["surface_temperature"]
    order = np.argsort(result.contact_points[:, 0])
    assert image.shape == (400, 640, 3)
    assert np.array_equal(face.get_offsets(), result.contact_points[order][:, :2])
    assert np.array_equal(face.get_array(), result.surface_temperature[-1, order])
    assert face.get_clim() == (result.surface_temperature.min(), result.max_temperature.max())
    assert np.ptp(result.surface_temperature[-1]) > 0


def test_the_shipped_heat_scene_says_where_it_cools_below_its_start_and_the_bounded_step_does_not(monkeypatch):
    """The shipped heat pad: the consistent step's undershoot said in one warning; the bounded step has none.

    From 20 °C at its coarse face the consistent step cools a node to −5.2 °C and the run says so naming heat.scheme;
    with ``heat.scheme = "bounded"`` every node at every step stays at or above 20 °C, the balance closed, the peak
    within 2 % of the consistent step's.
    """
    lowest, original = [], Heat.advance

    def advance(heat, dt, generated, touching=None):
        out = original(heat, dt, generated, touching)
        lowest.append(float(out.min()))
        return out

    monkeypatch.setattr(Heat, "advance", advance)
    seen = balances(monkeypatch)
    scene = ngwear.load_scene(scene_file("brake_pad_heat"))
    consistent = ngwear.simulate(scene, progress=False)
    coldest = min(lowest)
    said = [w for w in consistent.warnings if w.startswith("heat.scheme:")]
    assert coldest < 0.0 and len(said) == 1 and f"fell to {coldest:.4g} °C" in said[0] and "'bounded'" in said[0]
    lowest.clear(), seen.clear()
    bounded = ngwear.simulate(scene.replace(**{"heat.scheme": "bounded"}), progress=False)
    assert bounded.completed and len(lowest) == bounded.steps and scene.heat.start == scene.heat.ambient == 20.0
    assert min(lowest) >= 20.0 - 1e-12 and min(f.min() for f in bounded.temperatures.values()) >= 20.0 - 1e-12
    assert not [w for w in bounded.warnings if w.startswith("heat.scheme:")]
    assert bounded.max_temperature.max() == pytest.approx(consistent.max_temperature.max(), rel=0.02)
    assert max(abs(b.residual) / b.supplied for b in seen if b.supplied) < 1e-12


def test_a_thermal_strain_warning_names_the_thermal_expansion():
    """Strains past 1 % by heat alone (α = 2e-4 1/K on the shipped heat pad) are said of material.expansion.

    The warning gives α ΔT; it named the softest modulus, material.shear_axis.
    """
    scene = ngwear.load_scene(scene_file("brake_pad_heat")).replace(**{"material.expansion": 2e-4})
    result = ngwear.simulate(scene, progress=False)
    strained = [w for w in result.warnings if "strains reach at least" in w]
    assert result.completed and len(strained) == 1
    assert strained[0].startswith("material.expansion = 0.0002 1/K: strains reach at least ")
    assert "(thermal expansion: α ΔT = " in strained[0] and "shear_axis" not in strained[0]
    cool = ngwear.simulate(scene.replace(**{"material.expansion": 2e-5}), progress=False)
    assert not [w for w in cool.warnings if "strains reach at least" in w]


def test_temperature_limits_are_said_with_the_region_the_step_and_the_temperature(tmp_path):
    """Temperature limits on the shipped heat pad: one warning each, as the rows give them; a resume says the same.

    ``material.max_temperature`` and ``foundation.max_temperature``: the first step past it and the peak (the face,
    the body's hottest, is its friction region's); the backing's own limit, above what it reaches, says nothing.
    """
    limits = {"material.max_temperature": 120.0, "material.regions.backing.max_temperature": 1000.0,
              "foundation.max_temperature": 25.0}
    scene = ngwear.load_scene(scene_file("brake_pad_heat")).replace(**limits)
    whole = ngwear.simulate(scene, progress=False)
    said = {w.split(" = ")[0]: w for w in whole.warnings if w.split(" = ")[0].endswith("max_temperature")}
    assert set(said) == {"material.max_temperature", "foundation.max_temperature"}
    for key, rows, what in (("material.max_temperature", whole.max_temperature, "region body"),
                            ("foundation.max_temperature", whole.foundation_temperature, "the counterface")):
        first, peak = int(np.argmax(rows > limits[key])), int(np.argmax(rows))
        assert said[key] == (f"{key} = {limits[key]:g} °C: {what} passed it at step {first} (t = {whole.times[first]:.4g}"
                             f" s), up to {rows[peak]:.4g} °C at step {peak} (t = {whole.times[peak]:.4g} s)")
    half = scene.replace(**{"time.T": scene.time.T / 2, "time.steps": scene.time.steps // 2})
    ngwear.simulate(half, progress=False, checkpoint=tmp_path)
    resumed = ngwear.simulate(scene, progress=False, resume=tmp_path)
    assert resumed.warnings == whole.warnings
    unlimited = ngwear.simulate(scene.replace(**{key: None for key in limits}), progress=False)
    assert not [w for w in unlimited.warnings if "max_temperature" in w]


def test_a_contact_conductance_of_the_state_out_of_range_stops_the_run_in_one_line_keeping_the_steps():
    result = ngwear.simulate(lumped_stop(**{"heat.interface": "conductance",
                                            "heat.contact_conductance": "1 - 100 * p"}), progress=False)
    assert not result.completed and result.steps >= 0
    assert "heat.contact_conductance: must be >= 0 at every contact point" in result.status, result.status
    assert "\n" not in result.status
