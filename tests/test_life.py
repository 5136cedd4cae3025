"""A part's life in the time loop: programmes run stop by stop, stops.csv, wear.limit, cycle jumps, resume.

A programme's stops drive the run through their factors (``ngwear.runs.stop_clock``); these tests check what a run of one
must satisfy: one stop at constant factors is the plain run; a dwell wears nothing; the stops of a block are one
problem; with the trapezoidal rule each stop's worn volume is κ/μ times the energy it dissipates (Archard against
the friction power, the same rule on the same rows); ``wear.limit`` ends a run as worn out where the remaining
thickness reaches it; jumps keep the worn volume and the remaining thickness of stop by stop.
"""
import json
import logging
import threading

import numpy as np
import pandas as pd
import pytest
from conftest import PAPER

import ngwear
from ngwear.model.programme import Schedule
from ngwear.model.scene_mesh import build_mesh
from ngwear.numerics.recession import contact_height
from ngwear.results.history_csv import bare
from ngwear.results.metrics import disc_taper, plane_slope, taper_along
from ngwear.runs.checks import WORN_OUT


def strip(programme, **keys):
    """The paper's strip (coarse) running ``programme`` instead of its interval."""
    data = ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.2, **keys}).to_dict()
    data.pop("time")
    data["output"].pop("every")
    return ngwear.Scene.from_dict({**data, "programme": programme})


def pressed(programme, **keys):
    """The strip held by a tilting plate on its top alone (no clamp): it wears in towards a periodic state."""
    return strip(programme, **{"geometry.dirichlet": [], "loads.traction": {}, "contact.friction": 0.3,
                               "contact.wear": 0.01,
                               "loads.plate": {"boundary": "top", "force": [0.0, -0.3], "tilt": True}, **keys})


BLOCKS = [{"count": 3, "duration": 0.2, "speed": [1.0, 0.0], "dwell": 0.1},
          {"count": 2, "duration": 0.1, "load": [0.5, 1.5]}]


@pytest.fixture(scope="module")
def blocks():
    return ngwear.simulate(strip({"stops": BLOCKS, "steps_per_stop": 4}, **{"wear.integrator": "trapezoidal"}),
                           progress=False)


def test_one_stop_at_constant_factors_is_the_plain_run():
    programme = strip({"stops": [{"duration": 0.5}], "steps_per_stop": 10})
    plain = ngwear.simulate(ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.2, "time.T": 0.5, "time.steps": 10}),
                            progress=False)
    run = ngwear.simulate(programme, progress=False)
    assert run.completed and run.steps == plain.steps == 10
    assert np.allclose(run.times, plain.times, rtol=0, atol=1e-15)
    for name in ("wear", "pressure", "normal_displacement"):
        assert np.abs(getattr(run, name) - getattr(plain, name)).max() <= 1e-12 * np.abs(getattr(plain, name)).max()
    stops = run.stops
    assert len(stops) == 1 and bool(stops["simulated"].iloc[0])
    assert stops["worn_volume"].iloc[0] == pytest.approx(plain.wear_volume[-1], rel=1e-12)


def test_stops_and_dwells(blocks):
    r, s = blocks, Schedule.of(blocks.scene.programme)
    m = 4
    assert r.completed and r.steps + 1 == 5 * (m + 1)
    for i in range(1, 5):                                  # the crossing to stop i wears nothing; its start is loaded
        start = i * (m + 1)
        assert r.times[start] == s.start[i]
        assert np.array_equal(r.wear[start], r.wear[start - 1])
        assert r.normal_force[start] > 0
    assert r.normal_force[m] > 0.5 * r.normal_force[0]                       # a stop to rest ends loaded
    assert r.friction_force[m] == 0 and r.torque[m] == 0                     # and at rest: no friction
    for i in range(4):
        assert np.array_equal(np.diff(r.times[i * (m + 1):(i + 1) * (m + 1)]) > 0, np.ones(m, bool))
    # the second block's load ramps 0.5 → 1.5: the clamped strip's normal force follows s_F (within the layer)
    second = r.normal_force[3 * (m + 1):4 * (m + 1)]
    assert np.all(np.diff(second) > 0) and second[-1] / second[0] == pytest.approx(3.0, rel=0.1)


