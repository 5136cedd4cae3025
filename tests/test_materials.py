"""Elasticity laws: Hooke as today, transversely isotropic constants, rotation and positive definiteness.

Also the compaction law's linearisation (Taylor tests), its H(F) constants, and a user's energy differentiated by
NGSolve.
"""
import logging

import ngsolve as ngs
import numpy as np
import pytest
from netgen.occ import Box, OCCGeometry, Pnt, Rectangle, X, Y, Z

from ngwear.model import mandel
from ngwear.model.materials import Anisotropic, Compaction, Energy, Isotropic, TransverselyIsotropic, strain
from ngwear.model.moduli import Moduli, estimate_moduli, stress_at, tangent_at, tangent_values
from ngwear.model.scene import SceneError
from ngwear.numerics.forms import tangent_form

LAM, ETA, BETA = 2.0, 1.5, 10.0
PAD = dict(young_plane=4.0, young_axis=2.0, poisson_plane=0.25, poisson_axis=0.15, shear_axis=1.0)  # E_p = 2 E_a


def body_mesh(dim, maxh):
    shape = Rectangle(1, 1).Face() if dim == 2 else Box(Pnt(0, 0, 0), Pnt(1, 1, 1))
    shape.faces.name = "body" if dim == 2 else None
    if dim == 3:
        shape.solids.name = "body"
    return ngs.Mesh(OCCGeometry(shape, dim=dim).GenerateMesh(maxh=maxh))


@pytest.fixture(scope="module", params=[2, 3])
def field(request):
    """A smooth displacement on the unit square / cube whose trace of strain changes sign (P2)."""
    dim = request.param
    mesh = body_mesh(dim, 0.25 if dim == 2 else 0.5)
    fes = ngs.VectorH1(mesh, order=2)
    gfu = ngs.GridFunction(fes)
    X = (ngs.x, ngs.y, ngs.z)[:dim]
    gfu.Set(ngs.CF(tuple(0.3 * (X[i] - 0.5) ** 2 * (1 + i) - 0.1 * X[(i + 1) % dim] + 0.05 * ngs.sin(3 * X[i])
                         for i in range(dim))))
    return mesh, fes, gfu


def values(cf, mesh, order=2):
    types = (ngs.TRIG,) if mesh.dim == 2 else (ngs.TET,)
    return np.asarray(cf(mesh.MapToAllElements({t: ngs.IntegrationRule(t, order) for t in types}, ngs.VOL)))


def symmetric(rng, n, d):
    a = rng.standard_normal((n, d, d))
    return 0.5 * (a + a.transpose(0, 2, 1))


def stiffness_tensor(C_M):
    """The 4th-order tensor C_ijkl of a Mandel matrix (independent of :mod:`ngwear.model.mandel`'s rotation)."""
    d = {3: 2, 6: 3}[len(C_M)]
    pairs = mandel.PAIRS[d]
    w = [1.0 if i == j else np.sqrt(2) for i, j in pairs]
    C = np.zeros((d,) * 4)
    for a, (i, j) in enumerate(pairs):
        for b, (k, m) in enumerate(pairs):
            for p, q in {(i, j), (j, i)}:
                for r, s in {(k, m), (m, k)}:
                    C[p, q, r, s] = C_M[a, b] / (w[a] * w[b])
    return C


# ---------------------------------------------------------------- linear laws


def hooke(eps, dim):
    """Hooke's law as ngwear wrote it before the laws: σ = 2η ε + λ tr(ε) I."""
    return 2 * ETA * eps + LAM * ngs.Trace(eps) * ngs.Id(dim)


