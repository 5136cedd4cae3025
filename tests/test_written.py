"""Every number a run writes is the one its solver used: each array of each file against the step's own state.

A heated programme on the strip (μ(T), κ(T), stops to rest with dwells, ``"surface"`` wear with geometry updates,
thermal expansion) runs with its solver's states captured as each step is solved and recorded: the step's instant
(t, s_v, s_F), its coefficients, p, λ, w, δ and the contact forces, the discretization it was solved on, the heat's
rows, nodal T and thermal load G (as the step saw them: a geometry update moves the mesh's vertices), and each
geometry update's W.  From these alone — not through :class:`ngwear.Result` — the test
computes what the contact VTU, the body VTU, ``history.csv``, ``stops.csv`` and ``summary.json`` must hold, and
compares every array.  A pin on a disc given only ``angular_velocity`` has torque · ω = friction power and wears
V = (κ/μ) · dissipated energy.
"""
import json

import numpy as np
import pandas as pd
import pytest
import pyvista as pv
from scipy.integrate import cumulative_trapezoid

import ngwear
from ngwear.model.programme import Schedule
from ngwear.model.scene import Scene
from ngwear.numerics.thickness import thickness
from ngwear.results.history_csv import bare
from ngwear.results.recording import Recording
from ngwear.runs import loop
from ngwear.runs.heating import Heating

RTOL = 1e-12


def heated_life() -> Scene:
    return Scene.from_dict({
        "name": "heated_life",
        "geometry": {"kind": "strip", "size": [1.0, 0.2], "dirichlet": []}, "mesh": {"maxh": 0.05},
        "material": {"lame_lambda": 0.0, "lame_mu": 300.0, "conductivity": 5.0, "density": 1.0, "heat_capacity": 2.0,
                     "expansion": 1e-3},
        "contact": {"law": "linear", "stiffness": 1e3, "gap": 0.05, "friction": "0.5 - 0.02 * T",
                    "wear": "0.05 * (1 + 0.1 * T)", "direction": [0.0, -1.0]},
        "foundation": {"velocity": [1.0, 0.0], "thermal_mass": 3.0, "cooling": 0.5},
        "loads": {"plate": {"boundary": "top", "force": [0.0, -1.0]}},
        "heat": {"model": "conduction", "partition": 0.5, "ambient": 1.0},
        "wear": {"geometry": "surface", "update": 0.5, "integrator": "implicit"},
        "programme": {"stops": [{"count": 3, "duration": 1.0, "speed": [1.0, 0.0], "dwell": 0.5}],
                      "steps_per_stop": 8},
        "output": {"every": 0.5}})


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """(result, its folder, the solver's states of the recorded steps, the updates' (step, W))."""
    solved, loads, steps, updates = {}, {}, [], []
    advance, append, keep, moved = loop.advance, Recording.append, Recording.keep_temperature, Recording.moved
    after = Heating.after

    def advancing(disc, caches, state, target):
        new, record = advance(disc, caches, state, target)
        solved[id(new)] = disc
        return new, record

    def heating(self, state, target):
        loads[id(state)] = self.load                     # G of the discretization in force at the step
        return after(self, state, target)

    def appending(recording, state, heated=None):
        append(recording, state, heated)
        steps.append({"disc": solved[id(state)], "state": state, "heated": dict(heated or {}),
                      "load": loads[id(state)]})

    def keeping(recording, temperature):
        keep(recording, temperature)
        steps[-1]["temperature"] = temperature.copy()

    def moving(recording, realised, disc, before):
        updates.append((len(recording.result.times) - 1, realised.copy()))
        moved(recording, realised, disc, before)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(loop, "advance", advancing)
        patch.setattr(Recording, "append", appending)
        patch.setattr(Recording, "keep_temperature", keeping)
        patch.setattr(Recording, "moved", moving)
        patch.setattr(Heating, "after", heating)
        result = ngwear.simulate(heated_life(), progress=False)
    out = result.save(tmp_path_factory.mktemp("heated_life"))
    assert result.completed and result.geometry_updates >= 2 and len(steps) == result.steps + 1
    return result, out, steps, updates