def test_stop_table_is_archard_against_the_friction_power(blocks):
    """Trapezoidal rule: Δw_i = ∫ κ ‖v*_i‖ p_i dt on the rows, so Σ m Δw = κ/μ ∫ P dt to round-off."""
    r, stops = blocks, blocks.stops
    scene = r.scene
    assert list(stops.index) == [0, 1, 2, 3, 4] and list(stops["block"]) == [0, 0, 0, 1, 1]
    assert stops["simulated"].all()
    ratio = scene.contact.wear / scene.contact.friction
    assert np.allclose(stops["worn_volume"], ratio * stops["energy"], rtol=1e-10, atol=0)
    assert stops["worn_volume"].sum() == pytest.approx(r.wear_volume[-1], rel=1e-12)
    assert stops["max_total_wear"].iloc[-1] == r.total_wear[-1].max()
    assert stops["min_remaining_thickness"].iloc[-1] == pytest.approx(1.0 - r.wear[-1].max(), rel=1e-12)
    assert (stops["apparent_friction"] <= scene.contact.friction + 1e-12).all()
    assert not any("temperature" in c for c in stops.columns)                 # no heat: no temperature columns


def test_cli_writes_stops_csv(tmp_path):
    from ngwear.cli import main
    scene = tmp_path / "life.toml"
    text = PAPER.read_text().split("[time]")[0].replace("maxh = 0.05", "maxh = 0.2")
    scene.write_text(text + '[programme]\nstops = [{ count = 2, duration = 0.2, speed = [1.0, 0.0], dwell = 0.1 }]\n'
                            'steps_per_stop = 4\n[material.regions]\n'.replace("[material.regions]\n", "")
                     + "\n[wear]\nintegrator = \"trapezoidal\"\n")
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet", "--no-pictures", "--no-check"]) == 0
    table = pd.read_csv(tmp_path / "out" / "stops.csv", index_col="stop")
    saved = ngwear.load_result(tmp_path / "out")
    assert np.allclose(table["energy"], saved.stops["energy"], rtol=1e-12) and len(table) == 2


def test_the_stops_tapers_and_the_summary_are_the_metrics_of_the_remaining_thickness(blocks):
    """Each stop's taper is the fit of its remaining thickness; the summary's blocks are Archard's κ/μ per MJ."""
    r, stops, summary = blocks, blocks.stops, blocks.summary()
    velocity, m = r.scene.foundation.velocity, r.scene.programme.steps_per_stop
    ends = np.flatnonzero(Schedule.of(r.scene.programme).rows(r.jumped)[1][:r.steps + 1] == m)
    assert "taper_radial" not in stops and len(ends) == len(stops) == 5          # a translating counterface
    for stop, end in zip(stops.index, ends, strict=True):
        remaining = r.remaining_thickness[end]
        assert stops.loc[stop, "taper_along"] == taper_along(r.contact_points, remaining, r.weights, velocity)
        slope = plane_slope(r.contact_points, remaining, r.weights, [0.0, 1.0])
        assert stops.loc[stop, "taper_slope"] == pytest.approx(abs(slope[0]), rel=1e-12)
    assert stops["taper_along"].abs().max() > 1e-3, "the strip's wear is not uniform: a taper to see"
    assert summary["taper_along"] == stops["taper_along"].iloc[-1] and "stops_to_limit" not in summary
    assert [b["stops"] for b in summary["blocks"]] == [3, 2]
    ratio = 1e6 * r.scene.contact.wear / r.scene.contact.friction
    assert [b["volume_per_megajoule"] for b in summary["blocks"]] == pytest.approx([ratio, ratio], rel=1e-10)
    assert summary["blocks"][1]["volume_per_stop"] == pytest.approx(stops["worn_volume"].iloc[3:].mean(), rel=1e-12)