def test_isotropic_is_todays_hooke(field):
    mesh, fes, gfu = field
    dim = mesh.dim
    law = Isotropic(LAM, ETA, dim)
    eps = strain(gfu)
    today = values(hooke(eps, dim), mesh)
    scale = np.abs(today).max()
    assert np.abs(values(law.stress(eps), mesh) - today).max() < 1e-14 * scale
    mandel_path = Anisotropic(tuple(map(tuple, law.matrix)))        # what every other linear law computes
    assert np.abs(values(mandel_path.stress(eps), mesh) - today).max() < 1e-14 * scale
    u, v = fes.TnT()
    ours = ngs.BilinearForm(law.elastic_integrand(u, v) * ngs.dx).Assemble().mat
    theirs = ngs.BilinearForm(ngs.InnerProduct(hooke(strain(u), dim), strain(v)) * ngs.dx).Assemble().mat
    a, b = ours.CSR(), theirs.CSR()
    diff = np.abs((sp_matrix(a) - sp_matrix(b)).toarray()).max()
    assert diff < 1e-13 * np.abs(sp_matrix(b).toarray()).max()
    assert law.is_linear and law.tangent_at_zero() is law
    assert law.monotonicity == pytest.approx(2 * ETA, rel=1e-14)
    assert law.lipschitz == pytest.approx(2 * ETA + dim * LAM, rel=1e-14)


def sp_matrix(csr):
    import scipy.sparse as sp
    data, cols, rows = csr
    return sp.csr_matrix((np.array(data), np.array(cols), np.array(rows)))


@pytest.mark.parametrize("axis", [(0, 0, 1), (1, 2, 3), (0.3, -1, 0.2), (1, 0), (0.6, -0.8)])
def test_transversely_isotropic_with_isotropic_constants_is_isotropic(axis):
    E, nu = 3.0, 0.3
    ti = TransverselyIsotropic(E, E, nu, nu, E / (2 * (1 + nu)), axis)
    iso = Isotropic(E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu)), len(axis))
    assert np.abs(ti.matrix - iso.matrix).max() < 1e-14 * np.abs(iso.matrix).max()


@pytest.mark.parametrize("axis", [(0, 0, 1), (1, 2, 3), (-0.3, 0.1, 0.9)])
def test_uniaxial_and_shear_stress_recover_the_five_constants(axis):
    """Homogeneous states: ε = C⁻¹ σ for uniaxial stress along the axis and across it, and for shear."""
    law = TransverselyIsotropic(**PAD, axis=axis)
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    e = np.cross(a, [1.0, 0, 0] if abs(a[0]) < 0.9 else [0, 1.0, 0])
    e /= np.linalg.norm(e)
    f = np.cross(a, e)
    S = np.linalg.inv(law.matrix)

    def strain_of(sigma):
        return mandel.from_mandel(S @ mandel.to_mandel(sigma))

    s = -0.7
    eps = strain_of(s * np.outer(a, a))                                             # along the axis
    assert a @ eps @ a == pytest.approx(s / PAD["young_axis"], rel=1e-13)
    for t in (e, f, (e + f) / np.sqrt(2)):
        assert t @ eps @ t == pytest.approx(-PAD["poisson_axis"] * s / PAD["young_axis"], rel=1e-12)
    eps = strain_of(s * np.outer(e, e))                                             # across it
    assert e @ eps @ e == pytest.approx(s / PAD["young_plane"], rel=1e-13)
    assert f @ eps @ f == pytest.approx(-PAD["poisson_plane"] * s / PAD["young_plane"], rel=1e-12)
    nu_pa = PAD["poisson_axis"] * PAD["young_plane"] / PAD["young_axis"]
    assert a @ eps @ a == pytest.approx(-nu_pa * s / PAD["young_plane"], rel=1e-12)
    tau = 0.4
    eps = strain_of(tau * (np.outer(a, e) + np.outer(e, a)))                        # shear in a plane with the axis
    assert a @ eps @ e == pytest.approx(tau / (2 * PAD["shear_axis"]), rel=1e-13)
    eps = strain_of(tau * (np.outer(e, f) + np.outer(f, e)))                        # shear in the isotropic plane
    assert e @ eps @ f == pytest.approx(tau * (1 + PAD["poisson_plane"]) / PAD["young_plane"], rel=1e-13)


