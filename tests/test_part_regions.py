"""Regions of the user's parts: a STEP/BREP file's named solids, a mesh file's materials, shapes and meshes from Python.

The solid (material) that carries the face ``contact`` is the region ``body``, the others keep their names; solids
that only touch in the file are glued on reading, so a column of two solids is the series of its springs, exactly
as the built-in backing (tests/test_regions.py).
"""
import json
from pathlib import Path

import ngsolve as ngs
import pytest
from conftest import ROOT
from netgen.occ import Box, Compound, Glue, Pnt, Z
from test_cli import assert_one_line_error, ngwear
from test_regions import COLUMN

import ngwear as ng
from ngwear.model.part_files import describe
from ngwear.model.scene_mesh import build_mesh
from ngwear.model.user_parts import read_shape

SIGMA, T1, E1, L = 0.02 / 0.01, 0.3, 2e3, 5e3         # COLUMN: 0.02 N on 0.1 × 0.1, t₁ = 0.3, E₁ = 2e3, L = 5e3


def column_shape(backing: float, glued: bool, names=("lining", "plate")):
    """A friction column (its bottom ``contact``) on a plate (its top ``top``): two named solids."""
    lining, plate = Box(Pnt(0, 0, 0), Pnt(0.1, 0.1, T1)), Box(Pnt(0, 0, T1), Pnt(0.1, 0.1, T1 + backing))
    lining.faces.Min(Z).name, plate.faces.Max(Z).name = "contact", "top"
    lining.solids.name, plate.solids.name = names
    return Glue([lining, plate]) if glued else Compound([lining, plate])


def column_scene(geometry: dict, young: float) -> ng.Scene:
    """COLUMN on a part of ``geometry`` whose region ``plate`` has Young's modulus ``young``."""
    mesh = {} if geometry.get("kind") == "mesh" or "shape" in geometry and not hasattr(geometry["shape"], "solids") \
        else {"maxh": 0.1}
    return ng.Scene.from_dict({**COLUMN, "geometry": {"dirichlet": [], **geometry}, "mesh": mesh,
                               "material": {"young": E1, "poisson": 0.0, "regions": {"plate": {"young": young}}}})


def series(backing: float, young: float) -> float:
    """δ = σ (t₁/E₁ + t₂/E₂ + 1/L): uniaxial stress, ν = 0, no friction (exact for P1)."""
    return SIGMA * (T1 / E1 + backing / young + 1 / L)


@pytest.mark.parametrize("glued", [True, False], ids=["glued", "touching"])
def test_step_column_of_two_named_solids_is_the_series_of_its_springs(tmp_path, glued):
    """Named solids are regions, the contact solid is ``body``; solids that only touch are glued on reading."""
    backing, young = 0.2, 1e3
    column_shape(backing, glued).WriteStep(str(tmp_path / "column.step"))
    scene = column_scene({"kind": "step", "file": str(tmp_path / "column.step")}, young)
    assert scene.geometry.regions == ("body", "plate")
    result = ng.simulate(scene, progress=False)
    assert set(result.discretization.mesh.GetMaterials()) == {"body", "plate"}
    assert result.plate_displacement[-1, 0] == pytest.approx(series(backing, young), rel=1e-10)


def test_mesh_file_materials_and_python_meshes_and_shapes_keep_their_regions(tmp_path):
    """A .vol's materials are regions (its contact one renamed ``body``); a mesh or shape given in Python too."""
    backing, young = 0.05, 1e4
    shape = column_shape(backing, glued=True)
    step = column_scene({"kind": "step", "file": _written(shape, tmp_path / "column.step")}, young)
    ngmesh = build_mesh(step).ngmesh
    for index in range(1, ngmesh.GetNDomains() + 1):                 # the materials as the CAD system named them
        if ngmesh.GetMaterial(index) == "body":
            ngmesh.SetMaterial(index, "lining")
    ngmesh.Save(str(tmp_path / "column.vol"))
    runs = {"vol": column_scene({"kind": "mesh", "file": str(tmp_path / "column.vol")}, young),
            "mesh": column_scene({"shape": ngs.Mesh(ngmesh)}, young),
            "shape": column_scene({"shape": shape}, young)}
    for how, scene in runs.items():
        assert scene.geometry.regions == ("body", "plate"), how
        result = ng.simulate(scene, progress=False)
        assert result.plate_displacement[-1, 0] == pytest.approx(series(backing, young), rel=1e-10), how
    sidecar = json.loads(Path(f"{runs['shape'].geometry.file}.names.json").read_text())
    assert sidecar["solids"] == ["lining", "plate"]             # BREP has no names: the sidecar keeps them


