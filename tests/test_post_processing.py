"""What a run writes for post-processing: stress and contact fields, history.csv, the run's summary, provenance."""
import contextlib
import hashlib
import io
import json
import math
import platform
import re

import ngsolve as ngs
import numpy as np
import pandas as pd
import pytest
import pyvista as pv
from netgen.csg import unit_cube
from netgen.geom2d import unit_square

import ngwear
from ngwear.cli import main
from ngwear.model.materials import Compaction, Energy, Isotropic, TransverselyIsotropic, strain
from ngwear.results.bulk_stress import BulkStress, full_tensor, von_mises
from ngwear.results.history_csv import bare
from ngwear.results.provenance import COLUMNS
from ngwear.results.result import load_result
from ngwear.studies.sweep import simulate_case

OMEGA, STOP, DENSITY = 50.0, 4.0, 2500.0    # the pad's disc: rad/s, s to rest; the friction material's ρ


@pytest.fixture(scope="module")
def stop(tmp_path_factory):
    """The shipped pad braking to rest in 4 s (ω: 50 → 0 rad/s), through the CLI: (result, folder, printed text)."""
    out = tmp_path_factory.mktemp("stop")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert main(["run", "geometries/brake_pad.toml", "--out", str(out), "--no-pictures", "--no-check", "-q",
                     "--set", "time.T=4.0", "time.steps=8", "output.every=2.0", f"material.density={DENSITY}",
                     f"foundation.speed_table=[[0, 1], [{STOP}, 0]]"]) == 0
    return load_result(out), out, printed.getvalue()


def speed_factor(t):
    return np.interp(t, [0.0, STOP], [1.0, 0.0])


# ---------------------------------------------------------------- VTU: the bulk


def test_frame_holds_the_stress_tensor_and_its_von_mises_value(stop):
    result, out, _ = stop
    assert [line for line in (out / "fields.pvd").read_text().splitlines() if "DataSet" in line] == [
        f'<DataSet timestep="{float(result.times[s])!r}" part="{part}" file="{kind}_step{s:03d}.vtu"/>'
        for s in result.stored_steps for part, kind in ((0, "fields"), (1, "contact"))]
    grid = pv.read(out / "fields_step004.vtu")
    assert set(grid.point_data) == {"displacement", "wear", "stress", "von_mises"} and "region" in grid.cell_data
    sigma = grid.point_data["stress"].reshape(-1, 3, 3)
    assert sigma.shape == (grid.n_points, 3, 3) and np.allclose(sigma, sigma.transpose(0, 2, 1), rtol=0, atol=1e-6)
    deviator = sigma - np.trace(sigma, axis1=1, axis2=2)[:, None, None] / 3 * np.eye(3)
    assert np.allclose(grid.point_data["von_mises"], np.sqrt(1.5 * np.sum(deviator ** 2, axis=(1, 2))), rtol=1e-10)
    # the pad carries 3 kN through its contact face: σ_zz < 0 there, of the order of the mean pressure
    face = grid.points[:, 2] < 1e-9
    assert np.median(sigma[face, 2, 2]) == pytest.approx(-result.mean_pressure[4], rel=0.3)


@pytest.mark.parametrize("dim", [2, 3])
def test_von_mises_of_a_uniaxial_strain_is_two_eta_a(dim):
    """A uniaxial strain gives Hooke's σ_vM = 2η|a|, also for the compaction law and a ψ of Hooke's energy.

    u = a x e₁: ε = a e₁⊗e₁; Hooke σ = diag(λ + 2η, λ, λ) a; compaction in compression adds β a to the diagonal
    (σ_vM unchanged); a ψ of Hooke's energy gives Hooke's σ (3D).
    """
    lam, eta, beta, a = 1.5, 0.7, 4.0, -0.02
    mesh = ngs.Mesh((unit_square if dim == 2 else unit_cube).GenerateMesh(maxh=0.5))
    u = ngs.GridFunction(ngs.VectorH1(mesh, order=1))
    u.Set(ngs.CF((a * ngs.x, *[0] * (dim - 1))))
    at = mesh(*[0.4] * dim)
    hooke = np.diag([lam + 2 * eta, lam, lam]) * a
    laws = [(Isotropic(lam, eta, dim), hooke), (Compaction(lam, eta, beta, dim), hooke + beta * a * np.eye(3))]
    if dim == 3:
        laws.append((Energy(lambda e: eta * ngs.InnerProduct(e, e) + lam / 2 * ngs.Trace(e) ** 2, dim), hooke))
    for law, expected in laws:
        sigma = full_tensor(law, strain(u))
        assert np.allclose(np.reshape(sigma(at), (3, 3)), expected, rtol=1e-12, atol=1e-15), law
        assert von_mises(sigma)(at) == pytest.approx(2 * eta * abs(a), rel=1e-12)