def test_plane_strain_along_the_axis_has_the_closed_form_modulus():
    """2D, axis in the plane: ε_zz = 0 gives σ_yy/ε_yy = E_a / (1 − ν_ap² E_p / E_a) under uniaxial σ_yy."""
    law = TransverselyIsotropic(**PAD, axis=(0, 1))
    S = np.linalg.inv(law.matrix)
    eps = mandel.from_mandel(S @ mandel.to_mandel(np.diag([0.0, 1.0])))
    Ea, Ep, nu = PAD["young_axis"], PAD["young_plane"], PAD["poisson_axis"]
    assert 1 / eps[1, 1] == pytest.approx(Ea / (1 - nu ** 2 * Ep / Ea), rel=1e-13)


@pytest.mark.parametrize("along_axis", [True, False])
def test_column_compressed_along_and_across_the_axis_recovers_the_young_moduli(along_axis):
    """A 1 × 1 × 2 column on rollers pressed by a traction s on its top: E and ν from its displacements.

    Top displacement s H / E, lateral contraction −ν s W / E, exact for P1 (the stress is uniaxial and homogeneous).
    """
    axis = (0, 0, 1) if along_axis else (1, 0, 0)
    law = TransverselyIsotropic(**PAD, axis=axis)
    shape = Box(Pnt(0, 0, 0), Pnt(1, 1, 2))
    shape.faces.Min(Z).name, shape.faces.Max(Z).name = "bottom", "top"
    shape.faces.Min(X).name, shape.faces.Min(Y).name = "left", "front"
    mesh = ngs.Mesh(OCCGeometry(shape).GenerateMesh(maxh=0.6))
    fes = ngs.VectorH1(mesh, order=1, dirichletz="bottom", dirichletx="left", dirichlety="front")
    u, v = fes.TnT()
    a = ngs.BilinearForm(law.elastic_integrand(u, v) * ngs.dx).Assemble()
    s = -0.3
    f = ngs.LinearForm(s * v[2] * ngs.ds("top")).Assemble()
    gfu = ngs.GridFunction(fes)
    gfu.vec.data = a.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky") * f.vec
    Ep, Ea, nu_p, nu_ap = PAD["young_plane"], PAD["young_axis"], PAD["poisson_plane"], PAD["poisson_axis"]
    if along_axis:      # z is the axis: x and y lie in the isotropic plane
        E, nu_x, nu_y = Ea, nu_ap, nu_ap
    else:               # x is the axis, y and z lie in the plane: ν_pa = ν_ap E_p / E_a towards the axis
        E, nu_x, nu_y = Ep, nu_ap * Ep / Ea, nu_p
    top = gfu(mesh(0.5, 0.5, 2.0))
    assert top[2] == pytest.approx(s * 2 / E, rel=1e-10)
    corner = gfu(mesh(1.0, 1.0, 1.0))
    assert corner[0] == pytest.approx(-nu_x * s / E, rel=1e-9)
    assert corner[1] == pytest.approx(-nu_y * s / E, rel=1e-9)


@pytest.mark.parametrize("axis", [(1, 2, 3), (-0.5, 0.2, 0.1), (0.6, -0.8)])
def test_a_rotated_axis_rotates_the_stiffness_as_a_fourth_order_tensor(axis):
    d = len(axis)
    base = TransverselyIsotropic(**PAD, axis=(0, 0, 1) if d == 3 else (1, 0))
    turned = TransverselyIsotropic(**PAD, axis=axis)
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    if d == 3:   # Rodrigues: the rotation taking e₃ to a
        k = np.cross([0, 0, 1.0], a)
        K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        R = np.eye(3) + K + K @ K / (1 + a[2])
    else:
        R = np.array([[a[0], -a[1]], [a[1], a[0]]])
    expected = np.einsum("ia,jb,kc,ld,abcd->ijkl", R, R, R, R, stiffness_tensor(base.matrix))
    got = stiffness_tensor(turned.matrix)
    assert np.abs(got - expected).max() < 1e-13 * np.abs(expected).max()


