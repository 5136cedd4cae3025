"""Real parts: the brake pad and the pin (their faces, sizes and curved ends), the user's CAD and mesh files.

The pad's faces have the areas of an annular sector (up to the chords of its arcs), the pin's spherical
cap has the initial distance of a sphere, a STEP file's face names become boundaries, a shape or a mesh
given in Python runs exactly like the same body built in, and the full-system path agrees with the
condensed one on a small pad and a small pin under a plate on a turning disc.
"""
import math
import os
import shutil

import ngsolve as ngs
import numpy as np
import pytest
from conftest import ROOT
from netgen.occ import Box, Pnt, X, Z

import ngwear
from ngwear import Scene, SceneError
from ngwear.model.keys import Level
from ngwear.model.scene_mesh import build_mesh, mesh_key
from ngwear.model.user_parts import read_shape

DISC = {"foundation": {"velocity": [0.0, 0.0, 0.0], "angular_velocity": [0.0, 0.0, 1.0]},
        "contact": {"gap": 0.05, "stiffness": 10.0, "friction": 0.3, "wear": 0.5},
        "material": {"young": 50.0, "poisson": 0.3}, "time": {"steps": 6}}


def on_disc(geometry, maxh, force=-0.05, **extra):
    return Scene.from_dict({**DISC, "name": geometry["kind"], "geometry": {"dirichlet": [], **geometry},
                            "mesh": {"maxh": maxh, **extra},
                            "loads": {"plate": {"boundary": "back", "force": [0.0, 0.0, force]}}})


def area(mesh, name):
    return ngs.Integrate(ngs.CF(1.0) * ngs.ds(name), mesh)


def test_pad_faces_are_an_annular_sector():
    scene = on_disc({"kind": "pad", "size": [0.6, 1.0, 60.0, 0.15]}, 0.1)
    mesh = build_mesh(scene)
    sector = math.pi / 3 * (1.0 - 0.36) / 2
    assert set(mesh.GetBoundaries()) == {"contact", "back", "inner", "outer", "leading", "trailing"}
    assert area(mesh, "contact") == pytest.approx(sector, rel=2e-3)      # arcs as chords of ≤ 0.1
    assert area(mesh, "back") == pytest.approx(area(mesh, "contact"), rel=1e-12)
    assert area(mesh, "inner") == pytest.approx(0.6 * math.pi / 3 * 0.15, rel=2e-3)
    assert area(mesh, "outer") == pytest.approx(1.0 * math.pi / 3 * 0.15, rel=2e-3)
    assert area(mesh, "leading") == pytest.approx(0.4 * 0.15, rel=1e-12)
    y = ngs.Integrate(ngs.y * ngs.ds("leading"), mesh) / area(mesh, "leading")
    assert y == pytest.approx(-0.8 * math.sin(math.pi / 6), rel=1e-9)   # φ = −angle/2: where a point of the disc enters
    points = ngwear.simulate(scene, progress=False).discretization.points
    assert points.weights.sum() == pytest.approx(area(mesh, "contact"), rel=1e-12)
    assert np.abs(points.coords[:, 2]).max() == 0


@pytest.mark.parametrize("end", ["flat", "sphere"])
def test_pin_with_a_flat_or_a_spherical_end(end):
    radius, cap_radius = 0.1, 0.25
    geometry = {"kind": "pin", "size": [radius, 0.3], "position": [1.0, 0.5], "end": end}
    if end == "sphere":
        geometry["end_radius"] = cap_radius
    scene = on_disc(geometry, 0.05, contact_maxh=0.02).replace(**{"contact.stiffness": 1000.0, "contact.wear": 0.02,
                                                                   "material.young": 1e4,
                                                                   "wear.integrator": "implicit"})
    result = ngwear.simulate(scene, progress=False)
    assert result.completed and set(result.discretization.mesh.GetBoundaries()) == {"contact", "back", "side"}
    xy = result.contact_points[:, :2] - [1.0, 0.5]
    assert np.linalg.norm(xy, axis=1).max() == pytest.approx(radius, rel=1e-9)
    d0 = result.d0
    if end == "flat":
        assert not d0.any() and result.contact_area[-1] == pytest.approx(result.weights.sum(), rel=1e-12)
    else:   # d₀ = R − √(R² − ρ²) on the cap: the distance to the disc of a sphere touching it at the axis
        rho = np.linalg.norm(xy, axis=1)
        assert d0 == pytest.approx(cap_radius - np.sqrt(cap_radius ** 2 - rho ** 2), abs=1e-12)
        touching = result.pressure[0] > 0          # at first the cap touches near its tip; then it wears flat
        assert 0 < result.contact_area[0] < 0.5 * result.weights.sum() < result.contact_area[-1]
        assert rho[touching].max() < rho.max() and rho[np.argmax(result.pressure[0])] < 0.03
    assert np.abs(result.normal_force - 0.05).max() < 1e-10