def _written(shape, path) -> str:
    shape.WriteStep(str(path))
    return str(path)


def test_a_brep_sidecar_of_face_names_only_is_still_read(tmp_path):
    """The sidecar before solids had names: a plain list of face names; the solids are then the body."""
    shape = column_shape(0.1, glued=True)
    shape.WriteBrep(str(tmp_path / "column.brep"))
    (tmp_path / "column.brep.names.json").write_text(json.dumps([face.name for face in shape.faces]))
    part = describe(str(tmp_path / "column.brep"), "step")
    assert part.regions == ("body",) and {"contact", "top"} <= set(part.boundaries)
    assert {s.name for s in read_shape(str(tmp_path / "column.brep")).solids} <= {None, ""}


def test_cad_pad_backed_has_the_friction_block_and_the_steel_plate():
    """cad_pad_backed.step: solid ``friction`` (carries contact) → ``body``, ``steel`` kept; volumes are the solids'."""
    scene = ng.load_scene(ROOT / "geometries" / "cad_pad_backed.toml")
    assert scene.geometry.regions == ("body", "steel")
    shape = read_shape(scene.geometry.file)
    assert [s.name for s in shape.solids] == ["friction", "steel"]
    mesh = build_mesh(scene)
    for region, solid in zip(("body", "steel"), shape.solids):      # straight-sided elements under the arcs
        assert ngs.Integrate(1, mesh, definedon=mesh.Materials(region)) == pytest.approx(solid.mass, rel=3e-3)
    inside = [f for f in shape.faces if not f.name]
    assert len({round(f.mass, 12) for f in inside}) == 1        # one shared face (listed by each solid)
    interface = ngs.Integrate(1, mesh, ngs.BND, definedon=mesh.Boundaries("default"))
    assert interface == pytest.approx(inside[0].mass, rel=3e-3)
    assert scene.material.regions["steel"].young == 210e9
    back = ngs.Integrate(ngs.z * ngs.ds("back"), mesh) / ngs.Integrate(ngs.CF(1.0) * ngs.ds("back"), mesh)
    assert back == pytest.approx(0.012 + 0.0055, rel=1e-12)       # the caliper presses the steel plate


def test_an_unknown_region_of_a_cad_part_is_one_line(tmp_path):
    scene = ROOT / "geometries" / "cad_pad_backed.toml"
    with pytest.raises(ng.SceneError) as info:
        ng.load_scene(scene).replace(**{"material.regions": {"backing": {"young": 1e9, "poisson": 0.3}}})
    assert str(info.value) == "material.regions.backing: unknown region (the part's regions: body, steel)"
    proc = ngwear("run", scene, "--set", "material.regions.friction.young=1e9", "--quiet", "--out", tmp_path / "o",
                  cwd=tmp_path)
    assert_one_line_error(proc, "material.regions.friction")
    assert "unknown region (the part's regions: body, steel)" in proc.stderr


def test_a_solid_apart_from_the_rest_is_one_line(tmp_path):
    """A lining that does not touch its plate floats (K is singular): refused naming geometry.file, not PARDISO's error."""
    lining, plate = Box(Pnt(0, 0, 0), Pnt(0.1, 0.1, T1)), Box(Pnt(0, 0, T1 + 0.1), Pnt(0.1, 0.1, T1 + 0.2))
    lining.faces.Min(Z).name, lining.faces.Max(Z).name, plate.faces.Max(Z).name = "contact", "lid", "top"
    lining.solids.name, plate.solids.name = "lining", "plate"
    scene = column_scene({"kind": "step", "file": _written(Compound([lining, plate]), tmp_path / "apart.step")}, 1e3)
    with pytest.raises(ng.SceneError) as info:
        ng.simulate(scene, progress=False)
    assert str(info.value).startswith("geometry.file: the part falls apart: region body is held by neither "
                                      "geometry.dirichlet nor loads.plate")
    held = scene.replace(**{"geometry.dirichlet": ["lid"]})          # each piece held: the mesh is accepted
    assert set(build_mesh(held).GetMaterials()) == {"body", "plate"}
