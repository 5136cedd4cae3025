"""What a run of several regions, laws and coefficient fields writes: summary, VTU, pictures."""
import json

import ngsolve as ngs
import numpy as np
import pytest
import pyvista as pv
from PIL import Image

import ngwear
from ngwear.cli import main
from ngwear.results.units import unit
from ngwear.views import part_plots, render
from ngwear.views.pictures import write_pictures

LAM, ETA, BETA = 1.0, 0.8, 3.0          # the body's compaction law
E_B, NU_B = 50.0, 0.3                   # the backing's Hooke law
GLUED = {
    "name": "glued", "geometry": {"kind": "box", "size": [1.0, 0.5, 0.3], "backing": 0.1}, "mesh": {"maxh": 0.2},
    "material": {"law": "compaction", "lame_lambda": LAM, "lame_mu": ETA, "compaction_modulus": BETA,
                 "regions": {"backing": {"law": "linear", "young": E_B, "poisson": NU_B}}},
    "contact": {"friction": "0.2 + 0.1*x", "wear": "where(y < 0.25, 0.5, 1.0)", "gap": 0.1,
                "direction": [0, 0, -1]},
    "foundation": {"velocity": [1, 0, 0]}, "loads": {"traction": {"top": [0.0, 0.0, -0.3]}}, "time": {"steps": 12}}


@pytest.fixture(scope="module")
def glued():
    return ngwear.simulate(ngwear.Scene.from_dict(GLUED), progress=False)


def element_regions(mesh):
    """Region index of each element (its place in mesh.GetMaterials()) and its centroid."""
    names = mesh.GetMaterials()
    elements = list(mesh.Elements(ngs.VOL))
    centroids = np.array([np.mean([mesh.vertices[v.nr].point for v in el.vertices], axis=0) for el in elements])
    return np.array([names.index(el.mat) for el in elements]), centroids


def hooke(young, poisson):
    return young * poisson / ((1 + poisson) * (1 - 2 * poisson)), young / (2 * (1 + poisson))


# ---------------------------------------------------------------- summary


def test_summary_gives_each_regions_law_constants_and_moduli(glued, tmp_path):
    """Compaction m_F = 2η, L_F = 2η + d(λ + β); Hooke (λ, η ≥ 0) m_F = 2η, L_F = 2η + dλ."""
    lam_b, eta_b = hooke(E_B, NU_B)
    materials = glued.summary()["materials"]
    assert list(materials) == ["body", "backing"]
    body, backing = materials["body"], materials["backing"]
    assert body == {"law": "compaction", "lame_lambda": LAM, "lame_mu": ETA, "compaction_modulus": BETA,
                    "m_F": pytest.approx(2 * ETA, rel=1e-14), "L_F": pytest.approx(2 * ETA + 3 * (LAM + BETA), rel=1e-14)}
    assert backing["law"] == "linear" and (backing["young"], backing["poisson"]) == (E_B, NU_B)
    assert backing["m_F"] == pytest.approx(2 * eta_b, rel=1e-12)
    assert backing["L_F"] == pytest.approx(2 * eta_b + 3 * lam_b, rel=1e-12)
    glued.save(tmp_path)
    assert json.loads((tmp_path / "summary.json").read_text())["materials"] == json.loads(json.dumps(materials))


def test_energy_law_gets_its_moduli_estimated_over_the_run():
    """ψ of the compaction law, compressed: the sampled tangents give m_F = 2η, L_F = 2η + 2(λ + β) (2D)."""
    def psi(e):
        tr = ngs.Trace(e)
        return ETA * ngs.InnerProduct(e, e) + LAM / 2 * tr ** 2 + BETA / 2 * ngs.IfPos(tr, 0, tr ** 2)

    scene = ngwear.Scene.from_dict({
        "geometry": {"kind": "strip", "size": [1.0, 0.3]}, "mesh": {"maxh": 0.1},
        "material": {"law": "energy", "energy": psi}, "contact": {"friction": 0.0, "wear": 0.0},
        "loads": {"traction": {"top": [0.0, -0.2]}}, "time": {"steps": 2}})
    body = ngwear.simulate(scene, progress=False).summary()["materials"]["body"]
    assert body["law"] == "energy" and body["estimated"] > 0
    assert body["m_F"] == pytest.approx(2 * ETA, rel=1e-10)
    assert body["L_F"] == pytest.approx(2 * ETA + 2 * (LAM + BETA), rel=1e-10)