def test_plane_strain_normal_stress_of_a_transversely_isotropic_law():
    """σ₃₃ = C₃₃₁₁ ε₁₁ + C₃₃₂₂ ε₂₂ + C₃₃₁₂ √2 ε₁₂ of the 3D Mandel stiffness whose plane-strain block is the law."""
    law = TransverselyIsotropic(2.0, 1.0, 0.25, 0.12, 0.5, (0.6, -0.8))
    mesh = ngs.Mesh(unit_square.GenerateMesh(maxh=0.5))
    u = ngs.GridFunction(ngs.VectorH1(mesh, order=1))
    e11, e22, e12 = 0.01, -0.03, 0.02
    u.Set(ngs.CF((e11 * ngs.x + e12 * ngs.y, e12 * ngs.x + e22 * ngs.y)))
    sigma = np.reshape(full_tensor(law, strain(u))(mesh(0.3, 0.6)), (3, 3))
    c = law.stiffness_3d
    assert sigma[2, 2] == pytest.approx(c[2, 0] * e11 + c[2, 1] * e22 + c[2, 5] * np.sqrt(2) * e12, rel=1e-12)
    assert sigma[0, 2] == sigma[1, 2] == 0


@pytest.fixture(scope="module")
def backed_p2():
    """A P2 box: compaction body on a Hooke backing, μ linear in x (the vertices' reconstruction is exact)."""
    scene = ngwear.Scene.from_dict({
        "geometry": {"kind": "box", "size": [1.0, 0.5, 0.3], "backing": 0.1}, "mesh": {"maxh": 0.25, "order": 2},
        "material": {"law": "compaction", "lame_lambda": 1.0, "lame_mu": 0.8, "compaction_modulus": 3.0,
                     "regions": {"backing": {"law": "linear", "lame_lambda": 20.0, "lame_mu": 15.0}}},
        "contact": {"friction": "0.2 + 0.1*x", "wear": 0.5, "gap": 0.1, "direction": [0, 0, -1]},
        "foundation": {"velocity": [1, 0, 0]}, "loads": {"traction": {"top": [0.0, 0.0, -0.3]}},
        "time": {"steps": 2}, "wear": {"integrator": "implicit"}})
    return ngwear.simulate(scene, progress=False)


def test_each_region_has_its_own_laws_stress(backed_p2):
    """The same uniaxial strain a e₁⊗e₁ gives σ_vM = 2η|a| with each region's η: 0.8 in the body, 15 in the backing."""
    mesh, a = backed_p2.discretization.mesh, 0.01
    u = ngs.GridFunction(backed_p2.discretization.fes)
    u.Set(ngs.CF((a * ngs.x, 0, 0)))
    stress = BulkStress(backed_p2.scene, mesh, u)
    stress.update()
    body, backing = mesh(0.5, 0.25, 0.05), mesh(0.5, 0.25, 0.35)
    for vm in (von_mises(stress.exact), stress.von_mises):                  # exact, and projected on P1 (exact too)
        assert vm(body) == pytest.approx(2 * 0.8 * a, rel=1e-10) and vm(backing) == pytest.approx(2 * 15 * a, rel=1e-10)


# ---------------------------------------------------------------- VTU: the contact face


def test_contact_file_holds_the_contact_fields_at_the_contact_points(stop):
    result, out, _ = stop
    r = np.hypot(*result.contact_points[:, :2].T)
    for step in result.stored_steps:
        face = pv.read(out / f"contact_step{step:03d}.vtu")
        assert set(face.point_data) == {"displacement", "pressure", "reaction", "wear", "total_wear",
                                        "remaining_thickness", "slip_rate", "friction", "wear_coefficient"}
        assert np.array_equal(face.points, result.contact_points)
        for name in ("pressure", "reaction", "wear"):
            assert np.array_equal(face.point_data[name], getattr(result, name)[step]), name
        assert np.array_equal(face.point_data["friction"], result.friction_coefficient)
        assert np.array_equal(face.point_data["wear_coefficient"], result.wear_coefficient)
        assert np.allclose(face.point_data["slip_rate"], speed_factor(result.times[step]) * OMEGA * r, rtol=1e-12)
        assert np.allclose(face.point_data["displacement"], result.displacement_at(result.contact_points, step),
                           rtol=0, atol=1e-12)
        assert face.compute_cell_sizes()["Area"].sum() == pytest.approx(result.weights.sum(), rel=1e-12)