def test_the_shipped_life_reports_its_tapers_its_blocks_and_the_stops_left(tmp_path, capsys):
    """The shipped pad (``wear.limit`` 2 mm): its stops' tapers, its blocks and the stops left to the limit.

    A jumped stop's taper goes on linearly from its simulated one's; the summary projects the stops to the limit at
    the last simulated stop's wear; ``life.png`` is drawn.
    """
    from ngwear.cli import main
    out = tmp_path / "out"
    assert main(["run", "brake_pad_life", "--out", str(out), "--quiet", "--no-check"]) == 0
    printed = capsys.readouterr().out
    assert "block 2" in printed and "per MJ" in printed and (out / "life.png").stat().st_size > 10_000
    stops = pd.read_csv(out / "stops.csv", index_col="stop").rename(columns=bare)
    summary = json.loads((out / "summary.json").read_text())
    for column in ("taper_radial", "taper_circumferential", "taper_slope"):
        assert np.isfinite(stops[column]).all() and column in summary
    assert summary["taper_radial"] == pytest.approx(stops["taper_radial"].iloc[-1], rel=1e-9)
    saved = ngwear.load_result(out)
    scene, m = saved.scene, saved.scene.programme.steps_per_stop
    stop_of, step_of = (a[:saved.steps + 1] for a in Schedule.of(scene.programme).rows(saved.jumped))
    ends = np.flatnonzero(step_of == m)
    jumped = np.flatnonzero(~stops["simulated"].to_numpy())
    longest = max(np.split(jumped, np.flatnonzero(np.diff(jumped) > 1) + 1), key=len)
    end = ends[stop_of[ends] == longest[0] - 1][0]                          # the simulated stop before them
    increment = saved.total_wear[end] - saved.total_wear[end - m]
    for k, stop in enumerate(longest, start=1):
        left = saved.remaining_thickness[end] - k * increment
        expected = disc_taper(saved.contact_points, left, saved.weights, [0, 0, 0], scene.foundation.angular_velocity)
        assert stops.loc[stop, "taper_radial"] == pytest.approx(expected[0], rel=1e-9)
    assert len(longest) > 10 and stops.loc[longest[-1], "taper_radial"] != stops.loc[longest[0], "taper_radial"]
    remaining, limit = saved.remaining_thickness[-1], scene.wear.limit
    end = ends[-1]
    per_stop = saved.total_wear[end] - saved.total_wear[end - m]
    assert summary["stops_to_limit"] == pytest.approx(np.min((remaining - limit) / per_stop), rel=1e-12)
    assert summary["stops_to_limit"] > 100, "half of 12 mm worn, 2 mm the limit: hundreds of stops left"


def test_wear_limit_ends_the_run_as_worn_out(capsys):
    limit = 0.97
    scene = strip({"stops": BLOCKS, "steps_per_stop": 4}, **{"wear.limit": limit})
    r = ngwear.simulate(scene, progress=False)
    assert r.status == WORN_OUT and not r.completed
    remaining = r.remaining_thickness.min(axis=1)
    assert remaining[-1] <= limit < remaining[-2], "it stops at the first step that reaches the limit"
    assert "wear.limit" in r.warnings[-1] and f"t = {r.times[-1]:.6g}" in r.warnings[-1]
    assert np.array_equal(r.total_wear, r.wear) and np.allclose(r.remaining_thickness, r.thickness - r.wear)


def test_a_jump_ends_before_wear_limit():
    """The shipped life to 9.5 mm of friction material left: worn out at the step that reaches it, within a stop's wear.

    A jump is bounded by the limit (and the next update): it reached it 48 µm deep, 16 stops late, when it was not.
    """
    limit = 0.0095
    r = ngwear.simulate(ngwear.load_scene("brake_pad_life").replace(**{"wear.limit": limit}), progress=False)
    remaining = r.remaining_thickness.min(axis=1)
    assert r.status == WORN_OUT and remaining[-1] <= limit < remaining[-2] and len(r.jumped) > 100
    per_stop = (remaining[0] - remaining[-1]) / len(r.stops)
    assert limit - remaining[-1] < 0.2 * per_stop


def test_an_invariant_broken_by_a_jump_says_so(monkeypatch):
    """Jumps without their bounds (as before they had them): the layer worn through at a crossing, said as a jump's."""
    from ngwear.runs import jumps

    monkeypatch.setattr(jumps, "room", lambda increment, left: np.inf)
    r = ngwear.simulate(ngwear.load_scene("brake_pad_life").replace(**{"wear.update": 0.5}), progress=False)
    assert r.status.startswith("step ") and "invariant wear_le_penetration broken" in r.status
    assert "a cycle jump of" in r.status and "programme.jump_tolerance" in r.status and "implicit" not in r.status


