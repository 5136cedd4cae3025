"""Local refinement of Γ_C: ``mesh.contact_maxh`` within ``mesh.contact_zone`` of ``mesh.zone_center``.

For every kind: the contact points within the zone are as dense as h asks (a triangulation of edge h has
2/(√3 h²) vertices per unit area), those outside thin out smoothly, and the zone sits where its centre says: the
part's first point of contact by default (the sphere's tip, the flat pad's centroid, the strip's middle).
"""
import math

import numpy as np
import pytest
from conftest import ROOT
from scipy.spatial import cKDTree

import ngwear
from ngwear.model.scene import Scene, SceneError
from ngwear.model.scene_mesh import mesh_key
from ngwear.numerics.discrete import Discretization

PIN = {"name": "sphere", "units": "SI",
       "geometry": {"kind": "pin", "size": [0.001, 0.004], "end": "sphere", "position": [0.03, 0.0], "dirichlet": []},
       "mesh": {"maxh": 0.0005, "contact_maxh": 5e-5, "contact_zone": 3e-4},
       "material": {"young": 2e11, "poisson": 0.3},
       "contact": {"stiffness": 1.0, "gap": 1e-12, "direction": [0, 0, -1]},
       "loads": {"plate": {"boundary": "back", "force": [0, 0, -1000.0]}}, "time": {"steps": 1}}


def across(points, center, nu):
    """Distance from the centre measured across ν (the zone's measure)."""
    flat = np.eye(len(nu)) - np.outer(nu, nu)
    return np.linalg.norm((points - center) @ flat, axis=1)


def spacing(points) -> np.ndarray:
    """Each point's distance to its nearest neighbour (the local edge length of the contact mesh, P1)."""
    return cKDTree(points).query(points, k=2)[0][:, 1]


@pytest.fixture(scope="module")
def pin():
    return Discretization(Scene.from_dict(PIN))


def test_a_sphere_ended_pin_is_refined_around_its_tip_only(pin):
    """About the points the zone needs (its area at edge h), not the whole cap's; spacing ≈ h inside, growing out."""
    scene, pts = pin.scene, pin.points.coords
    h, rho, a = scene.mesh.contact_maxh, scene.mesh.contact_zone, scene.geometry.size[0]
    r = across(pts, np.array([0.03, 0.0, 0.0]), np.array([0.0, 0.0, -1.0]))
    needed = math.pi * rho**2 * 2 / (math.sqrt(3) * h**2)             # 84 points of a triangulation of edge h
    cap = 2 * math.pi * a**2 * 2 / (math.sqrt(3) * h**2)               # 2 900: the hemisphere at edge h
    inside = r <= rho
    assert 0.6 * needed < inside.sum() < 1.2 * needed and pin.points.n < 0.1 * cap
    near = spacing(pts)
    assert near[r < rho - h].max() < 1.3 * h and np.median(near[r < rho - h]) < 1.1 * h
    assert np.median(near[r > 3 * rho]) > 4 * h                           # coarse away from the zone
    ring = [np.median(near[(r > lo) & (r < lo + 2e-4)]) for lo in (3e-4, 5e-4, 7e-4)]
    assert ring[0] < ring[1] < ring[2]                                    # grading: growing smoothly outwards
    assert np.abs(pts[inside, :2].mean(axis=0) - [0.03, 0.0]).max() < h   # centred on the tip: the pin's axis


def test_the_zone_and_its_centre_shape_the_mesh_key(pin):
    scene = pin.scene
    keys = {mesh_key(scene.replace(**change)) for change in
            ({"mesh.contact_zone": 2e-4}, {"mesh.zone_center": [0.0302, 0.0, 0.0]}, {"mesh.zone_center": None})}
    assert len(keys) == 3 and mesh_key(scene) in keys


def test_a_flat_pad_is_refined_around_its_centre_or_where_told():
    """The pad's first point of contact is all of its face: the zone sits on the face's centroid, or on zone_center."""
    pad = Scene.from_dict({"geometry": {"kind": "pad", "dirichlet": ["back"]},
                           "mesh": {"maxh": 0.15, "contact_maxh": 0.02, "contact_zone": 0.08}})
    inner, outer, angle, _ = pad.geometry.size
    half = math.radians(angle) / 2
    centroid = 2 / 3 * (outer**3 - inner**3) / (outer**2 - inner**2) * math.sin(half) / half
    for centre in (None, [0.75, 0.2, 0.0]):
        scene = pad.replace(**{"mesh.zone_center": centre})
        pts = Discretization(scene).points.coords
        expected = np.array([centroid, 0.0] if centre is None else centre[:2])
        dense = spacing(pts) < 1.3 * scene.mesh.contact_maxh
        assert dense.sum() > 40
        assert np.linalg.norm(pts[dense, :2].mean(axis=0) - expected) < 0.02, centre
        assert across(pts[dense], np.array([*expected, 0.0]), np.array([0.0, 0.0, -1.0])).max() < 0.08 + 0.04


