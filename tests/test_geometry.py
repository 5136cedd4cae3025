"""Meshes: named regions and boundaries, and a failed (partial) Netgen meshing is an error, not a silent mesh."""
import ngsolve as ngs
import pytest

from ngwear import SceneError
from ngwear.model.geometry import _check_complete, build_mesh


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