def test_a_programme_resumes_to_the_bit(tmp_path):
    scene = strip({"stops": BLOCKS, "steps_per_stop": 4})
    whole = ngwear.simulate(scene, progress=False)
    calls = []

    class Stopper:                      # set the stop event after 7 rows (in the middle of stop 1)
        def is_set(self):
            calls.append(1)
            return len(calls) > 7

    first = ngwear.simulate(scene, progress=False, checkpoint=tmp_path, stop=Stopper())
    assert first.status == "interrupted" and 0 < first.steps < whole.steps
    resumed = ngwear.simulate(None, progress=False, resume=tmp_path)
    assert resumed.completed, resumed.status
    for name in ("times", "wear", "pressure", "normal_displacement"):
        assert np.array_equal(getattr(resumed, name), getattr(whole, name)), name


@pytest.mark.slow
def test_jumps_keep_stop_by_stop():
    """200 identical stops to rest under a tilting plate: jumps within 1 % (volume) and 2 % (thickness), far fewer."""
    programme = {"stops": [{"count": 200, "duration": 1.0, "speed": [1.0, 0.0], "dwell": 0.5}], "steps_per_stop": 5}
    scene = pressed(programme, **{"wear.integrator": "trapezoidal"})
    each = ngwear.simulate(scene, progress=False)
    jumping = ngwear.simulate(scene.replace(**{"programme.jump": True}), progress=False)
    assert each.completed and jumping.completed
    stops = jumping.stops
    simulated = int(stops["simulated"].sum())
    assert len(stops) == 200 and simulated < 100
    assert each.wear.max() > 0.3 * scene.contact.gap, "worn well into the layer"
    a, b = each.stops.iloc[-1], stops.iloc[-1]
    assert b["max_total_wear"] == pytest.approx(a["max_total_wear"], rel=0.02)
    assert stops["worn_volume"].sum() == pytest.approx(each.stops["worn_volume"].sum(), rel=0.01)
    assert b["min_remaining_thickness"] == pytest.approx(a["min_remaining_thickness"], rel=0.02)


def taper_scene(geometry="surface", gap=0.05, T=12.0, steps=120):
    """A 1 × 0.25 pad per unit width, μ = 0.3, under a tilting plate on its top (h = 0.25), τ = 1/(κ‖v*‖L) = 1."""
    return ngwear.Scene.from_dict({
        "name": "taper", "geometry": {"kind": "strip", "size": [1.0, 0.25], "dirichlet": []},
        "mesh": {"maxh": 0.05}, "material": {"young": 100.0, "poisson": 0.3},
        "contact": {"stiffness": 10.0, "gap": gap, "friction": 0.3, "wear": 0.1},
        "foundation": {"velocity": [1.0, 0.0]},
        "loads": {"plate": {"boundary": "top", "force": [0.0, -0.1], "tilt": True}},
        "time": {"T": T, "steps": steps}, "wear": {"integrator": "trapezoidal", "geometry": geometry},
        "output": {"every": T}})


@pytest.fixture(scope="module")
def surface():
    return ngwear.simulate(taper_scene(), progress=False)


def test_surface_is_the_layer_until_the_first_update(surface):
    layer = ngwear.simulate(taper_scene("layer"), progress=False)
    first = surface.removed_rows[0]
    assert surface.geometry_updates >= 5 and 0 < first < surface.steps
    for name in ("wear", "pressure", "normal_displacement", "plate_displacement"):
        assert np.array_equal(getattr(surface, name)[:first], getattr(layer, name)[:first]), name
    assert layer.wear.max() == pytest.approx(0.05, rel=1e-3), "the layer mode stops wearing at g"
    assert surface.total_wear[-1].max() > 2 * 0.05, "the surface mode wears on, far beyond the layer"


