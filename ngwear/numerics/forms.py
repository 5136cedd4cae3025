"""NGSolve forms on the body and the contact points of Γ_C.

Elastic form  a(u, v) = ∫_Ω F(ε(u)) : ε(v) dx,  load  ℓ(v) = ∫_Ω f₀·v dx + Σ ∫_ΓN f_N·v da.

Contact form (the nonlinear boundary integrator, paper φ with fixed w):

    φ(w, u, v) = ∫_ΓC p(u_ν − d₀ − w) (v_ν + μ n*·v_τ) da,   u_ν = u·ν,   n* = n*(x),

integrated with the *nodal* rule of the element (trapezoidal / Simpson on segments, vertex rule
on triangles): the integral is Σ_i m_i p_i (ν + μ n*)·v(x_i) over the contact points x_i with
weights m_i.  This makes the constraint u_ν ≤ g + d₀, the wear update and ∫_ΓC w all nodal, so the
discrete Archard identity holds to round-off.  For P2 the points are vertices and edge midpoints.
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp
from ngsolve.fem import NODE_TYPE

from ..model.laws import Compliance, hooke_stress
from ..model.scene import Scene

NODAL_RULES = {
    (2, 1): (ngs.SEGM, [(0.0,), (1.0,)], [0.5, 0.5]),
    (2, 2): (ngs.SEGM, [(0.0,), (0.5,), (1.0,)], [1 / 6, 4 / 6, 1 / 6]),
    (3, 1): (ngs.TRIG, [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)], [1 / 6, 1 / 6, 1 / 6]),
}


def contact_ds(dim: int, order: int):
    """ds("contact") with the nodal integration rule of the contact elements."""
    et, pts, wts = NODAL_RULES[dim, order]
    return ngs.ds("contact", intrules={et: ngs.IntegrationRule(pts, wts)})


def displacement_space(mesh: ngs.Mesh, scene: Scene) -> ngs.FESpace:
    """Vector H1 of the scene's order on the body, clamped on the Dirichlet boundaries and the plate's."""
    plate = scene.loads.plate
    clamped = (*scene.geometry.dirichlet, *((plate.boundary,) if plate else ()))
    return ngs.VectorH1(mesh, order=scene.mesh.order, definedon="body", dirichlet="|".join(clamped))


def elastic_integrand(fes: ngs.FESpace, scene: Scene):
    """σ(ε(u)) : ε(v) dx."""
    lam, mu = scene.material.lame
    u, v = fes.TnT()
    strain = ngs.Sym(ngs.Grad(u))
    return ngs.InnerProduct(hooke_stress(strain, lam, mu, scene.dim), ngs.Sym(ngs.Grad(v))) * ngs.dx("body")


def elastic_form(fes: ngs.FESpace, scene: Scene) -> ngs.BilinearForm:
    """a(u, v) = ∫ σ(ε(u)) : ε(v) dx (symmetric, constant in time)."""
    return ngs.BilinearForm(elastic_integrand(fes, scene), symmetric=True)


def load_form(fes: ngs.FESpace, scene: Scene) -> ngs.LinearForm:
    """ℓ(v) = ∫ f₀·v dx + Σ_b ∫_b f_N·v da at unit time factor."""
    v = fes.TestFunction()
    f = ngs.LinearForm(fes)
    if scene.loads.body_force is not None:
        f += ngs.InnerProduct(ngs.CF(scene.loads.body_force), v) * ngs.dx("body")
    for name, vec in scene.loads.traction.items():
        f += ngs.InnerProduct(ngs.CF(vec), v) * ngs.ds(name)
    return f


@dataclass
class ContactForm:
    """φ(w, u, ·) as an NGSolve form; ``w``, ``d0`` and the components of ``n_star`` are nodal GridFunctions."""

    form: ngs.BilinearForm
    w: ngs.GridFunction
    d0: ngs.GridFunction
    mu: ngs.Parameter
    n_star: list


def contact_form(fes: ngs.FESpace, scene: Scene, law: Compliance, with_elastic: bool) -> ContactForm:
    """The nonlinear boundary integrator (residual by ``Apply``, Jacobian by ``AssembleLinearization``)."""
    dim, order = scene.dim, scene.mesh.order
    scal = ngs.H1(fes.mesh, order=order, definedon="body")
    w, d0 = ngs.GridFunction(scal), ngs.GridFunction(scal)
    mu = ngs.Parameter(scene.contact.friction)
    n_star = [ngs.GridFunction(scal) for _ in range(dim)]
    nu = ngs.CF(scene.contact.direction)
    u, v = fes.TnT()
    form = ngs.BilinearForm(fes)
    if with_elastic:
        form += elastic_integrand(fes, scene)
    compression = ngs.InnerProduct(u, nu) - d0 - w
    direction = nu + mu * ngs.CF(tuple(n_star))
    form += law.cf(compression) * ngs.InnerProduct(direction, v) * contact_ds(dim, order)
    return ContactForm(form, w, d0, mu, n_star)


def initial_distance(coords: np.ndarray, nu) -> np.ndarray:
    """d₀ ≥ 0 at points x_i: distance along ν to the foundation plane through the lowest point, max ν·x − ν·x_i."""
    heights = coords @ np.asarray(nu, dtype=float)
    return heights.max(initial=0.0) - heights


@dataclass(frozen=True)
class ContactPoints:
    """The nodal points x_i of Γ_C with weights m_i and evaluation maps.

    ``P`` (d·n × ndof): (P u)[d i + k] = u_k(x_i).  ``Q`` (ndof_scalar × n): coefficients of the
    scalar H1 function with nodal values ``w`` at the points (for the NGSolve form's w and d₀).
    ``vertices[i]``: the mesh vertex at x_i, −1 for an edge midpoint (P2).
    """

    coords: np.ndarray
    weights: np.ndarray
    P: sp.csr_matrix
    Q: sp.csr_matrix
    vertices: np.ndarray

    @property
    def n(self) -> int:
        return len(self.weights)


def contact_points(fes: ngs.FESpace, dim: int, order: int) -> ContactPoints:
    """Collect the contact points (vertices, plus edge midpoints for P2) and their nodal weights."""
    mesh = fes.mesh
    ndof_s = fes.ndof // dim
    index: dict[tuple, int] = {}
    coords, weights = [], []
    prow, pcol, pval = [], [], []
    qrow, qcol, qval = [], [], []

    def point(key, x):
        if key not in index:
            index[key] = len(coords)
            coords.append(x)
            weights.append(0.0)
        return index[key]

    def vdofs(vnr):
        dofs = fes.GetDofNrs(ngs.NodeId(NODE_TYPE.VERTEX, vnr))
        return [d for d in dofs if d >= 0]

    beta = _bubble_scale(fes, dim) if order == 2 else None
    for el in mesh.Elements(ngs.BND):
        if el.mat != "contact":
            continue
        verts = [v.nr for v in el.vertices]
        xs = [np.array(mesh[v].point) for v in el.vertices]
        size = np.linalg.norm(xs[1] - xs[0]) if dim == 2 else 0.5 * np.linalg.norm(
            np.cross(xs[1] - xs[0], xs[2] - xs[0]))
        vertex_weight = size / (6 if order == 2 else dim)
        for v, x in zip(verts, xs):
            i = point(("v", v), x)
            weights[i] += vertex_weight
        if order == 2:
            for e in el.edges:
                a, b = mesh[e].vertices
                i = point(("e", e.nr), 0.5 * (np.array(mesh[a].point) + np.array(mesh[b].point)))
                weights[i] += 4 * size / 6
    for (kind, nr), i in index.items():
        if kind == "v":
            dofs = vdofs(nr)
            terms = [(dofs, 1.0)]
            if dofs:
                qrow.append(dofs[0]), qcol.append(i), qval.append(1.0)
        else:
            a, b = (v.nr for v in mesh[ngs.NodeId(NODE_TYPE.EDGE, nr)].vertices)
            edofs = [d for d in fes.GetDofNrs(ngs.NodeId(NODE_TYPE.EDGE, nr)) if d >= 0]
            be = beta[edofs[0]]
            terms = [(vdofs(a), 0.5), (vdofs(b), 0.5), (edofs, be)]
            for col, c in ((i, 1 / be), (index["v", a], -0.5 / be), (index["v", b], -0.5 / be)):
                qrow.append(edofs[0]), qcol.append(col), qval.append(c)
        for dofs, c in terms:
            for k, dof in enumerate(dofs):
                prow.append(dim * i + k), pcol.append(dof), pval.append(c)
    n = len(coords)
    P = sp.csr_matrix((pval, (prow, pcol)), shape=(dim * n, fes.ndof))
    Q = sp.csr_matrix((qval, (qrow, qcol)), shape=(ndof_s, n))
    vertices = np.full(n, -1)
    for (kind, nr), i in index.items():
        if kind == "v":
            vertices[i] = nr
    return ContactPoints(np.array(coords)[:, :dim], np.array(weights), P, Q, vertices)


def _bubble_scale(fes: ngs.FESpace, dim: int) -> np.ndarray:
    """β_e: value at the edge midpoint of the P2 edge shape function, per scalar edge DOF.

    From f = |x|²: f(mid) − (f(a)+f(b))/2 = −|b−a|²/4 = β_e c_e, with c_e the interpolant's edge DOF.
    """
    mesh = fes.mesh
    scal = ngs.H1(mesh, order=2, definedon="body")
    gf = ngs.GridFunction(scal)
    gf.Set(sum(c * c for c in (ngs.x, ngs.y, ngs.z)[:dim]))
    coef = gf.vec.FV().NumPy()
    beta = np.zeros(scal.ndof)
    for e in mesh.edges:
        dofs = scal.GetDofNrs(e)
        if not dofs or dofs[0] < 0:
            continue
        a, b = (np.array(mesh[v].point) for v in e.vertices)
        if abs(coef[dofs[0]]) > 0:
            beta[dofs[0]] = -np.dot(b - a, b - a) / 4 / coef[dofs[0]]
    return beta