def test_run_prints_each_regions_material_beside_the_uniqueness_line(tmp_path, capsys):
    scene = tmp_path / "glued.toml"
    scene.write_text("""
[geometry]
kind = "strip"
size = [1.0, 0.3]
backing = 0.1
[mesh]
maxh = 0.15
[material]
law = "compaction"
lame_lambda = 1.0
lame_mu = 0.8
compaction_modulus = 3.0
[material.regions.backing]
law = "linear"
young = 50.0
poisson = 0.3
[contact]
friction = 0.3
[loads.traction]
top = [0.0, -0.2]
[time]
steps = 3
""")
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--no-pictures", "-q"]) == 0
    lines = capsys.readouterr().out.splitlines()
    materials = [line.split(None, 1)[1] for line in lines if line.startswith("material ")]
    assert materials == ["body: compaction λ=1 η=0.8 β=3; m_F = 1.6, L_F = 9.6",
                         "backing: linear E=50 ν=0.3; m_F = 38.46, L_F = 96.15"]
    after = lines[[i for i, line in enumerate(lines) if line.startswith("material ")][-1] + 1]
    assert after.split()[0] == "uniqueness" and "(H_S)" in after


# ---------------------------------------------------------------- VTU


def test_vtu_frames_hold_every_region_with_a_region_field(glued, tmp_path):
    glued.save(tmp_path)
    regions, centroids = element_regions(glued.discretization.mesh)
    for frame in sorted(tmp_path.glob("fields_step*.vtu")):
        grid = pv.read(frame)
        assert np.bincount(grid.cell_data["region"]).tolist() == np.bincount(regions).tolist()
        assert np.array_equal(grid.cell_data["region"] == 1, grid.cell_centers().points[:, 2] > 0.3)
        assert grid.point_data["displacement"].shape == (grid.n_points, 3)


def test_p2_vtu_subdivides_each_region_alike(tmp_path):
    scene = ngwear.Scene.from_dict({
        "geometry": {"kind": "strip", "size": [1.0, 0.3], "backing": 0.1}, "mesh": {"maxh": 0.15, "order": 2},
        "contact": {"friction": 0.0, "wear": 0.0}, "loads": {"traction": {"top": [0.0, -0.2]}},
        "time": {"steps": 1}})
    result = ngwear.simulate(scene, progress=False)
    result.save(tmp_path)
    regions, _ = element_regions(result.discretization.mesh)
    grid = pv.read(tmp_path / "fields_step001.vtu")
    assert grid.n_cells > len(regions)                                    # subdivided
    per_element = grid.n_cells // len(regions)
    assert np.bincount(grid.cell_data["region"]).tolist() == (per_element * np.bincount(regions)).tolist()
    assert np.array_equal(grid.cell_data["region"] == 1, grid.cell_centers().points[:, 1] > 0.3)


# ---------------------------------------------------------------- pictures


def test_run_pictures_add_regions_and_coefficient_maps(glued, tmp_path):
    paths = {p.name for p in write_pictures(glued, tmp_path)}
    assert {"regions.png", "coefficients.png", "contact_maps.png"} <= paths
    for name in ("regions.png", "coefficients.png"):
        image = np.asarray(Image.open(tmp_path / name).convert("RGB"))
        assert image.std() > 20 and len(np.unique(image.reshape(-1, 3), axis=0)) > 50


def test_region_picture_colours_the_cells_by_their_region(glued):
    regions, _ = element_regions(glued.discretization.mesh)
    with render.Canvas("region", window_size=(400, 200)) as canvas:
        image = canvas.frame(glued, -1)
        grid = canvas._parts["body"].grid
        assert np.array_equal(grid.cell_data["region"], regions)
        assert canvas._parts["body_actor"].mapper.scalar_range == (-0.5, 1.5)
    assert image.std() > 20


