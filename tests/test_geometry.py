"""Meshes: named regions and boundaries; a failed (partial) Netgen meshing is an error; a child meshes as this process."""
import ngsolve as ngs
import pytest

from ngwear import SceneError
from ngwear.model import netgen_meshing as meshing
from ngwear.model.scene_mesh import _check_complete, build_mesh


def test_regions_and_boundaries(paper_scene):
    mesh = build_mesh(paper_scene.replace(**{"mesh.maxh": 0.3}))
    assert set(mesh.GetMaterials()) == {"body"}
    assert set(mesh.GetBoundaries()) == {"left", "right", "top", "contact"}
    assert ngs.Integrate(ngs.CF(1.0), mesh) == pytest.approx(3.0)
    length = ngs.Integrate(ngs.CF(1.0), mesh, definedon=mesh.Boundaries("contact"))
    assert length == pytest.approx(3.0)


def test_partial_mesh_is_rejected(paper_scene):
    mesh = build_mesh(paper_scene.replace(**{"mesh.maxh": 0.3}))
    _check_complete(mesh, 3.0)
    with pytest.raises(SceneError, match="meshed only 50.0%"):
        _check_complete(mesh, 2 * 3.0)


def test_a_mesh_made_in_a_child_is_the_mesh_made_here(paper_scene, tmp_path, monkeypatch):
    """Above meshing.IN_PROCESS the child writes the same file; a refined zone's SceneError there is one here."""
    scene = paper_scene.replace(**{"mesh.maxh": 0.1})
    shape = meshing.part(scene.geometry, scene.mesh)
    meshing.generate(scene, shape, tmp_path / "here.vol")
    monkeypatch.setattr(meshing, "IN_PROCESS", 0)
    meshing.generate(scene, shape, tmp_path / "child.vol")
    assert (tmp_path / "child.vol").read_bytes() == (tmp_path / "here.vol").read_bytes()
    away = scene.replace(**{"mesh.contact_maxh": 0.02, "mesh.contact_zone": 0.1, "mesh.zone_center": [50.0, 0.0]})
    with pytest.raises(SceneError, match=r"^mesh\.zone_center: no point of Γ_C within mesh\.contact_zone = 0\.1 "):
        meshing.generate(away, meshing.part(away.geometry, away.mesh), tmp_path / "away.vol")
