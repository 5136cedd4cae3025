"""The compaction law's kink as sparse algebra, and the low-rank update of a factorised K (ngwear.numerics.kink).

F(u) = K_lin u + Dᵀ(c ∘ min(Du, 0)) must be NGSolve's symbolic ``Apply`` of the law to round-off (P1: tr ε is
constant on an element), its tangent NGSolve's ``tangent_form``; Woodbury's update of a factorisation must solve
with the tangent as a fresh factorisation of it does; and a run that updates must agree with one that refactorises.
"""
import ngsolve as ngs
import numpy as np
import pytest
import scipy.sparse as sp

import ngwear
from ngwear.numerics import elastic
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.forms import elastic_integrand, tangent_form
from ngwear.numerics.kink import Kink, kinked
from ngwear.numerics.operators import ElasticOperator, UpdatedOperator

BACKED = {"mesh.maxh": 0.25, "geometry.backing": 0.25, "material": {
    "law": "compaction", "lame_lambda": 1.0, "lame_mu": 1.0, "compaction_modulus": 100.0,
    "regions": {"backing": {"law": "linear", "young": 50.0, "poisson": 0.3}}}}


@pytest.fixture(scope="module")
def disc():
    return Discretization(ngwear.load_scene("box3d").replace(**BACKED))


def strained(disc, seed=0):
    """A displacement whose strain has both signs of tr ε over the body (about half the points compressed)."""
    return 0.01 * np.random.default_rng(seed).standard_normal(disc.fes.ndof) * disc.body.free


def as_csr(form, n):
    form.Assemble()
    vals, cols, ptr = form.mat.CSR()
    return sp.csr_matrix((np.array(vals), np.array(cols), np.array(ptr)), shape=(n, n))


def test_the_kink_is_ngsolves_symbolic_law_to_round_off(disc):
    elastic, u = disc.elastic, strained(disc)
    assert elastic.kink is not None and 0.2 < elastic.kink.compressed(u).mean() < 0.8
    form = ngs.BilinearForm(elastic_integrand(disc.fes, elastic.laws))
    gf, out = disc.gridfunction(u), ngs.GridFunction(disc.fes)
    form.Apply(gf.vec, out.vec)
    reference = out.vec.FV().NumPy()
    assert np.abs(elastic.forces(u) - reference).max() <= 1e-13 * np.abs(reference).max()
    tangent = as_csr(tangent_form(disc.fes, elastic.laws, gf), disc.fes.ndof)
    tangent = tangent + sp.triu(tangent, 1).T if sp.tril(tangent, -1).nnz == 0 else tangent
    kinked_tangent = disc.tangent(u).elastic.stiffness
    assert abs(kinked_tangent - tangent).max() <= 1e-12 * abs(tangent).max()


def test_only_p1_compaction_is_kinked():
    scene = ngwear.load_scene("box3d").replace(**BACKED)
    mesh = Discretization(scene).mesh
    laws = Discretization(scene, mesh).elastic.laws
    assert kinked(ngs.VectorH1(mesh, order=1), laws)
    assert not kinked(ngs.VectorH1(mesh, order=2), laws)          # tr ε varies on an element: NGSolve's rule
    assert Kink(ngs.VectorH1(mesh, order=1), laws).D.shape[0] == sum(
        1 for el in mesh.Elements(ngs.VOL) if el.mat == "body")  # one point per element of the compaction region


@pytest.mark.parametrize("schur", [False, True], ids=["plain", "schur"])
def test_the_updated_factorisation_solves_as_a_new_one(disc, schur):
    kink, body = disc.elastic.kink, disc.body
    K = disc.elastic.stiffness
    base = ElasticOperator(K, body.free, body.contact_dofs, schur=schur)
    branches = kink.compressed(strained(disc, 1))
    flipped = np.flatnonzero(~branches)[:7]
    delta = -kink.c[flipped]                                # seven points leave the compressed branch
    updated = UpdatedOperator(base, kink.D[flipped], delta, {}, flipped)
    K_t = K + kink.D[flipped].T @ sp.diags(delta) @ kink.D[flipped]
    fresh = ElasticOperator(sp.csr_matrix(K_t), body.free, body.contact_dofs, schur=schur)
    rhs = np.random.default_rng(2).standard_normal((disc.fes.ndof, 3))
    expected = fresh.solve(rhs)
    assert np.abs(updated.solve(rhs) - expected).max() <= 1e-9 * np.abs(expected).max()
    assert np.abs(updated.solve(rhs) - base.solve(rhs)).max() > 1e-3 * np.abs(expected).max()   # it did change
    if schur:
        r = rhs[base.contact_dofs]
        assert np.allclose(updated.contact_solve(r), fresh.contact_solve(r), rtol=0, atol=1e-9 * np.abs(
            fresh.contact_solve(r)).max())


def test_a_run_that_updates_agrees_with_one_that_refactorises(monkeypatch):
    """The shipped compaction pad at β = 100η (the kink moves): most tangents are updates, the result the same."""
    scene = ngwear.load_scene("brake_pad_compaction").replace(**{"mesh.maxh": 0.006, "time.steps": 12,
                                                                  "material.compaction_modulus": 4.0e10})
    mesh = Discretization(scene).mesh
    built = {ElasticOperator: 0, UpdatedOperator: 0}
    for cls in built:
        monkeypatch.setattr(cls, "__init__", counted(cls.__init__, cls, built))
    updated = ngwear.simulate(scene, discretization=Discretization(scene, mesh), progress=False)
    assert built[UpdatedOperator] > built[ElasticOperator] > 1
    monkeypatch.setattr(elastic, "LOW_RANK", -1)          # every tangent factorised
    refactorised = ngwear.simulate(scene, discretization=Discretization(scene, mesh), progress=False)
    assert updated.status == refactorised.status == "completed"
    tolerance = 10 * scene.solver.tolerance
    assert np.abs(updated.wear - refactorised.wear).max() <= tolerance * np.abs(refactorised.wear).max()
    assert np.abs(updated.pressure - refactorised.pressure).max() <= tolerance * np.abs(refactorised.pressure).max()


def counted(init, cls, built):
    def wrapper(self, *args, **kwargs):
        built[cls] += 1
        init(self, *args, **kwargs)
    return wrapper
