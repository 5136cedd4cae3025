"""Wear that removes material: the mesh moved by the wear, its quality, a remesh, and the worn region's thickness.

Checks: a uniform wear W moves a prismatic body's worn region by exactly φ = W (1 − s/H) (the harmonic extension
reproduces linear functions), so its volume is A (H − W), every element keeps its shape but for the squeeze
1 − W/H, the faces parallel to ν keep their vertices and a backing does not move; a wear beyond the thickness
inverts elements and is said in one line; NGSolve's integrals and point search follow the moved vertices; the
remeshed worn body has the same regions, boundaries and measures; the thickness along −ν under each contact point
is the part's (a strip, a box, the shipped pad on its backing, a spherical pin end, a half disk).
"""
import math

import ngsolve as ngs
import numpy as np
import pytest
from conftest import PAPER, ROOT

import ngwear
from ngwear.model.kinds import KINDS
from ngwear.model.scene_mesh import build_mesh
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.recession import (
    QUALITY,
    Extension,
    Recession,
    RemeshError,
    contact_height,
    mean_ratio,
    quality,
    remeshed,
    tilted,
)
from ngwear.numerics.thickness import thickness
from ngwear.numerics.topology import coordinates, facets, place, signed_volumes, simplices

BOX = ngwear.load_scene(ROOT / "geometries" / "box3d.toml").replace(**{"mesh.maxh": 0.2})
STRIP = ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.25, "geometry.backing": 0.4})


def volume(mesh, region=None):
    return ngs.Integrate(ngs.CF(1.0), mesh, definedon=mesh.Materials(region) if region else None)


def test_mean_ratio_of_regular_and_flattened_simplices():
    tet = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    triangle = np.array([[0, 0], [1, 0], [0.5, math.sqrt(3) / 2]])
    assert mean_ratio(tet, np.array([[0, 1, 2, 3]]))[0] == pytest.approx(1.0, rel=1e-14)
    assert mean_ratio(triangle, np.array([[0, 1, 2]]))[0] == pytest.approx(1.0, rel=1e-14)
    flat = triangle * [1, 0.1]                      # height a tenth: 4√3 A / Σl² = 0.1·3/(1 + 2(0.25 + 0.0075))
    assert mean_ratio(flat, np.array([[0, 1, 2]]))[0] == pytest.approx(0.3 / 1.515, rel=1e-12)


@pytest.mark.parametrize("scene, height", [(BOX, 0.5), (STRIP, 1.0)], ids=["box", "strip-backing"])
def test_uniform_wear_squeezes_the_worn_region_linearly(scene, height):
    mesh = build_mesh(scene)
    nu = np.array(scene.contact.direction)
    extension = Extension(mesh, nu)
    start, whole = coordinates(mesh), volume(mesh)
    worn = 0.3 * height
    moved = extension.moved(np.full(len(extension.contact), worn))
    depth = -(start @ nu)                            # the height above Γ_C
    body = depth <= height * (1 + 1e-12)
    expected = start - np.outer(np.where(body, worn * (1 - depth / height), 0.0), nu)
    assert np.abs(moved - expected).max() < 1e-12 * height, "φ = W (1 − s/H), the backing still"
    nodes, regions = simplices(mesh)
    q = quality(moved, start, nodes)
    carrying = mesh.GetMaterials().index("body")
    assert q.inverted == 0 and q.squeezed == pytest.approx(1 - 0.3, rel=1e-10) and q.acceptable
    before = signed_volumes(start, nodes[regions != carrying])
    assert np.array_equal(before, signed_volumes(moved, nodes[regions != carrying]))
    place(mesh, moved)
    area = whole / (height + (scene.geometry.backing or 0.0))
    assert volume(mesh) == pytest.approx(whole - worn * area, rel=1e-12)
    surface = start[extension.contact].mean(axis=0)
    assert mesh(*(surface - 1.1 * worn * nu)).nr >= 0 and mesh(*(surface - 0.9 * worn * nu)).nr < 0, \
        "the point search follows: the worn layer is outside"


