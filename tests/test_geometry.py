"""Meshes: named regions and boundaries, and a failed (partial) Netgen meshing is an error, not a silent mesh."""
import ngsolve as ngs
import pytest

from ngwear import SceneError
from ngwear.model.geometry import _check_complete, build_mesh


def test_regions_and_boundaries(paper_scene):
    mesh = build_mesh(paper_scene.replace(**{"mesh.maxh": 0.3}))
    assert set(mesh.GetMaterials()) == {"body", "layer"}
    assert {"left", "right", "top", "contact", "foundation"} <= set(mesh.GetBoundaries())
    layer = ngs.Integrate(ngs.CF(1.0), mesh, definedon=mesh.Materials("layer"))
    assert layer == pytest.approx(3.0 * paper_scene.contact.gap)


def test_partial_mesh_is_rejected(paper_scene):
    mesh = build_mesh(paper_scene.replace(**{"mesh.maxh": 0.3}))
    _check_complete(mesh, 3.0 * 1.2)
    with pytest.raises(SceneError, match="meshed only 50.0%"):
        _check_complete(mesh, 2 * 3.0 * 1.2)