def test_p2_contact_file_adds_the_vertices_with_linear_values(backed_p2, tmp_path):
    """P2 in 3D: the contact points are the edge midpoints; the facets' vertices follow them, μ = 0.2 + 0.1 x there."""
    backed_p2.save(tmp_path)
    face = pv.read(tmp_path / "contact_step002.vtu")
    n = len(backed_p2.weights)
    assert face.n_points > n and set(face.celltypes) == {pv.CellType.QUADRATIC_TRIANGLE}
    assert np.array_equal(face.points[:n], backed_p2.contact_points)
    assert np.array_equal(face.point_data["pressure"][:n], backed_p2.pressure[2])
    assert np.allclose(face.point_data["friction"], 0.2 + 0.1 * face.points[:, 0], rtol=1e-12)
    assert np.allclose(face.points[n:, 2], 0.0) and face.compute_cell_sizes()["Area"].sum() == pytest.approx(0.5)


# ---------------------------------------------------------------- history.csv


def test_history_csv_is_the_result_table_with_units(stop):
    result, out, _ = stop
    table = pd.read_csv(out / "history.csv")
    assert table.rename(columns=bare).equals(result.to_dataframe())
    assert list(table.columns) == [
        "step", "times [s]", "speed_factor", "load_factor", "normal_force [N]", "torque [N m]", "friction_force [N]",
        "apparent_friction",
        "contact_area [m^2]", "wear_volume [m^3]", "max_wear [m]", "max_pressure [Pa]", "mean_pressure [Pa]",
        "friction_power [W]", "dissipated_energy [J]", "plate_displacement [m]", "tangential_force_x [N]",
        "tangential_force_y [N]", "tangential_force_z [N]", "newton_iterations"]
    assert np.array_equal(table["step"], np.arange(9))
    for column, values in [("times [s]", result.times), ("torque [N m]", result.torque),
                           ("wear_volume [m^3]", result.wear @ result.weights),
                           ("max_pressure [Pa]", result.pressure.max(axis=1)),
                           ("plate_displacement [m]", result.plate_displacement[:, 0]),
                           ("tangential_force_y [N]", result.tangential_force[:, 1]),
                           ("newton_iterations", [r.iterations for r in result.newton])]:
        assert np.array_equal(table[column], values), column


def test_a_dimensionless_history_has_bare_names(backed_p2):
    table = backed_p2.to_dataframe()
    assert "torque" in table and "times" in table and not any("[" in c for c in table.columns)
    assert len(table) == 3 and np.array_equal(table["contact_area"], backed_p2.contact_area)


# ---------------------------------------------------------------- the whole run's summary


def test_a_stop_to_rest_is_summed_over_the_run(stop):
    result, out, printed = stop
    summary = json.loads((out / "summary.json").read_text())
    t = result.times
    # independently: P = s(t) ω Σ m μ p r (‖v*‖ = s ω r on the disc), and T ω
    power = speed_factor(t) * OMEGA * (result.pressure @ (result.friction_coefficient * result.weights
                                                          * np.hypot(*result.contact_points[:, :2].T)))
    assert np.allclose(result.friction_power, power, rtol=1e-12)
    assert np.allclose(np.abs(result.torque) * OMEGA * speed_factor(t), power, rtol=1e-12)
    energy = np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(t))
    assert summary["dissipated_energy"] == pytest.approx(energy, rel=1e-12)
    assert energy == pytest.approx(-summary["torque_peak"] * OMEGA * STOP / 2, rel=0.02)   # ≈ |T| ω t_stop / 2
    assert summary["torque_peak"] == result.torque[np.argmax(np.abs(result.torque))] < 0
    assert summary["torque_mean"] == pytest.approx(np.sum(0.5 * (result.torque[1:] + result.torque[:-1])
                                                          * np.diff(t)) / STOP, rel=1e-12)
    assert summary["pressure_peak"] == result.pressure.max()
    assert summary["wear_mass"] == pytest.approx(DENSITY * (result.wear[-1] @ result.weights), rel=1e-12)
    assert summary["gap_reached_at"] is None and summary["end_time"] == STOP
    assert summary["torque"] == 0.0 and math.copysign(1, summary["torque"]) == 1       # at rest: 0, not −0
    assert summary["units"]["dissipated_energy"] == "J" and summary["units"]["wear_mass"] == "kg"
    lines = printed.splitlines()
    keys = [line.split()[0] for line in lines]
    assert keys.index("torque_peak") < keys.index("last") < keys.index("torque")        # the run first
    assert not re.search(r"(?<![\w.])-0(?![.\d])", printed)                              # never −0
    assert re.search(r"^torque +0 N·m$", printed, re.M) and re.search(r"^gap_reached_at +never$", printed, re.M)