def test_a_cad_part_is_refined_in_its_zone():
    """The STEP pad (no shape of ngwear's): its face is refined within the zone only, coarse elsewhere."""
    scene = ngwear.load_scene(ROOT / "geometries" / "cad_pad.toml").replace(**{"mesh.maxh": 0.01})
    h, rho = 0.0025, 0.01
    disc = Discretization(scene.replace(**{"mesh.contact_maxh": h, "mesh.contact_zone": rho}))
    pts = disc.points.coords
    r = across(pts, pts.mean(axis=0), np.asarray(scene.contact.direction))
    near = spacing(pts)
    assert near[r < rho - h].max() < 1.3 * h and np.median(near[r > 3 * rho]) > 2.5 * h
    whole = disc.points.weights.sum() * 2 / (math.sqrt(3) * h**2)         # the face at edge h: 7 400 points
    assert disc.points.n < 0.2 * whole


def test_a_strip_is_refined_about_its_middle():
    strip = ngwear.load_scene(ROOT / "geometries" / "paper_strip.toml").replace(**{
        "mesh.maxh": 0.2, "mesh.contact_maxh": 0.02, "mesh.contact_zone": 0.3})
    x = np.sort(Discretization(strip).points.coords[:, 0])
    gaps, middle = np.diff(x), 0.5 * (x[1:] + x[:-1])
    assert gaps[np.abs(middle - 1.5) < 0.3].max() <= 1.2 * 0.02 and gaps[np.abs(middle - 1.5) > 1.0].min() > 0.1


def test_zone_results_agree_with_uniform_refinement():
    """Hertz on the half-disk, the arc refined within the zone (1/7 of the points) or all of it: they agree.

    Within the discretisation error (their distance to Hertz's solution), the zone no farther from it.
    """
    from test_hertz import hertz

    scene = ngwear.load_scene(ROOT / "geometries" / "hertz.toml").replace(**{
        "mesh.maxh": 0.2, "mesh.contact_maxh": 0.005, "mesh.grading": 0.3})
    zone, uniform = (ngwear.simulate(scene.replace(**{"mesh.contact_zone": rho}), progress=False) for rho in (0.15, 1))
    assert len(zone.contact_points) < len(uniform.contact_points) / 7
    (z, u) = (hertz(r) for r in (zone, uniform))
    assert abs(z["a"] - u["a"]) < 0.1 * abs(u["a"] - u["a_hertz"])
    assert abs(z["peak"] - u["peak"]) < abs(u["peak"] - u["p0_hertz"])
    assert z["force"] == pytest.approx(u["force"], rel=5e-3)
    at = np.linspace(-0.8, 0.8, 41)
    error = {name: np.std(np.interp(at * h["a_hertz"], h["x"], h["traction"]) - h["p0_hertz"] * np.sqrt(1 - at**2))
             for name, h in (("zone", z), ("uniform", u))}
    assert error["zone"] < 1.2 * error["uniform"] < 0.02 * u["p0_hertz"], error


@pytest.mark.parametrize("changes, message", [
    ({"mesh.contact_zone": 3e-4, "mesh.contact_maxh": None}, "mesh.contact_zone: only with mesh.contact_maxh"),
    ({"mesh.zone_center": [0.03, 0.0]}, "mesh.zone_center: must be a list of 3 numbers"),
    ({"mesh.contact_zone": None, "mesh.zone_center": [0.03, 0.0, 0.0]}, "mesh.zone_center: only with "
                                                                         "mesh.contact_zone"),
    ({"mesh.contact_zone": 0.1}, "mesh.contact_zone: must be in (0, 0.004]"),
])
def test_zone_errors_name_the_key(changes, message):
    with pytest.raises(SceneError) as info:
        Scene.from_dict(PIN).replace(**changes)
    assert str(info.value).startswith(message) and "\n" not in str(info.value), info.value


def test_a_zone_off_the_part_is_one_line():
    far = Scene.from_dict(PIN).replace(**{"mesh.zone_center": [0.05, 0.0, 0.0]})
    with pytest.raises(SceneError, match=r"^mesh\.zone_center: no point of Γ_C within mesh\.contact_zone = 0\.0003 "
                                         r"of \(0\.05, 0, 0\)"):
        Discretization(far).mesh


def test_a_mesh_file_takes_no_zone(tmp_path):
    strip = ngwear.load_scene(ROOT / "geometries" / "paper_strip.toml").replace(**{"mesh.maxh": 0.5})
    Discretization(strip).mesh.ngmesh.Save(str(tmp_path / "strip.vol"))
    with pytest.raises(SceneError, match=r"^mesh\.maxh: not used with geometry\.kind = 'mesh'.*mesh\.contact_zone"):
        Scene.from_dict({"geometry": {"kind": "mesh", "file": str(tmp_path / "strip.vol"), "dirichlet": ["left"]},
                         "mesh": {"contact_zone": 0.1}})
