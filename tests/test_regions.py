"""Regions: a backing glued onto the part, a material per region, against closed forms."""
import ngsolve as ngs
import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.model.scene_mesh import build_mesh

COLUMN = {   # a 0.1 × 0.1 column of friction material (t₁ = 0.3) on a backing (t₂), held by a plate on top
    "geometry": {"kind": "box", "size": [0.1, 0.1, 0.3], "dirichlet": []},
    "mesh": {"maxh": 0.1},
    "contact": {"stiffness": 5e3, "gap": 1.0, "friction": 0.0, "wear": 0.0, "direction": [0.0, 0.0, -1.0]},
    "foundation": {"velocity": [1.0, 0.0, 0.0]},
    "loads": {"plate": {"boundary": "top", "force": [0.0, 0.0, -0.02]}},     # strains ≤ 0.2 %: small
    "time": {"T": 1.0, "steps": 1},
}


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("backing, young", [(0.05, 1e4), (0.2, 1e3), (0.1, 1e7)])
def test_glued_column_is_the_series_of_its_springs(order, backing, young):
    """ν = 0 and no friction: uniaxial stress σ = F/A, δ = σ (t₁/E₁ + t₂/E₂ + 1/L), exact for piecewise-linear u."""
    scene = ngwear.Scene.from_dict({**COLUMN, "geometry": {**COLUMN["geometry"], "backing": backing},
                                    "mesh": {"maxh": 0.1, "order": order},
                                    "material": {"young": 2e3, "poisson": 0.0,
                                                 "regions": {"backing": {"young": young}}}})
    result = ngwear.simulate(scene, progress=False)
    sigma = 0.02 / 0.01
    expected = sigma * (0.3 / 2e3 + backing / young + 1 / 5e3)
    assert result.completed
    assert result.plate_displacement[-1, 0] == pytest.approx(expected, rel=1e-10)
    assert result.pressure[-1] == pytest.approx(np.full(len(result.weights), sigma), rel=1e-10)


def test_backing_is_a_region_with_its_own_faces():
    scene = ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml").replace(**{"geometry.backing": 0.004})
    mesh = build_mesh(scene)
    inner, outer, angle, thickness = scene.geometry.size
    sector = np.radians(angle) / 2 * (outer ** 2 - inner ** 2)
    volumes = {r: ngs.Integrate(1, mesh, definedon=mesh.Materials(r)) for r in ("body", "backing")}
    assert volumes["body"] == pytest.approx(sector * thickness, rel=2e-3)     # straight-sided elements under arcs
    assert volumes["backing"] == pytest.approx(sector * 0.004, rel=2e-3)
    area = {b: ngs.Integrate(1, mesh, ngs.BND, definedon=mesh.Boundaries(b)) for b in ("contact", "interface", "back")}
    assert area["contact"] == pytest.approx(area["interface"], rel=1e-3)    # facets under the arcs differ
    assert area["back"] == pytest.approx(area["interface"], rel=1e-3)
    assert scene.geometry.regions == ("body", "backing") and "interface" not in scene.geometry.boundaries


@pytest.mark.parametrize("changes, field, fragment", [
    ({"material.regions": {"lining": {"young": 1.0}}}, "material.regions.lining", "unknown region"),
    ({"geometry.backing": 0.1, "material": {"regions": {"body": {"young": 1.0, "poisson": 0.2}}}},
     "material.regions.backing", "missing"),
    ({"geometry.backing": 0.1, "material.regions": {"backing": {"young": 1.0, "lame_mu": 1.0}}},
     "material.regions.backing.young", "cannot be combined"),
    ({"geometry.backing": 1e-6}, "geometry.backing", "at least 0.001"),
    ({"geometry.backing": -0.1}, "geometry.backing", "> 0"),
    ({"geometry.backing": 0.1, "geometry.kind": "half_disk", "geometry.size": [1.0]}, "geometry.backing",
     "only for geometry.kind"),
])
def test_bad_regions_are_one_line_naming_the_key(paper_scene, changes, field, fragment):
    with pytest.raises(ngwear.SceneError) as info:
        paper_scene.replace(**changes)
    message = str(info.value)
    assert message.startswith(f"{field}:") and fragment in message and "\n" not in message


@pytest.mark.parametrize("axis, modulus", [([0.0, 0.0, -1.0], "young_axis"), ([1.0, 0.0, 0.0], "young_plane"),
                                           ([0.0, 1.0, 0.0], "young_plane"), (None, "young_axis")])
def test_transversely_isotropic_column_recovers_its_moduli(axis, modulus):
    """A transversely isotropic column with ν_p = ν_ap = 0 is strained by σ/E along z: δ = σ (h/E + 1/L), exact.

    E = E_a when the axis is z (given, or the default: ν), E_p when the axis lies in the plane.
    """
    constants = {"law": "transversely_isotropic", "young_plane": 3e3, "young_axis": 1e3, "poisson_plane": 0.0,
                 "poisson_axis": 0.0, "shear_axis": 500.0, **({"axis": axis} if axis else {})}
    result = ngwear.simulate(ngwear.Scene.from_dict({**COLUMN, "material": constants}), progress=False)
    expected = 2.0 * (0.3 / constants[modulus] + 1 / 5e3)
    assert result.plate_displacement[-1, 0] == pytest.approx(expected, rel=1e-10)


def test_transversely_isotropic_pad_is_softer_through_its_thickness():
    """A pad twice as stiff in-plane as through its thickness sinks between the isotropic pads of E_a and E_p."""
    pad = ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml").replace(**{
        "mesh.maxh": 0.02, "time.steps": 1, "time.T": 1.0, "output.every": 1.0, "contact.wear": 0.0})
    sink = {}
    for name, material in (("soft", {"young": 1e9, "poisson": 0.25}), ("stiff", {"young": 2e9, "poisson": 0.25}),
                           ("ti", {"law": "transversely_isotropic", "young_plane": 2e9, "young_axis": 1e9,
                                   "poisson_plane": 0.25, "poisson_axis": 0.25, "shear_axis": 0.4e9})):
        result = ngwear.simulate(pad.replace(**{"material": material}), progress=False)
        sink[name] = result.plate_displacement[-1, 0] - 3000 / (result.weights.sum() * 1e10)   # minus the layer's
    assert sink["stiff"] < sink["ti"] < sink["soft"]