@pytest.mark.parametrize("scene", [STRIP, ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml")],
                         ids=["strip-backing", "pad"])
def test_facets_are_ngsolves_boundary_elements(scene):
    """Netgen's element arrays give NGSolve's boundary elements: the same vertices and names, in its order."""
    mesh = build_mesh(scene)
    faces, names = facets(mesh)
    elements = list(mesh.Elements(ngs.BND))
    assert np.array_equal(faces, [[v.nr for v in el.vertices] for el in elements])
    assert names.tolist() == [el.mat for el in elements] and "interface" in names


def test_faces_parallel_to_nu_slide_and_the_others_are_held():
    mesh = build_mesh(BOX)
    faces, names = facets(mesh)
    assert set(tilted(coordinates(mesh), faces, names, np.array([0.0, 0.0, -1.0]))) == {"top"}
    pad = build_mesh(ngwear.load_scene(ROOT / "geometries" / "brake_pad.toml"))
    faces, names = facets(pad)
    assert set(tilted(coordinates(pad), faces, names, np.array([0.0, 0.0, -1.0]))) == {"back", "interface"}, \
        "the arcs' chords tilt, the arcs do not"


def test_wear_through_the_region_inverts_elements_and_says_where():
    mesh = build_mesh(BOX)
    extension = Extension(mesh, BOX.contact.direction)
    nodes, _ = simplices(mesh)
    q = quality(extension.moved(np.full(len(extension.contact), 0.6)), extension.reference, nodes)
    assert q.inverted > 0 and not q.acceptable and q.worst == 0.0
    assert q.reason.startswith("the worn mesh has") and "\n" not in q.reason
    x = extension.reference[extension.contact, 0]
    step = quality(extension.moved(0.45 * (x > 0.5)), extension.reference, nodes)
    assert step.inverted > 0, "a step of 90 % of the height within an element cannot be followed"
    taper = quality(extension.moved(0.25 * x), extension.reference, nodes)
    assert taper.acceptable and taper.reason is None and QUALITY < taper.worst < 1


@pytest.mark.parametrize("scene, exact", [(BOX, 1e-4), (STRIP, 1e-12)], ids=["box", "strip-backing"])
def test_remeshed_worn_body_keeps_regions_boundaries_and_measures(scene, exact):
    """2D: the moved boundary meshed anew (exact); 3D: the part cut by a B-spline through the worn face."""
    mesh = build_mesh(scene, use_cache=False)
    nu = np.array(scene.contact.direction)
    extension = Extension(mesh, nu)
    x = extension.reference[extension.contact, 0]
    place(mesh, extension.moved(0.2 * (0.5 + x / x.max())))                 # a tapered wear
    shape = KINDS[scene.geometry.kind].build(scene.geometry, scene.mesh)
    fresh = remeshed(mesh, scene.mesh.maxh, nu, shape)
    assert fresh.GetMaterials() == mesh.GetMaterials()
    assert set(fresh.GetBoundaries()) == set(mesh.GetBoundaries())
    for region in mesh.GetMaterials():
        assert volume(fresh, region) == pytest.approx(volume(mesh, region), rel=exact)
    for name in set(mesh.GetBoundaries()):
        measure = [ngs.Integrate(ngs.CF(1.0) * ngs.ds(name), m) for m in (mesh, fresh)]
        assert measure[1] == pytest.approx(measure[0], rel=exact), name
    nodes, _ = simplices(fresh)
    assert mean_ratio(coordinates(fresh), nodes).min() > 2 * QUALITY


def test_a_mesh_without_geometry_is_not_remeshed_in_3d():
    mesh = build_mesh(BOX)
    with pytest.raises(RemeshError, match="^a part given as a mesh"):
        remeshed(mesh, 0.2, BOX.contact.direction)


@pytest.mark.parametrize("name, changes, expected", [
    ("paper_strip.toml", {"mesh.maxh": 0.25}, lambda x: np.ones(len(x))),
    ("paper_strip.toml", {"mesh.maxh": 0.25, "geometry.backing": 0.4}, lambda x: np.ones(len(x))),
    ("box3d.toml", {"mesh.maxh": 0.2}, lambda x: np.full(len(x), 0.5)),
    ("brake_pad.toml", {"mesh.maxh": 0.012}, lambda x: np.full(len(x), 0.012)),
    ("pin_on_disc.toml", {"mesh.maxh": 0.006, "mesh.contact_maxh": 0.0015}, lambda x: 0.012 - x[:, 2]),
    ("hertz.toml", {"mesh.maxh": 0.2, "mesh.contact_maxh": 0.1}, lambda x: 1.0 - x[:, 1]),
], ids=["strip", "strip-backing", "box", "pad-backing", "pin-sphere", "half-disk"])
def test_thickness_along_nu_under_each_contact_point(name, changes, expected):
    scene = ngwear.load_scene(ROOT / "geometries" / name).replace(**changes)
    disc = Discretization(scene)
    measured = thickness(disc.mesh, disc.points.coords, scene.contact.direction)
    assert np.abs(measured - expected(disc.points.coords)).max() < 1e-12 * measured.max()


@pytest.mark.parametrize("order", [1, 2])
def test_an_update_realises_the_wear_at_the_vertices_and_keeps_the_rest_in_the_layer(order):
    """P1: the whole wear since the update moves Γ_C; P2 (3D: the edge midpoints) keeps a rest in the layer.

    A vertex takes the least wear of the points at it, so the move never exceeds a point's wear; the rest is ≤ h|∇w|.
    """
    scene = BOX.replace(**{"mesh.order": order})
    disc = Discretization(scene)
    nu = np.array(scene.contact.direction)
    x = disc.points.coords[:, 0]
    for wear in (np.full(disc.points.n, 0.1), 0.05 + 0.05 * x, 0.1 - 0.05 * x ** 2):
        recession = Recession(build_mesh(scene), disc.points, nu)
        coords, q = recession.trial(wear)
        assert q.acceptable
        rest = wear - recession.accept(coords, wear)
        assert rest.min() >= 0 and rest.max() <= (1e-15 if order == 1 or np.ptp(wear) == 0 else 0.05 * 0.2)
        assert np.allclose(coordinates(recession.mesh)[recession.extension.contact],
                           recession.extension.reference[recession.extension.contact]
                           - np.outer(recession.wear, nu), atol=1e-15)


def test_the_height_of_the_smallest_element_at_the_contact():
    """On the strip's flat Γ_C (y = 0) an element's height over its contact edge is its third vertex's y."""
    mesh = build_mesh(STRIP)
    nodes, _ = simplices(mesh)
    y = coordinates(mesh)[:, 1]
    touching = (np.abs(y[nodes]) < 1e-14).sum(axis=1) == 2
    assert contact_height(mesh) == pytest.approx(np.where(touching[:, None], y[nodes], 0).max(axis=1)[touching].min())
    assert 0 < contact_height(build_mesh(BOX)) <= BOX.mesh.maxh


def test_a_moved_discretization_rebuilds_only_the_moved_regions_stiffness():
    """``Discretization.moved`` keeps the backing's gradient blocks (no vertex of it moves); K is the fresh one's."""
    disc = Discretization(STRIP)
    K = disc.elastic.stiffness
    recession = Recession(ngs.Mesh(disc.mesh.ngmesh.Copy()), disc.points, np.array(STRIP.contact.direction))
    coords, _ = recession.trial(np.full(disc.points.n, 0.2))
    recession.accept(coords, np.full(disc.points.n, 0.2))
    assert recession.extension.regions == ("body",)
    moved = disc.moved(recession.mesh, recession.extension.regions)
    fresh = Discretization(STRIP, recession.mesh).elastic.stiffness
    assert (abs(moved.elastic.stiffness - fresh)).max() == 0 and (abs(moved.elastic.stiffness - K)).max() > 0
    kept, old = moved.body.gradient_blocks.built, disc.body.gradient_blocks.built
    assert all(kept["backing"][ab] is old["backing"][ab] for ab in old["backing"])
    assert all(kept["body"][ab] is not old["body"][ab] for ab in old["body"])
    coords, _ = recession.trial(np.full(disc.points.n, 0.1))         # a second update, on the same mesh object:
    recession.accept(coords, np.full(disc.points.n, 0.1))            # the body's index map is kept, K is fresh's
    again = moved.moved(recession.mesh, recession.extension.regions)
    patterns = again.body.gradient_blocks.patterns
    assert patterns is moved.body.gradient_blocks.patterns and set(patterns) == {"body"}
    assert (abs(again.elastic.stiffness - Discretization(STRIP, recession.mesh).elastic.stiffness)).max() == 0