@pytest.fixture(scope="module")
def strip(paper_scene):
    """The paper's strip (2D, P1, Hooke λ = η = 1), coarse."""
    return ngwear.simulate(paper_scene.replace(**{"mesh.maxh": 0.25, "time.steps": 20}), progress=False)


def test_a_2d_frame_has_the_plane_strain_stress_and_a_contact_line(strip, tmp_path):
    """Hooke in plane strain: σ₃₃ = ν (σ₁₁ + σ₂₂), ν = λ / (2(λ + η)) = 1/4; Γ_C as segments of total length Σ m_i."""
    strip.save(tmp_path)
    sigma = pv.read(tmp_path / "fields_step020.vtu").point_data["stress"].reshape(-1, 3, 3)
    assert np.abs(sigma).max() > 0.05
    assert np.allclose(sigma[:, 2, 2], 0.25 * (sigma[:, 0, 0] + sigma[:, 1, 1]), rtol=0, atol=1e-12)
    assert np.all(sigma[:, :2, 2] == 0) and np.all(sigma[:, 2, :2] == 0)
    face = pv.read(tmp_path / "contact_step020.vtu")
    assert set(face.celltypes) == {pv.CellType.LINE} and np.array_equal(face.point_data["wear"], strip.wear[20])
    assert face.compute_cell_sizes()["Length"].sum() == pytest.approx(strip.weights.sum(), rel=1e-12)


def test_first_time_wear_reached_the_gap(strip):
    result = strip
    reached = result.wear.max(axis=1) >= 0.99 * result.scene.contact.gap           # w → g only asymptotically
    assert reached.any() and not reached[0]
    assert result.summary()["gap_reached_at"] == result.times[np.argmax(reached)]


# ---------------------------------------------------------------- provenance


def test_provenance_traces_the_versions_and_the_scene(stop, tmp_path):
    _, out, printed = stop
    scene = json.loads((out / "scene.json").read_text())
    expected = {"ngwear": ngwear.__version__, "ngsolve": ngs.__version__, "python": platform.python_version(),
                "scene_sha256": hashlib.sha256(json.dumps(scene, sort_keys=True, separators=(",", ":"),
                                                          ensure_ascii=False).encode()).hexdigest()}
    assert json.loads((out / "summary.json").read_text())["provenance"] == expected
    assert load_result(out).provenance == expected and f"ngwear {ngwear.__version__}, NGSolve" in printed
    with np.load(out / "result.npz") as data:                       # without it: not a result of ngwear
        damaged = {k: data[k] for k in data.files if k != "provenance"}
    for name in ("scene.json", "mesh.vol"):
        (tmp_path / name).write_bytes((out / name).read_bytes())
    np.savez(tmp_path / "result.npz", **damaged)
    with pytest.raises(ngwear.SceneError, match=r"result\.npz is damaged or not a result of ngwear \(no provenance\)$"):
        load_result(tmp_path)


def test_a_study_row_records_the_provenance(backed_p2, tmp_path):
    row = simulate_case(backed_p2.scene, "group", str(tmp_path))
    assert row["status"] == "completed"
    assert [row[c] for c in COLUMNS] == [*backed_p2.provenance.values()] == [
        ngwear.__version__, ngs.__version__, platform.python_version(), backed_p2.provenance["scene_sha256"]]
