"""Regions: a backing glued onto the part, a material per region, against closed forms."""
import ngsolve as ngs
import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.model.geometry import build_mesh

COLUMN = {   # a 0.1 × 0.1 column of friction material (t₁ = 0.3) on a backing (t₂), held by a plate on top
    "geometry": {"kind": "box", "size": [0.1, 0.1, 0.3], "dirichlet": []},
    "mesh": {"maxh": 0.1},
    "contact": {"stiffness": 5e3, "gap": 1.0, "friction": 0.0, "wear": 0.0, "direction": [0.0, 0.0, -1.0]},
    "foundation": {"velocity": [1.0, 0.0, 0.0]},
    "loads": {"plate": {"boundary": "top", "force": [0.0, 0.0, -2.0]}},
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
    sigma = 2.0 / 0.01
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