def test_surface_updates_keep_the_force_balance_and_the_wear(surface):
    r = surface
    assert r.completed
    assert np.abs(r.normal_force - 0.1).max() < 1e-12, "Σ m (p + λ) = F at every step, the updates' weights"
    total = r.total_wear
    assert (np.diff(total, axis=0) >= -1e-15).all() and (r.wear >= 0).all(), "w ≥ 0; the total never decreases"
    threshold = 0.25 * 0.05
    assert r.wear.max() < 2 * threshold, "each update moves the wear once it passes wear.update × h"
    assert np.allclose(r.remaining_thickness[-1], 0.25 - total[-1], atol=1e-12)
    assert r.penetration.max() <= 0.05 and r.summary()["max_penetration"] <= 0.05, "u_ν − d₀ ≤ g of the moved face"
    assert np.abs(r.compression[-1] - r.pressure[-1] / 10.0).max() < 1e-12, "p = L (u_ν − d₀ − w) on the moved face"
    assert r.summary()["geometry_updates"] == r.geometry_updates


def test_surface_keeps_the_taper_as_the_pad_shrinks(surface):
    """Worn in beyond the layer, p = F/A + s ξ with the friction couple's balance on the worn face.

    Σ m p (x − x_c) = −μ Σ m p h(x): the friction acts along the worn face, at the height h(x) = h − W(x) below the
    plate, W = W̄ + t ξ the worn face (t its taper).  With p = F/A + s ξ this is s I = μ F (h − W̄) − μ s t I, so

        s = μ F (h − W̄) / (I (1 + μ t)),

    the closed form's μ F h / I (:mod:`ngwear.studies.closed_forms`) with h shrinking with the mean wear and the face's
    inclination (here 2.5 %).
    """
    r = surface
    a, force, mu = 1.0, 0.1, 0.3
    xi = a / 2 - r.contact_points[:, 0]
    m = r.row_weights[-1]
    design = np.column_stack([np.ones_like(xi), xi]) * np.sqrt(m)[:, None]
    fit = lambda values: np.linalg.lstsq(design, values * np.sqrt(m), rcond=None)[0]   # noqa: E731
    (_, slope), (_, taper) = fit(r.pressure[-1]), fit(r.total_wear[-1])
    assert m @ r.pressure[-1] / m.sum() == pytest.approx(force / m.sum(), rel=1e-9)
    assert taper > 0.05, "a tapered face: the leading edge wears more"
    height = 0.25 - m @ r.total_wear[-1] / m.sum()
    assert height < 0.25 - 2 * 0.05
    assert slope == pytest.approx(mu * force * height / (a ** 3 / 12) / (1 + mu * taper), rel=0.01)


def test_cli_worn_out_exits_0_and_says_where(tmp_path, capsys):
    from ngwear.cli import main
    code = main(["run", str(PAPER), "--out", str(tmp_path / "out"), "--quiet", "--no-pictures", "--no-check",
                 "--set", "mesh.maxh=0.2", "--set", "time.steps=20", "--set", "wear.limit=0.99"])
    err = capsys.readouterr().err
    assert code == 0 and "ngwear: worn out: wear.limit: the remaining thickness reached 0.99" in err
    saved = ngwear.load_result(tmp_path / "out")
    assert saved.status == WORN_OUT and saved.remaining_thickness[-1].min() <= 0.99 < saved.remaining_thickness[-2].min()


def interrupted(scene, folder, rows, monkeypatch):
    """``scene`` run into ``folder`` (a checkpoint), its stop event set once it recorded ``rows`` rows (as a signal)."""
    from ngwear.results.recording import Recording

    stop, append = threading.Event(), Recording.append

    def counting(recording, *step):
        append(recording, *step)
        if len(recording.result.times) == rows:
            stop.set()

    with monkeypatch.context() as patched:
        patched.setattr(Recording, "append", counting)
        return ngwear.simulate(scene, progress=False, checkpoint=folder, stop=stop)


SURFACE_ROWS = ("times", "wear", "total_wear", "remaining_thickness", "pressure", "normal_displacement",
                "plate_displacement", "removed_rows", "row_weights")


HEATED = {"material.conductivity": 0.01, "material.density": 1.0, "material.heat_capacity": 1.0,
          "heat.model": "conduction", "heat.partition": 1.0, "contact.friction": "0.3 - 0.1 * T"}