def test_cad_pad_from_its_step_file():
    scene = ngwear.load_scene(ROOT / "geometries" / "cad_pad.toml")
    assert scene.geometry.file == str((ROOT / "geometries" / "cad_pad.step").resolve())
    assert set(scene.geometry.boundaries) == {"back", "chamfer", "contact", "inner", "leading", "outer", "slot",
                                              "trailing"}
    coarse = scene.replace(**{"mesh.maxh": 0.012, "time.steps": 4, "output.every": 150.0, "wear.integrator": "trapezoidal"})
    result = ngwear.simulate(coarse, progress=False)
    assert result.completed and np.abs(result.normal_force - 3000.0).max() < 1e-8 * 3000
    shape = read_shape(scene.geometry.file)
    contact = sum(f.mass for f in shape.faces if f.name == "contact")
    assert result.weights.sum() == pytest.approx(contact, rel=1e-2)           # the slot is not in contact
    assert result.contact_points[:, 1].min() < 0 < result.contact_points[:, 1].max()
    assert not ((np.abs(result.contact_points[:, 1]) < 0.0015 - 1e-9)).any(), "no contact point in the slot"


def test_a_part_file_keys_its_mesh_by_content_wherever_it_lies(tmp_path):
    """The mesh cache knows a moved or freshly cloned part by its bytes; an edited part is meshed anew."""
    scene = ngwear.load_scene(ROOT / "geometries" / "cad_pad.toml")
    copies = [tmp_path / folder / "pad.step" for folder in ("here", "there")]
    for number, copy in enumerate(copies):
        copy.parent.mkdir()
        shutil.copyfile(scene.geometry.file, copy)
        os.utime(copy, ns=(10**18 + number, 10**18 + number))                 # a clone's own mtime
    here, there = (scene.replace(**{"geometry.file": str(copy)}) for copy in copies)
    assert here.signature(Level.MESH) != there.signature(Level.MESH)        # in one session: path and mtime
    assert mesh_key(here) == mesh_key(there) == mesh_key(scene)
    step = copies[1].read_text()
    copies[1].write_text(step.replace("2026-11-23T06:41:44", "2026-11-24T06:41:44", 1))
    assert mesh_key(there) != mesh_key(here)


def test_shape_and_mesh_given_in_python_run_as_the_built_in_body(paper_scene):
    box = ngwear.load_scene(ROOT / "geometries" / "box3d.toml").replace(**{"mesh.maxh": 0.2, "time.steps": 10})
    built_in = ngwear.simulate(box, progress=False)
    shape = Box(Pnt(0, 0, 0), Pnt(1, 0.5, 0.5))
    shape.faces.Min(Z).name, shape.faces.Min(X).name, shape.faces.Max(Z).name = "contact", "left", "top"
    from_shape = ngwear.simulate(box.replace(**{"geometry": {"shape": shape, "dirichlet": ["left"]}}), progress=False)
    assert from_shape.scene.geometry.kind == "step" and from_shape.scene.geometry.file.endswith(".brep")
    assert np.abs(from_shape.wear.max() - built_in.wear.max()) < 1e-2 * built_in.wear.max()
    mesh = built_in.discretization.mesh
    from_mesh = ngwear.simulate(box.replace(**{"geometry": {"shape": mesh, "dirichlet": ["left"]}, "mesh": {}}),
                                progress=False)
    assert from_mesh.scene.geometry.kind == "mesh"
    assert np.array_equal(from_mesh.wear, built_in.wear)
    again = box.replace(**{"geometry": {"shape": mesh, "dirichlet": ["left"]}, "mesh": {}})
    assert again.geometry.file == from_mesh.scene.geometry.file        # one cached file per content