def test_positive_definiteness_is_refused_with_the_key_and_the_closed_form():
    with pytest.raises(SceneError) as err:
        TransverselyIsotropic(**{**PAD, "poisson_plane": 1.2}, axis=(0, 0, 1))
    assert str(err.value) == "material.poisson_plane: the stiffness is not positive definite: need |ν_p| < 1 " \
                             "(got ν_p = 1.2)"
    with pytest.raises(SceneError) as err:   # bound sqrt(0.75 · 2 / 8) = 0.4330
        TransverselyIsotropic(**{**PAD, "poisson_axis": -0.45}, axis=(0, 0, 1), key="material.regions.pad")
    assert str(err.value) == "material.regions.pad.poisson_axis: the stiffness is not positive definite: need " \
                             "|ν_ap| < sqrt((1 − ν_p) E_a / (2 E_p)) = 0.433013 (got ν_ap = -0.45)"
    for name in ("young_plane", "young_axis", "shear_axis"):
        with pytest.raises(SceneError, match=rf"^material.{name}: must be > 0 \(got -1.0\)$"):
            TransverselyIsotropic(**{**PAD, name: -1.0}, axis=(0, 0, 1))
    with pytest.raises(SceneError, match=r"^material.axis: must be a non-zero vector of 2 \(2D\) or 3 \(3D\) numbers"):
        TransverselyIsotropic(**PAD, axis=(0, 0, 0))
    with pytest.raises(SceneError, match=r"^material.lame_lambda: the stiffness is not positive definite: need "
                                         r"λ > −2η/3 = -1 \(got λ = -1.2\)$"):
        Isotropic(-1.2, 1.5, 3)
    with pytest.raises(SceneError, match=r"^material.lame_mu: must be > 0 \(got 0.0\)$"):
        Compaction(1.0, 0.0, 1.0, 2)
    with pytest.raises(SceneError, match=r"^material.compaction_modulus: must be >= 0 \(got -1.0\)$"):
        Compaction(1.0, 1.0, -1.0, 2)
    with pytest.raises(SceneError, match=r"^material.stiffness: not positive definite \(smallest eigenvalue -1\)$"):
        Anisotropic(((1.0, 0, 0), (0, 1.0, 0), (0, 0, -1.0)))


def test_the_closed_form_conditions_are_exactly_positive_definiteness():
    """Random constants: accepted iff the compliance S (built here independently) has positive eigenvalues."""
    rng = np.random.default_rng(5)
    accepted = refused = 0
    for _ in range(400):
        Ep, Ea, Ga = rng.uniform(0.2, 5, 3)
        nu_p, nu_ap = rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2)
        S = np.zeros((6, 6))
        S[:3, :3] = [[1 / Ep, -nu_p / Ep, -nu_ap / Ea], [-nu_p / Ep, 1 / Ep, -nu_ap / Ea], [-nu_ap / Ea, -nu_ap / Ea,
                                                                                               1 / Ea]]
        S[3, 3] = S[4, 4] = 1 / (2 * Ga)
        S[5, 5] = (1 + nu_p) / Ep
        pd = np.linalg.eigvalsh(S)[0] > 0
        try:
            law = TransverselyIsotropic(Ep, Ea, nu_p, nu_ap, Ga, tuple(rng.standard_normal(3)))
        except SceneError:
            refused += 1
            assert not pd
        else:
            accepted += 1
            assert pd and np.linalg.eigvalsh(law.matrix)[0] > 0
    assert accepted > 50 and refused > 50


# ---------------------------------------------------------------- compaction: Taylor tests


def residual_form(law, fes):
    u, v = fes.TnT()
    return ngs.BilinearForm(law.elastic_integrand(u, v) * ngs.dx)