@pytest.mark.parametrize("rows, heat", [(15, {}), (18, {**HEATED, "material.expansion": 0.01})])
def test_a_surface_run_resumes_across_its_updates_to_the_bit(tmp_path, monkeypatch, rows, heat):
    """Stopped after two of four updates (15: on the update's step; 18: heated, μ(T), expansion): the same arrays."""
    scene = taper_scene(T=3.0, steps=30).replace(**{"output.every": 0.5, **heat})
    whole = ngwear.simulate(scene, progress=False)
    first = interrupted(scene, tmp_path, rows, monkeypatch)
    assert first.status == "interrupted" and first.geometry_updates == 2 < whole.geometry_updates
    resumed = ngwear.simulate(None, progress=False, resume=tmp_path)
    assert resumed.completed and resumed.geometry_updates == whole.geometry_updates == 4
    for name in SURFACE_ROWS + (("surface_temperature", "step_friction", "heat_flux") if heat else ()):
        assert np.array_equal(getattr(resumed, name), getattr(whole, name)), name
    for step in whole.stored_steps:                 # the frames: their worn body, displacement and temperature
        assert np.array_equal(resumed.body_coordinates(step), whole.body_coordinates(step)), step
        assert np.array_equal(resumed.displacement(step), whole.displacement(step)), step
        assert not heat or np.array_equal(resumed.temperatures[step], whole.temperatures[step]), step


def test_a_matrix_free_surface_run_resumes_across_its_updates_to_the_bit(tmp_path, monkeypatch):
    """K factorised without the Schur complement: each update, and the resumed run, take the first K's ordering."""
    monkeypatch.setattr("ngwear.numerics.discrete.DENSE_LIMIT", 0)
    scene = taper_scene(T=3.0, steps=30).replace(**{"output.every": 0.5})
    whole = ngwear.simulate(scene, progress=False)
    first = interrupted(scene, tmp_path, 15, monkeypatch)
    with np.load(tmp_path / "checkpoint.npz") as saved:
        ordering = saved["surface_ordering"]
    assert first.geometry_updates == 2 and np.array_equal(ordering, first.discretization.elastic.operator.ordering)
    resumed = ngwear.simulate(None, progress=False, resume=tmp_path)
    assert resumed.completed and resumed.geometry_updates == whole.geometry_updates == 4
    assert np.array_equal(resumed.discretization.elastic.operator.ordering, ordering)
    for name in SURFACE_ROWS:
        assert np.array_equal(getattr(resumed, name), getattr(whole, name)), name
    with np.load(tmp_path / "checkpoint.npz") as saved:
        arrays = dict(saved)
    np.savez(tmp_path / "checkpoint.npz", **{**arrays, "surface_ordering": np.zeros_like(arrays["surface_ordering"])})
    with pytest.raises(ngwear.SceneError, match=r"checkpoint.npz is damaged \(its surface_ordering is not an ordering "
                                                r"of the \d+ free DOFs\)"):
        ngwear.simulate(None, progress=False, resume=tmp_path)


def test_a_surface_programme_with_jumps_resumes_to_the_bit(tmp_path, monkeypatch):
    """Jumps bounded by the next update, stopped after the second update: the same stops, jumps and rows."""
    data = taper_scene().to_dict()
    data.pop("time")
    data["output"].pop("every")
    programme = {"stops": [{"count": 60, "duration": 0.2, "speed": [1.0, 0.0], "dwell": 0.1}], "steps_per_stop": 4,
                 "jump": True, "jump_tolerance": 1e-2}
    scene = ngwear.Scene.from_dict({**data, "programme": programme})
    whole = ngwear.simulate(scene, progress=False)
    threshold = scene.wear.update * min(contact_height(build_mesh(scene)), scene.contact.gap)
    assert whole.removed.max() < 1.1 * threshold, "a jump ends before the update: each moves one threshold's wear"
    first = interrupted(scene, tmp_path, 20, monkeypatch)
    assert first.geometry_updates == 2 < whole.geometry_updates and 0 < len(first.jumped) < len(whole.jumped)
    resumed = ngwear.simulate(None, progress=False, resume=tmp_path)
    assert resumed.completed and np.array_equal(resumed.jumped, whole.jumped)
    for name in SURFACE_ROWS:
        assert np.array_equal(getattr(resumed, name), getattr(whole, name)), name


