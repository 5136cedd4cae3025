"""What an engineer reads off a run: friction force and apparent friction, torque, units, wall and solve time."""
import json

import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.results import units
from ngwear.views import part_plots, plots

SHIPPED = ROOT / "geometries"


def test_friction_force_is_mu_times_normal_force_where_every_point_slides(paper_result):
    """The strip on a translating foundation: F_t = −μ N e_x while no point is held at the bound (λ = 0)."""
    r, mu = paper_result, paper_result.scene.contact.friction
    free = np.all(r.reaction == 0, axis=1) & (r.normal_force > 0)
    assert free.sum() >= 10 and not free.all()                     # later steps hold points at u_ν − d₀ = g
    assert np.abs(r.apparent_friction[free] - mu).max() < 1e-10
    assert np.allclose(r.tangential_force[free], np.outer(-mu * r.normal_force[free], [1.0, 0.0]), rtol=1e-10,
                       atol=0)
    assert np.all(r.apparent_friction[~free] < mu) and np.all(r.apparent_friction > 0)   # λ carries no friction
    assert np.allclose(r.friction_force, mu * (r.pressure @ r.weights), rtol=1e-12)
    assert np.all(r.torque == 0)                                   # no rotation: no moment about an axis


def test_torque_is_the_moment_of_the_friction_forces():
    """A pad on a turning disc: T = Σ ((x_i − c) × f_i)·e and F_t = Σ f_i, f_i = μ m_i p_i n*_i computed here."""
    scene = ngwear.load_scene("brake_pad").replace(**{"mesh.maxh": 0.012, "time.steps": 10})
    r = ngwear.simulate(scene, progress=False)
    omega, nu, mu = np.array(scene.foundation.angular_velocity), np.array(scene.contact.direction), 0.4
    arms = r.contact_points - 0.0                                   # c = origin
    v = np.cross(omega, arms)
    v_tangential = v - np.outer(v @ nu, nu)
    n_star = -v_tangential / np.linalg.norm(v_tangential, axis=1)[:, None]
    forces = mu * (r.pressure * r.weights)[:, :, None] * n_star[None]          # (steps, points, 3)
    moment = np.cross(arms[None], forces) @ (omega / np.linalg.norm(omega))
    assert np.allclose(r.torque, moment.sum(axis=1), rtol=1e-12)
    assert np.allclose(r.tangential_force, forces.sum(axis=1), rtol=1e-12, atol=1e-12 * r.normal_force.max())
    assert np.all(r.torque < 0) and np.all(r.apparent_friction < mu)     # forces of different directions
    assert np.allclose(r.apparent_friction, np.linalg.norm(forces.sum(axis=1), axis=1) / r.normal_force, rtol=1e-12)


def test_apparent_friction_is_zero_without_normal_force():
    """Loads ramped from 0: at t = 0 nothing presses, and the apparent friction is 0, not NaN."""
    scene = ngwear.load_scene("paper_strip").replace(**{"mesh.maxh": 0.25, "time.steps": 4, "wear.integrator": "implicit",
                                                       "loads.time_table": [[0.0, 0.0], [1.0, 1.0]]})
    r = ngwear.simulate(scene, progress=False)
    assert r.normal_force[0] == 0 and r.apparent_friction[0] == 0 and np.all(np.isfinite(r.apparent_friction))
    assert r.apparent_friction[-1] > 0


@pytest.mark.parametrize("name, si", [("paper_strip", False), ("brake_pad", True)])
def test_units_in_the_files_of_si_scenes_only(name, si, tmp_path):
    scene = ngwear.load_scene(name).replace(**{"mesh.maxh": 0.25 if name == "paper_strip" else 0.012,
                                               "time.steps": 3, "wear.integrator": "implicit"})
    assert (scene.units == "SI") is si
    r = ngwear.simulate(scene, progress=False)
    r.save(tmp_path)
    summary = json.loads((tmp_path / "summary.json").read_text(encoding="utf-8"))
    with np.load(tmp_path / "result.npz") as data:
        assert ("units" in data) is si and ("units" in summary) is si
        assert data["friction_force"] == pytest.approx(r.friction_force, rel=1e-14)
        assert data["tangential_force"].shape == (4, scene.dim)
        if si:
            written = json.loads(str(data["units"]))
            assert {k: written[k] for k in ("times", "pressure", "normal_force", "torque", "wear_volume",
                                            "contact_area", "tangential_force", "weights")} == {
                "times": "s", "pressure": "Pa", "normal_force": "N", "torque": "N·m", "wear_volume": "m³",
                "contact_area": "m²", "tangential_force": "N", "weights": "m²"}
            assert set(written) <= set(data.keys())
            assert all(summary["units"][key] == written[key] for key in set(summary["units"]) & set(written))
            assert summary["units"]["max_wear"] == summary["units"]["gap"] == "m"
            assert set(summary["units"]) <= set(summary) and "apparent_friction" not in summary["units"]
    assert 0 < summary["solve_time_s"] <= summary["wall_time_s"]
    assert ngwear.load_result(tmp_path).solve_time == pytest.approx(r.solve_time)


def test_units_of_a_plane_strain_scene_are_per_unit_thickness():
    scene = ngwear.load_scene("paper_strip").replace(units="SI")
    written = units.units(scene)
    assert (written["normal_force"], written["torque"], written["contact_area"], written["wear_volume"]) == (
        "N/m", "N·m/m", "m", "m²")
    assert units.label(scene, "wear w", "length") == "wear w (m)"
    assert units.label(ngwear.load_scene("paper_strip"), "wear w", "length") == "wear w"


def test_history_shows_friction_force_or_torque_with_units(paper_result, monkeypatch, tmp_path):
    """A translating foundation gets the friction force panel; a turning one the torque; SI labels carry units."""
    drawn = []
    monkeypatch.setattr(part_plots, "_save", lambda fig, path: drawn.append(fig))
    part_plots.history(paper_result, tmp_path / "h.png")
    pad = ngwear.simulate(ngwear.load_scene("brake_pad").replace(**{"mesh.maxh": 0.012, "time.steps": 10}),
                          progress=False)
    part_plots.history(pad, tmp_path / "p.png")
    strip, disc = ([ax.get_title() for ax in fig.axes] for fig in drawn)
    assert strip[:2] == ["normal force Σ m (p + λ)", "friction force |F_t| = |Σ m μ p n*|"]   # no units
    assert disc[:3] == ["normal force Σ m (p + λ) (N)", "friction torque T (< 0: braking) (N·m)",
                        "worn volume Σ m w (m³)"]
    assert drawn[1].axes[0].get_xlabel() == "time t (s)"
    force = drawn[1].axes[0]                               # 3000 N held by the plate, equal up to round-off
    force.figure.canvas.draw()
    assert force.yaxis.get_major_formatter().get_offset() == ""
    low, high = force.get_ylim()
    assert low < 3000 < high and high - low == pytest.approx(300)


def test_a_constant_shows_as_itself_without_offset():
    from matplotlib.figure import Figure
    ax = Figure().subplots()
    values = 10.0 + np.array([0.0, 1e-10, -2e-10, 0.5e-10])
    ax.plot(values)
    plots.plain(ax, values)
    ax.figure.canvas.draw()
    labels = [t.get_text() for t in ax.get_yticklabels()]
    assert ax.yaxis.get_major_formatter().get_offset() == "" and ax.get_ylim() == pytest.approx((9.5, 10.5))
    assert "10.0" in labels or "10.00" in labels or "10" in labels, labels