def function(fes, cf):
    gf = ngs.GridFunction(fes)
    gf.Set(cf)
    return gf


def remainders(form, u, w, steps):
    """d(ε) = R(u + εw) − R(u) − ε J(u) w for each ε: its norm ‖d‖ and ⟨d, w⟩, and ‖J w‖."""
    r0, r1, jw, shifted = (u.CreateVector() for _ in range(4))
    form.Apply(u, r0)
    form.AssembleLinearization(u)
    jw.data = form.mat * w
    norms, tested = [], []
    for eps in steps:
        shifted.data = u + float(eps) * w          # a numpy scalar times a BaseVector is not a vector
        form.Apply(shifted, r1)
        d = r1.FV().NumPy() - r0.FV().NumPy() - eps * jw.FV().NumPy()
        norms.append(np.linalg.norm(d))
        tested.append(abs(d @ w.FV().NumPy()))
    return np.array(norms), np.array(tested), np.linalg.norm(jw.FV().NumPy())


@pytest.fixture(scope="module")
def square():
    mesh = body_mesh(2, 0.04)
    return ngs.VectorH1(mesh, order=2)


def test_compaction_linearisation_is_exact_away_from_the_kink(square):
    """All points compressed (tr ε ≤ −0.1): the residual is linear there, so the Taylor remainder is round-off.

    The same test sees a tangent that forgets β (a remainder of order ε); and the central difference of
    NGSolve's test_contact.py, and Apply as the derivative of the energy, hold to 1e-10.
    """
    fes = square
    law = Compaction(LAM, ETA, BETA, 2)
    uf = function(fes, ngs.CF((-0.1 * ngs.x + 0.02 * ngs.sin(3 * ngs.y), -0.1 * ngs.y + 0.02 * ngs.cos(2 * ngs.x))))
    u = uf.vec
    wf = function(fes, ngs.CF((ngs.sin(2 * ngs.x + ngs.y), ngs.x * ngs.y ** 2)))
    w = wf.vec
    assert values(ngs.Trace(strain(uf)), fes.mesh, order=4).max() < -0.1                # away from the kink
    steps = np.array([1e-2, 1e-3, 1e-4])
    form = residual_form(law, fes)
    r, _, jw = remainders(form, u, w, steps)
    assert np.all(r <= 1e-11 * steps * jw), r / (steps * jw)
    wrong = residual_form(Isotropic(LAM, ETA, 2), fes)        # a tangent without β: J_wrong w ≠ J w
    wrong.AssembleLinearization(u)
    form.AssembleLinearization(u)
    jw_wrong = u.CreateVector()
    jw_wrong.data = wrong.mat * w
    r1, r0 = u.CreateVector(), u.CreateVector()
    form.Apply(u, r0)
    shifted = u.CreateVector()
    shifted.data = u + 1e-3 * w
    form.Apply(shifted, r1)
    miss = np.linalg.norm(r1.FV().NumPy() - r0.FV().NumPy() - 1e-3 * jw_wrong.FV().NumPy())
    assert miss > 0.5 * 1e-3 * jw                                                           # it would be seen
    eps = 1e-4                                                                              # as in test_contact.py
    ur, ul, vr, vl, d = (u.CreateVector() for _ in range(5))
    ur.data, ul.data = u + eps * w, u - eps * w
    form.Apply(ur, vr)
    form.Apply(ul, vl)
    d.data = form.mat * w
    assert (ngs.InnerProduct(vr, w) - ngs.InnerProduct(vl, w)) / 2 / eps == pytest.approx(ngs.InnerProduct(d, w),
                                                                                          rel=1e-10)
    energy = ngs.BilinearForm(fes)
    energy += ngs.Variation(law.energy(strain(fes.TrialFunction())) * ngs.dx)
    form.Apply(u, d)                                                                    # Apply = derivative of ψ
    assert (energy.Energy(ur) - energy.Energy(ul)) / 2 / eps == pytest.approx(ngs.InnerProduct(d, w), rel=1e-9)