def test_a_heated_surface_run_keeps_its_energy_balance_across_updates(monkeypatch):
    """μ(T) and an adiabatic body across 4 updates: ∫ρc(T − T₀) = Σ Δt η Q − (the heat the worn material took).

    The temperature is carried node by node (``Heat.moved``): the body's capacity c = M 1 shrinks with the worn
    volume ΔV, and the heat (c − c')·(T − T₀) leaves with it, at most ρc ΔV max(T − T₀); the balance with it closes
    to round-off at every step, and μ is read from the last step's temperature on the moved body as on the first.
    """
    from test_heat_coupled import balances

    seen = balances(monkeypatch)
    scene = taper_scene(T=3.0, steps=30).replace(**HEATED)
    r = ngwear.simulate(scene, progress=False)
    assert r.completed and r.geometry_updates == 4
    assert np.array_equal(r.step_friction[1:], 0.3 - 0.1 * r.surface_temperature[:-1]), "μ_{j+1} = μ(T_j)"
    supplied = np.cumsum(np.diff(r.times) * r.heat_flux[1:])
    assert [b.supplied for b in seen] == pytest.approx(supplied, rel=1e-13)
    assert max(abs(b.residual) / b.supplied for b in seen) < 1e-12 and all(b.convected == 0 for b in seen)
    removed = np.array([b.removed for b in seen])             # after steps 1 … N
    assert np.array_equal(np.flatnonzero(np.diff(removed, prepend=0.0)) + 1, r.removed_rows + 1), "at the updates"
    lost = np.diff(removed[r.removed_rows], prepend=0.0)
    worn = np.einsum("ki,ki->k", r.removed, r.row_weights[r.removed_rows])    # ΔV = Σ m W of each update
    assert np.all(lost > 0) and np.all(lost <= worn * r.max_temperature[r.removed_rows])
    assert 0.02 < removed[-1] / supplied[-1] < 0.2


def test_a_programme_with_jumps_resumes_to_the_bit(tmp_path):
    programme = {"stops": [{"count": 60, "duration": 1.0, "speed": [1.0, 0.0], "dwell": 0.5}], "steps_per_stop": 4,
                 "jump": True, "jump_tolerance": 1e-2}
    scene = pressed(programme, **{"wear.integrator": "trapezoidal", "contact.wear": 0.005})
    whole = ngwear.simulate(scene, progress=False)
    calls = []

    class Stopper:                      # stops the run after some of its jumps
        def is_set(self):
            calls.append(1)
            return len(calls) > 150

    first = ngwear.simulate(scene, progress=False, checkpoint=tmp_path, stop=Stopper())
    assert first.status == "interrupted" and 0 < len(first.jumped) < len(whole.jumped)
    resumed = ngwear.simulate(None, progress=False, resume=tmp_path)
    assert resumed.completed and np.array_equal(resumed.jumped, whole.jumped)
    for name in ("times", "wear", "pressure", "plate_displacement"):
        assert np.array_equal(getattr(resumed, name), getattr(whole, name)), name


@pytest.mark.hostile
def test_the_progress_of_a_programme_counts_its_stops_jumped_or_not(caplog):
    """A programme's progress counts stops, the jumped ones among them, up to the programme's count and no further."""
    programme = {"stops": [{"count": 200, "duration": 1.0, "speed": [1.0, 0.0], "dwell": 0.5}], "steps_per_stop": 5,
                 "jump": True}
    with caplog.at_level(logging.INFO, logger="ngwear.progress"):
        run = ngwear.simulate(pressed(programme, **{"wear.integrator": "trapezoidal"}), progress=True)
    counts = [tuple(map(int, m.split(": ")[1].split(" stops")[0].replace(",", "").split(" of ")))
              for m in caplog.messages if " stops [" in m]
    assert run.completed and len(run.jumped) > 0
    assert counts[-1] == (200, 200) and all(n <= total == 200 for n, total in counts)
    assert [n for n, _ in counts] == sorted(n for n, _ in counts)