def expected(result, steps, updates) -> dict:
    """What every step's row must hold, computed from the solver's states alone."""
    first = steps[0]["disc"]
    nu = first.condensation.nu
    reference = first.points.coords                               # the contact points as built
    depth = thickness(first.mesh, reference, nu)
    removed, W = np.zeros(len(reference)), dict(updates)
    rows = {name: [] for name in ("wear", "total_wear", "normal_force", "friction_power", "torque", "tangential_x",
                                  "tangential_y", "contact_area", "max_pressure", "weights")}
    for j, step in enumerate(steps):
        disc, state = step["disc"], step["state"]
        m, f = disc.points.weights, state.forces
        tangential = f - np.outer(f @ nu, nu)
        v = disc.contact.motion.velocity(state.instant.speed)
        wear = np.maximum(state.wear - W[j], 0.0) if j in W else state.wear
        removed = removed + W.get(j, 0.0)
        rows["wear"].append(wear)
        rows["total_wear"].append(wear + removed)
        rows["normal_force"].append(m @ (state.pressure + state.lam))
        rows["friction_power"].append(-np.sum(tangential * v))
        rows["torque"].append(np.sum(reference[:, 0] * tangential[:, 1] - reference[:, 1] * tangential[:, 0]))
        rows["tangential_x"].append(tangential[:, 0].sum())
        rows["tangential_y"].append(tangential[:, 1].sum())
        rows["contact_area"].append(m @ (state.pressure + state.lam > 0))
        rows["max_pressure"].append(state.pressure.max())
        rows["weights"].append(m)
    out = {name: np.array(values) for name, values in rows.items()}
    out["times"] = np.array([s["state"].instant.t for s in steps])
    out["speed_factor"] = np.array([s["state"].instant.speed for s in steps])
    out["load_factor"] = np.array([s["state"].instant.load for s in steps])
    out["remaining_thickness"] = depth - out["total_wear"]
    out["wear_volume"] = np.einsum("ji,ji->j", out["total_wear"], out["weights"])
    out["max_wear"] = out["total_wear"].max(axis=1)
    out["friction_force"] = np.hypot(out["tangential_x"], out["tangential_y"])
    for name, (a, b) in {"apparent_friction": ("friction_force", "normal_force"),
                         "mean_pressure": ("normal_force", "contact_area")}.items():     # 0 where nothing presses
        out[name] = np.divide(out[a], out[b], out=np.zeros_like(out[a]), where=out[b] > 0)
    out["dissipated_energy"] = cumulative_trapezoid(out["friction_power"], out["times"], initial=0.0)
    for name in ("max_temperature", "foundation_temperature", "heat_flux", "surface_temperature", "step_friction",
                 "step_wear_coefficient"):
        out[name] = np.array([s["heated"][name] for s in steps])
    assert np.array_equal(out["step_friction"], [s["state"].coefficients.friction for s in steps])
    assert np.array_equal(out["step_wear_coefficient"], [s["state"].coefficients.wear for s in steps])
    return out


def displacement(step) -> np.ndarray:
    """U of a step from its contact forces, s_F and δ, and its temperature's thermal load: K⁻¹ (s_F f − Pᵀ f_c + f_th)."""
    disc, state = step["disc"], step["state"]
    u = disc.recover(state.forces, state.instant.load, state.plate)
    return u + disc.elastic.operator.solve(step["load"](step["temperature"]))


def close(a, b, name):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape, name
    assert np.allclose(a, b, rtol=RTOL, atol=RTOL * max(np.abs(b).max(initial=0.0), 1e-300)), name


def test_history_csv_holds_the_solvers_numbers_of_every_step(written):
    result, out, steps, updates = written
    want = expected(result, steps, updates)
    table = pd.read_csv(out / "history.csv").rename(columns=bare)
    assert np.array_equal(table["step"], np.arange(len(steps)))
    for name in ("times", "speed_factor", "load_factor", "normal_force", "torque", "friction_force",
                 "apparent_friction", "contact_area", "wear_volume", "max_wear", "max_pressure", "mean_pressure",
                 "friction_power", "dissipated_energy", "max_temperature", "foundation_temperature", "heat_flux"):
        close(table[name], want[name], name)
    close(table["tangential_force_x"], want["tangential_x"], "tangential_force_x")
    close(table["plate_displacement"], [s["state"].plate[0] for s in steps], "plate_displacement")
    assert (want["speed_factor"] == 0).any() and np.ptp(want["step_friction"]) > 0.01   # stops to rest, μ(T) moves
    assert want["max_wear"].max() > result.scene.contact.gap                             # worn beyond the layer


def test_the_contact_files_hold_the_steps_own_fields(written):
    result, out, steps, updates = written
    want = expected(result, steps, updates)
    for j in result.stored_steps:
        face = pv.read(out / f"contact_step{j:03d}.vtu")
        state, disc = steps[j]["state"], steps[j]["disc"]
        assert face.n_points == disc.points.n
        for name, values in (("pressure", state.pressure), ("reaction", state.lam), ("wear", want["wear"][j]),
                             ("total_wear", want["total_wear"][j]),
                             ("remaining_thickness", want["remaining_thickness"][j]),
                             ("slip_rate", np.linalg.norm(disc.contact.motion.velocity(state.instant.speed), axis=1)),
                             ("friction", state.coefficients.friction), ("wear_coefficient", state.coefficients.wear),
                             ("temperature", want["surface_temperature"][j])):
            close(face.point_data[name], values, f"{name} at step {j}")
        along = (disc.points.P @ displacement(steps[j])).reshape(disc.points.n, -1)
        close(face.point_data["displacement"][:, :2], along, f"displacement at step {j}")