def test_compaction_remainder_is_second_order_across_the_kink():
    """Across the kink the Taylor remainder tested against w has rate 2, its norm rate 3/2.

    tr ε(u) changes sign on a circle inside the square.  The points that cross the kink under u → u + εw lie in
    a band of measure O(ε), where the remainder is O(ε): tested against w (as test_contact.py tests ⟨·, w⟩) it is
    O(ε²); its Euclidean norm is O(ε^{3/2}).  (With too few crossing points, ε < 1e-3 here, the count is no
    longer proportional to ε; the steps stay above.)
    """
    fes = ngs.VectorH1(body_mesh(2, 0.02), order=2)
    X, Y = ngs.x - 0.45, ngs.y - 0.55
    uf = function(fes, ngs.CF((X * (X * X + Y * Y - 0.09) / 4 + 0.03 * ngs.y, Y * (X * X + Y * Y - 0.09) / 4)))
    wf = function(fes, ngs.CF((ngs.sin(2 * ngs.x + ngs.y), ngs.x * ngs.y ** 2 - ngs.y)))
    trace = values(ngs.Trace(strain(uf)), fes.mesh, order=4)             # tr ε(u) = (4 r² − 0.18)/4
    assert trace.min() < -0.04 and trace.max() > 0.5
    steps = 0.02 * 0.5 ** np.arange(5)
    norms, tested, jw = remainders(residual_form(Compaction(LAM, ETA, BETA, 2), fes), uf.vec, wf.vec, steps)
    rate = np.polyfit(np.log(steps), np.log(tested), 1)[0]
    assert 1.85 < rate < 2.15, (rate, tested)
    rate = np.polyfit(np.log(steps), np.log(norms), 1)[0]
    assert 1.35 < rate < 1.65, (rate, norms)
    assert norms[-1] > 1e-6 * steps[-1] * jw                                 # not round-off: the kink is crossed


def test_smooth_energy_remainder_has_rate_two(square):
    """A smooth nonlinear ψ through NGSolve's differentiation: the classical Taylor test, rate 2."""
    fes = square
    law = Energy(lambda e: ETA * ngs.InnerProduct(e, e) + 0.5 * LAM * ngs.Trace(e) ** 2 + ngs.Trace(e) ** 4, 2)
    uf = function(fes, ngs.CF((0.2 * (ngs.x - 0.5) ** 2, 0.1 * ngs.y * (ngs.x - 0.4))))
    u = uf.vec
    wf = function(fes, ngs.CF((ngs.sin(2 * ngs.x + ngs.y), ngs.x * ngs.y ** 2 - ngs.y)))
    w = wf.vec
    steps = 1e-2 * 0.5 ** np.arange(5)
    r, tested, _ = remainders(residual_form(law, fes), u, w, steps)
    for remainder in (r, tested):
        rate = np.polyfit(np.log(steps), np.log(remainder), 1)[0]
        assert 1.95 < rate < 2.05, (rate, remainder)


# ---------------------------------------------------------------- H(F) constants


def test_compaction_constants_hold_and_are_sharp():
    """m_F = 2η and L_F = 2η + d(λ + β) hold on random strain pairs and are reached within 3 %.

    Δε = cos θ D + sin θ I/√d with D a deviatoric unit tensor.
    """
    rng = np.random.default_rng(9)
    for dim in (2, 3):
        law = Compaction(LAM, ETA, BETA, dim)
        assert law.monotonicity == 2 * ETA and law.lipschitz == 2 * ETA + dim * (LAM + BETA)
        n = 600
        base = symmetric(rng, n, dim)
        dev = symmetric(rng, n, dim)
        dev -= np.einsum("nii->n", dev)[:, None, None] * np.eye(dim) / dim
        dev /= np.linalg.norm(dev, axis=(1, 2))[:, None, None]
        theta = rng.uniform(0, np.pi / 2, n)
        delta = np.cos(theta)[:, None, None] * dev + np.sin(theta)[:, None, None] * np.eye(dim) / np.sqrt(dim)
        delta *= rng.uniform(-1, 1, n)[:, None, None]
        ds = stress_at(law, base + delta) - stress_at(law, base)
        size = np.linalg.norm(delta, axis=(1, 2))
        mono = np.einsum("nij,nij->n", ds, delta) / size ** 2
        lips = np.linalg.norm(ds, axis=(1, 2)) / size
        assert mono.min() >= law.monotonicity * (1 - 1e-12) and lips.max() <= law.lipschitz * (1 + 1e-12)
        assert mono.min() <= 1.03 * law.monotonicity and lips.max() >= 0.97 * law.lipschitz


