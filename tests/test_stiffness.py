"""The stiffness from gradient blocks (ngwear.numerics.stiffness) is NGSolve's symbolic form of the same laws.

K_(i,k) = Σ_r Σ_ab C^r_iakb S^r_ab must equal the assembled ∫ C_ijkl ∂_l u_k ∂_j v_i dx to round-off for every
kind of linear law (isotropic, transversely isotropic about a tilted axis, anisotropic), in 2D and 3D, P1 (its blocks
summed in NumPy from the element arrays) and P2, on parts of one region and of two.
"""
import numpy as np
import pytest
import scipy.sparse as sp

import ngwear
from ngwear.model.materials import region_laws
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.forms import elastic_form
from ngwear.numerics.stiffness import GradientBlocks, assembled

TILTED = {"law": "transversely_isotropic", "young_plane": 2.0, "young_axis": 1.0, "poisson_plane": 0.3,
          "poisson_axis": 0.2, "shear_axis": 0.4, "axis": [0.3, 0.4, 0.866]}
CASES = {
    "strip-P1": ("paper_strip", {"mesh.maxh": 0.3}),
    "strip-P1-backed": ("paper_strip", {"mesh.maxh": 0.3, "geometry.backing": 0.2,
                                        "material.regions": {"backing": {"young": 50.0, "poisson": 0.3}}}),
    "strip-P2-backed": ("paper_strip", {"mesh.maxh": 0.4, "mesh.order": 2, "geometry.backing": 0.2,
                                        "material.regions": {"backing": {"young": 50.0, "poisson": 0.3}}}),
    "box-P1-tilted": ("box3d", {"mesh.maxh": 0.25, "material": TILTED}),
    "box-P2-backed": ("box3d", {"mesh.maxh": 0.4, "mesh.order": 2, "geometry.backing": 0.25, "material": {
        **TILTED, "regions": {"backing": {"law": "linear", "young": 50.0, "poisson": 0.3}}}}),
}


@pytest.mark.parametrize("name", list(CASES))
def test_the_blocks_give_ngsolves_stiffness(name):
    scene_name, changes = CASES[name]
    scene = ngwear.load_scene(scene_name).replace(**changes)
    disc = Discretization(scene)
    laws = region_laws(scene)
    assert len(laws) == (2 if "backed" in name else 1)
    expected = assembled(elastic_form(disc.fes, laws))
    blocks = GradientBlocks(disc.fes)
    assert blocks.vertex_p1 == ("P1" in name)                   # P1: summed from the element arrays, not NGSolve
    K = blocks.stiffness(laws)
    assert abs(K - expected).max() <= 1e-13 * abs(expected).max()
    assert abs(K - K.T).max() <= 1e-13 * abs(expected).max()
    assert disc.elastic.stiffness.nnz and abs(disc.elastic.stiffness - expected).max() <= 1e-13 * abs(expected).max()


def test_a_material_change_reuses_the_blocks():
    """Twice the Lamé constants: the discretization keeps the body, so its blocks, and K doubles."""
    scene = ngwear.load_scene("box3d").replace(**{"mesh.maxh": 0.3})
    disc = Discretization(scene)
    K = disc.elastic.stiffness
    blocks = disc.body.gradient_blocks
    lam, mu = scene.material.lame
    stiffer = disc.with_scene(scene.replace(**{"material.lame_lambda": 2 * lam, "material.lame_mu": 2 * mu}))
    assert stiffer.body.gradient_blocks is blocks
    assert abs(stiffer.elastic.stiffness - 2 * K).max() <= 1e-13 * abs(K).max()
    assert isinstance(stiffer.elastic.stiffness, sp.csr_matrix) and np.isfinite(stiffer.elastic.stiffness.data).all()


@pytest.mark.parametrize("name", ["strip-P2-backed", "box-P1-tilted"])
def test_the_taskmanager_assembles_the_same_matrix_to_the_bit(name, monkeypatch):
    """A large form's threads (forced here on a small one) sum each entry as one thread does."""
    from ngwear.numerics import stiffness

    scene_name, changes = CASES[name]
    disc = Discretization(ngwear.load_scene(scene_name).replace(**changes))
    laws = region_laws(disc.scene)
    one = assembled(elastic_form(disc.fes, laws))
    monkeypatch.setattr(stiffness, "PARALLEL", 0)
    threaded = assembled(elastic_form(disc.fes, laws))
    assert np.array_equal(one.indptr, threaded.indptr) and np.array_equal(one.indices, threaded.indices)
    assert np.array_equal(one.data, threaded.data)