def test_the_body_files_hold_the_steps_displacement_and_temperature(written):
    result, out, steps, _ = written
    for j in result.stored_steps:
        body = pv.read(out / f"fields_step{j:03d}.vtu")
        disc, temperature = steps[j]["disc"], steps[j]["temperature"]
        u, nv = displacement(steps[j]), disc.mesh.nv
        coords = result.body_coordinates(j) if result.body_coordinates(j) is not None else \
            disc.mesh.ngmesh.Coordinates()[:, :2]
        vertex = {tuple(np.round(x, 12)): k for k, x in enumerate(coords)}
        at = np.array([vertex[tuple(np.round(x[:2], 12))] for x in body.points])
        close(body.point_data["displacement"][:, :2], u.reshape(2, nv).T[at], f"displacement at step {j}")
        close(body.point_data["temperature"], temperature[at], f"temperature at step {j}")


def test_stops_csv_and_the_summary_hold_the_solvers_numbers(written):
    result, out, steps, updates = written
    want = expected(result, steps, updates)
    schedule, m = Schedule.of(result.scene.programme), result.scene.programme.steps_per_stop
    table = pd.read_csv(out / "stops.csv", index_col="stop").rename(columns=bare)
    assert len(table) == schedule.count
    for stop, end in enumerate(schedule.ends(len(steps))):
        span = slice(end - m, end + 1)
        t, s = want["times"][span], np.abs(want["speed_factor"][span])
        trapz = lambda values: float(np.sum(0.5 * (values[1:] + values[:-1]) * np.diff(t)))  # noqa: E731
        row = table.loc[stop]
        close(row["energy"], trapz(want["friction_power"][span]), "energy")
        close(row["friction_force"], trapz(want["friction_force"][span] * s) / trapz(s), "friction_force")
        increment = want["total_wear"][end] - want["total_wear"][end - m]
        close(row["worn_volume"], increment @ want["weights"][end], "worn_volume")
        close(row["max_total_wear"], want["total_wear"][end].max(), "max_total_wear")
        close(row["min_remaining_thickness"], want["remaining_thickness"][end].min(), "min_remaining_thickness")
        close(row["temperature_peak"], want["max_temperature"][span].max(), "temperature_peak")
        close(row["foundation_temperature_end"], want["foundation_temperature"][end], "foundation_temperature_end")
    summary = json.loads((out / "summary.json").read_text())
    for name in ("normal_force", "friction_power", "contact_area", "max_pressure", "mean_pressure", "wear_volume"):
        close(summary[name], want[name][-1], name)
    close(summary["max_wear"], want["max_wear"].max(), "max_wear")
    close(summary["dissipated_energy"], want["dissipated_energy"][-1], "dissipated_energy")
    close(summary["max_temperature"], want["max_temperature"].max(), "max_temperature")
    close(summary["remaining_thickness_min"], want["remaining_thickness"][-1].min(), "remaining_thickness_min")
    assert summary["geometry_updates"] == len(updates) and summary["steps"] == len(steps) - 1


def test_a_pin_given_only_its_angular_velocity_turns_without_sliding_across(tmp_path):
    """No translation is added: |T ω| = P at every step, and V = (κ/μ) ∫ P dt (the trapezoidal rule on both)."""
    data = ngwear.load_scene("pin_on_disc").to_dict()
    del data["foundation"]["velocity"]
    data["time"], data["wear"], data["output"] = {"T": 12.0, "steps": 20}, {"integrator": "trapezoidal"}, {"every": 6.0}
    pin = Scene.from_dict(data)
    assert pin.foundation.velocity == (0.0, 0.0, 0.0)
    result = ngwear.simulate(pin, progress=False)
    omega = pin.foundation.angular_velocity[2] * result.speed_factor
    assert result.completed and (result.torque[1:] < 0).all()
    assert np.allclose(-result.torque * omega, result.friction_power, rtol=1e-12, atol=0)
    kappa, mu = pin.contact.wear, pin.contact.friction
    assert np.allclose(result.wear_volume, kappa / mu * result.dissipated_energy, rtol=1e-6,
                       atol=1e-6 * result.wear_volume[-1])