def test_coefficient_maps_draw_the_results_coefficients(glued):
    """The maps' node values are μ = 0.2 + 0.1 x and κ = where(y < 0.25, 0.5, 1) at their nodes (P1: Γ_C's vertices)."""
    assert part_plots.varying(glued) == ["friction_coefficient", "wear_coefficient"]
    fig = part_plots.coefficient_figure(glued)
    friction, wear = (ax.collections[0] for ax in fig.axes if ax.get_label() != "<colorbar>")
    tri = part_plots._triangulation(glued)[0]
    assert np.allclose(friction.get_array(), 0.2 + 0.1 * tri.x, rtol=1e-14, atol=1e-14)
    assert np.array_equal(wear.get_array(), np.where(tri.y < 0.25, 0.5, 1.0))
    assert len(tri.x) == len(glued.friction_coefficient)                 # P1: one node per contact point


def test_maps_label_their_axes_and_bars_with_units():
    """An SI scene's maps of Γ_C: x and y in m on the axes; κ in 1/Pa, L in Pa/m (Pa/m^e for p = L r₊^e), μ none."""
    scene = ngwear.Scene.from_dict({**GLUED, "units": "SI"}).replace(**{"time.steps": 2, "wear.integrator": "implicit"})
    si = ngwear.simulate(scene, progress=False)
    fig = part_plots.coefficient_figure(si)
    maps = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert [ax.get_xlabel() for ax in maps] == ["x (m)", "x (m)"] and maps[0].get_ylabel() == "y (m)"
    assert [ax.get_ylabel() for ax in fig.axes if ax.get_label() == "<colorbar>"] == ["friction μ",
                                                                                      "wear coefficient κ (1/Pa)"]
    fig = part_plots.contact_figure(si, steps=[0, -1])
    maps = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert [ax.get_xlabel() for ax in maps] == ["", "", "x (m)", "x (m)"]
    assert [ax.get_ylabel() for ax in maps] == ["y (m)", "", "y (m)", ""]
    assert [ax.get_ylabel() for ax in fig.axes if ax.get_label() == "<colorbar>"] == ["pressure p (Pa)",
                                                                                      "wear depth (m)"]
    power = si.scene.replace(**{"contact.law": "power", "contact.exponent": 1.5})
    assert unit(power, "compliance stiffness") == "Pa/m^1.5" and unit(si.scene, "compliance stiffness") == "Pa/m"
    assert part_plots._axis_name(np.array([0.0, 0.0, -1.0])) == "−z"
    assert part_plots._axis_name(np.array([0.6, 0.8, 0.0])) == "along (0.6, 0.8, 0)"


def test_coefficient_curves_in_2d_and_none_for_numbers(paper_result):
    scene = ngwear.Scene.from_dict({
        "geometry": {"kind": "strip", "size": [1.0, 0.3]}, "mesh": {"maxh": 0.1},
        "contact": {"friction": 0.3, "wear": "0.05 + 0.1*x", "stiffness": "10 + 5*x"},
        "loads": {"traction": {"top": [0.0, -0.2]}}, "time": {"steps": 2}})
    result = ngwear.simulate(scene, progress=False)
    assert part_plots.varying(result) == ["wear_coefficient", "contact_stiffness"]
    wear, stiffness = (ax.lines[0] for ax in part_plots.coefficient_figure(result).axes)
    order = np.argsort(result.contact_points[:, 0])
    assert np.array_equal(wear.get_ydata(), result.wear_coefficient[order])
    assert np.allclose(wear.get_ydata(), 0.05 + 0.1 * wear.get_xdata(), rtol=1e-14)
    assert np.allclose(stiffness.get_ydata(), 10 + 5 * stiffness.get_xdata(), rtol=1e-14)
    assert part_plots.varying(paper_result) == []
    with pytest.raises(ValueError, match="names: no coefficient"):
        part_plots.coefficient_figure(paper_result)