@pytest.mark.parametrize("law", [Isotropic(LAM, ETA, 3), TransverselyIsotropic(**PAD, axis=(1, 1, 0)),
                                 TransverselyIsotropic(**PAD, axis=(1, 2))], ids=["iso", "ti3", "ti2"])
def test_linear_constants_are_the_extreme_eigenvalues(law):
    rng = np.random.default_rng(4)
    d, m = law.dim, mandel.size(law.dim)
    delta = mandel.from_mandel(rng.standard_normal((300, m)))
    ds = stress_at(law, delta)
    size = np.linalg.norm(delta, axis=(1, 2))
    mono = np.einsum("nij,nij->n", ds, delta) / size ** 2
    lips = np.linalg.norm(ds, axis=(1, 2)) / size
    assert mono.min() >= law.monotonicity * (1 - 1e-12) and lips.max() <= law.lipschitz * (1 + 1e-12)
    _, vectors = np.linalg.eigh(law.matrix)
    extreme = stress_at(law, mandel.from_mandel(vectors.T[[0, -1]]))
    assert np.einsum("ij,ij", extreme[0], mandel.from_mandel(vectors[:, 0])) == pytest.approx(law.monotonicity)
    assert np.linalg.norm(extreme[1]) == pytest.approx(law.lipschitz)
    assert 0 < law.monotonicity < law.lipschitz and d in (2, 3)


# ---------------------------------------------------------------- a user's energy


def compaction_energy(e):
    tr = ngs.Trace(e)
    return ETA * ngs.InnerProduct(e, e) + 0.5 * LAM * tr ** 2 + 0.5 * BETA * ngs.IfPos(tr, 0, tr ** 2)


def test_energy_of_the_compaction_law_reproduces_it(field):
    mesh, fes, gfu = field
    dim = mesh.dim
    law, user = Compaction(LAM, ETA, BETA, dim), Energy(compaction_energy, dim)
    eps = strain(gfu)
    trace = values(ngs.Trace(eps), mesh)
    assert trace.min() < 0 < trace.max()                                      # both branches are sampled
    for ours, theirs in ((user.stress(eps), law.stress(eps)), (user.tangent(eps), law.tangent(eps)),
                         (user.energy(eps), law.energy(eps))):
        a, b = values(ours, mesh), values(theirs, mesh)
        assert np.abs(a - b).max() < 1e-13 * np.abs(b).max()
    forms = [residual_form(x, fes) for x in (law, user)]
    applied = []
    for form in forms:
        form.AssembleLinearization(gfu.vec)
        res = gfu.vec.CreateVector()
        form.Apply(gfu.vec, res)
        applied.append(res.FV().NumPy().copy())
    assert np.abs(applied[0] - applied[1]).max() < 1e-13 * np.abs(applied[0]).max()
    a, b = (sp_matrix(form.mat.CSR()).toarray() for form in forms)
    assert np.abs(a - b).max() < 1e-13 * np.abs(a).max()
    zero = user.tangent_at_zero()
    assert np.abs(zero.matrix - law.tangent_at_zero().matrix).max() < 1e-13
    assert not user.is_linear and not law.is_linear