@pytest.mark.parametrize("geometry, extra", [
    ({"kind": "pad", "size": [0.6, 1.0, 40.0, 0.15]}, {}),
    ({"kind": "pin", "size": [0.1, 0.3], "end": "sphere", "end_radius": 0.2}, {"contact_maxh": 0.03}),
], ids=["pad", "pin"])
def test_full_system_agrees_on_a_small_pad_and_pin(geometry, extra):
    scene = on_disc(geometry, 0.15 if geometry["kind"] == "pad" else 0.08, **extra)
    scene = scene.replace(**{"loads.plate.tilt": True, "time.steps": 4, "output.every": 1.0})
    fast = ngwear.simulate(scene, progress=False)
    full = ngwear.simulate(scene.replace(**{"solver.method": "full"}), progress=False)
    assert fast.completed and full.completed and fast.wear.max() > 0
    for name in ("normal_displacement", "wear", "pressure", "plate_displacement"):
        assert np.abs(getattr(fast, name) - getattr(full, name)).max() < 1e-9, name
    assert np.allclose(fast.torque, full.torque, rtol=1e-9, atol=0)


@pytest.mark.parametrize("changes, field, fragment", [
    ({"geometry": {"kind": "step", "file": "missing.step", "dirichlet": []}}, "geometry.file", "does not exist"),
    ({"geometry": {"kind": "step", "file": str(ROOT / "geometries" / "box3d.toml"), "dirichlet": []}},
     "geometry.file", "is not a .step / .stp / .iges / .igs / .brep file"),
    ({"geometry": {"kind": "step", "file": str(ROOT / "geometries" / "cad_pad.step"), "dirichlet": ["side"]}},
     "geometry.dirichlet", "allowed: back, chamfer, inner, leading, outer, slot, trailing"),
    ({"geometry": {"kind": "step", "dirichlet": []}}, "geometry.file", "must name a file"),
    ({"geometry": {"kind": "step", "file": str(ROOT / "geometries" / "cad_pad.step"), "size": [1.0]}},
     "geometry.size", "not used with geometry.kind = 'step'"),
    ({"geometry": {"kind": "pad", "size": [1.0, 0.6, 60.0, 0.1]}}, "geometry.size", "r_inner < r_outer"),
    ({"geometry": {"kind": "pin", "end": "sphere", "end_radius": 0.05}}, "geometry.end_radius", "in [a, "),
    ({"geometry": {"kind": "pin", "size": [0.1, 0.01], "end": "sphere", "end_radius": 0.1}}, "geometry.size",
     "length must exceed its cap's height"),
    ({"geometry": {"kind": "pad", "position": [1.0, 0.0]}}, "geometry.position", "only for geometry.kind = 'pin'"),
    ({"geometry": {"kind": "pad"}, "mesh": {"maxh": 2.0}}, "mesh.maxh", "in (0, 1.0]"),
])
def test_part_keys_are_validated(changes, field, fragment):
    base = on_disc({"kind": "pad"}, 0.1).to_dict()
    for section, table in changes.items():
        base[section] = table
    with pytest.raises(SceneError) as info:
        Scene.from_dict(base)
    message = str(info.value)
    assert message.startswith(f"{field}:") and fragment in message and "\n" not in message, message


def test_a_file_without_a_contact_face_is_refused(tmp_path):
    shape = Box(Pnt(0, 0, 0), Pnt(1, 1, 1))
    shape.faces.Min(Z).name = "bottom"
    shape.WriteStep(str(tmp_path / "part.step"))
    (tmp_path / "part.toml").write_text('[geometry]\nkind = "step"\nfile = "part.step"\ndirichlet = ["bottom"]\n')
    with pytest.raises(SceneError, match=r"^geometry\.file: part\.step has no boundary named 'contact'"):
        ngwear.load_scene(tmp_path / "part.toml")