def test_linear_integrand_on_gradients_is_the_mandel_product(field):
    """C_ijkl ∂_l u_k ∂_j v_i assembles to the same matrix as C ε_M(u) · ε_M(v) (a rotated anisotropic law)."""
    mesh, fes, _ = field
    law = TransverselyIsotropic(**PAD, axis=(1, 2, 3)[:mesh.dim])
    u, v = fes.TnT()
    mandel_form = ngs.InnerProduct(mandel.matrix_cf(law.matrix) * mandel.vector_cf(strain(u)), mandel.vector_cf(strain(v)))
    forms = [ngs.BilinearForm(cf * ngs.dx).Assemble() for cf in (law.elastic_integrand(u, v), mandel_form)]
    a, b = (sp_matrix(form.mat.CSR()) for form in forms)
    assert abs(a - b).max() < 1e-13 * abs(b).max()


def test_the_stepper_tangent_is_the_linearisation_of_the_residual(field):
    """tangent_form (compaction: the scalar form of its tangent) = NGSolve's linearisation of the residual at u."""
    mesh, fes, gfu = field
    law = Compaction(LAM, ETA, BETA, mesh.dim)
    residual = residual_form(law, fes)
    residual.AssembleLinearization(gfu.vec)
    expected = sp_matrix(residual.mat.CSR()).toarray()
    rng = np.random.default_rng(5)
    for laws in ({"body": law}, {"body": Energy(compaction_energy, mesh.dim)}):
        tangent = tangent_form(fes, laws, gfu)
        tangent.Assemble()
        x, y = tangent.mat.CreateColVector(), tangent.mat.CreateRowVector()
        for column in rng.standard_normal((3, fes.ndof)):                      # its products: K stored symmetric
            x.FV().NumPy()[:] = column
            y.data = tangent.mat * x
            assert np.abs(y.FV().NumPy() - expected @ column).max() < 1e-12 * np.abs(expected @ column).max()


@pytest.mark.parametrize("dim", [2, 3])
def test_every_law_is_the_derivative_of_its_energy(dim):
    """Energy(law.energy) has the law's stress and tangent: ψ, σ and D are consistent."""
    rng = np.random.default_rng(dim)
    strains = symmetric(rng, 20, dim)
    axis = (1, 2, 3)[:dim]
    for law in (Isotropic(LAM, ETA, dim), Compaction(LAM, ETA, BETA, dim), TransverselyIsotropic(**PAD, axis=axis)):
        user = Energy(law.energy, dim)
        assert np.abs(stress_at(user, strains) - stress_at(law, strains)).max() < 1e-12
        assert np.abs(tangent_at(user, strains) - tangent_at(law, strains)).max() < 1e-12


def test_estimated_moduli_of_an_energy(field, caplog):
    mesh, fes, gfu = field
    dim = mesh.dim
    moduli = estimate_moduli(tangent_values(Energy(compaction_energy, dim), strain(gfu), mesh))
    law = Compaction(LAM, ETA, BETA, dim)
    assert moduli.monotonicity == pytest.approx(law.monotonicity, rel=1e-12)
    assert moduli.lipschitz == pytest.approx(law.lipschitz, rel=1e-12)
    assert moduli.samples == mesh.ne * (3 if dim == 2 else 4) and moduli.warning is None
    soft = Energy(lambda e: ETA * ngs.InnerProduct(e, e) - 0.25 * ngs.Trace(e) ** 4, dim)     # softens in bulk
    rng = np.random.default_rng(1)
    with caplog.at_level(logging.WARNING):
        moduli = estimate_moduli(tangent_at(soft, 2 * symmetric(rng, 50, dim)))
    assert moduli.monotonicity < 0
    assert moduli.warning.startswith(f"material: the law is not strongly monotone over the run's strains (m_F = "
                                     f"{moduli.monotonicity:.6g} <= 0 at 50 points)")
    assert moduli.warning in caplog.text
    assert Moduli(1.0, 2.0, 3).warning is None
