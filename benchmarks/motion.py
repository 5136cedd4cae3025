"""Wear that removes material: which extension keeps the pad's elements valid, and what an update costs.

``--part quality``: the shipped brake pad (12 mm of friction material on its 5.5 mm steel backing) worn in steps
of 0.5 mm of mean wear up to the whole friction material, uniformly and with two tapers (circumferential
W (1 + ξ/2), ξ = −1 at the leading edge … 1 at the trailing one; and W (1 + 0.4 ξ + 0.4 η), η from the inner to
the outer radius), each moved by four extensions of the wear into the friction material (the backing and the
interface held): ``harmonic`` (ngwear.numerics.recession: one scalar Laplace problem on the mesh as built, φ = W on
Γ_C, every vertex moving along −ν), ``incremental`` (the same on the mesh as last moved, for the wear since),
``stiffened`` (the Laplace problem with the coefficient V̄/V_T: small elements move rigidly) and ``elastic``
(vector linear elasticity, λ = η, the sides free).  Reported at half the friction material worn: the worst mean
ratio, the most squeezed element (V/V₀), inverted elements, how far a vertex moved off the sides; and the mean wear
from which an element is inverted or its mean ratio below ``motion.QUALITY``.

``--part bound``: the same pad, tapered, against a fresh Netgen mesh of the same worn body (its volume meshed anew
on the moved surface mesh, so both have the same contact points; the worst mean ratio of ngwear's remesh, the part
cut by the worn face, beside): the normal displacement s = H m of Γ_C under a
unit pressure (H = ν·P K⁻¹ Pᵀ·ν, what the contact problem sees of the body) on both, as L max|s − s_fresh|, the
change of the pressure, relative to it, that the difference causes through the layer; the unworn pad's row is the
difference between two volume meshes of one surface, the discretisation's own.

``--part cost``: at maxh 0.006 (shipped), 0.003 and 0.002, what an update costs: the extension's set-up
(assembly + PARDISO factorisation of the scalar Laplacian, once per reference mesh), one update (a back-substitution,
the new coordinates, the quality check), the rebuild of what the move invalidates (ngwear's K from gradient blocks,
its factorisation, the contact compliance, the loads, the plate), one step of the time loop (100 steps / 100), and
one NGSolve elastic solve on the same mesh (assemble + sparsecholesky + solve); medians of interleaved repetitions.

    .venv/bin/python benchmarks/motion.py [--part quality,bound,cost] [--reps 3] [--quick]
"""
from __future__ import annotations

import common as C
import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

import ngwear
from ngwear.model.kinds import KINDS
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.pardiso import Pardiso
from ngwear.numerics.recession import QUALITY, Extension, mean_ratio, quality, remeshed
from ngwear.numerics.topology import coordinates, place, simplices

PAD = C.ROOT / "geometries" / "brake_pad.toml"
NU = np.array([0.0, 0.0, -1.0])
THICKNESS, HALF_ANGLE, INNER, OUTER = 0.012, np.radians(30.0), 0.10, 0.15
PATTERNS = {"uniform": lambda xi, eta: np.ones_like(xi), "taper": lambda xi, eta: 1 + 0.5 * xi,
            "taper2": lambda xi, eta: 1 + 0.4 * xi + 0.4 * eta}


def pad(maxh=0.006):
    return ngwear.load_scene(PAD).replace(**{"mesh.maxh": maxh})


def shape(points: np.ndarray, pattern: str) -> np.ndarray:
    """The wear pattern at points of Γ_C, mean about 1 (ξ: leading −1 … trailing 1, η: inner −1 … outer 1)."""
    xi = np.arctan2(points[:, 1], points[:, 0]) / HALF_ANGLE
    eta = (np.hypot(points[:, 0], points[:, 1]) - (INNER + OUTER) / 2) / ((OUTER - INNER) / 2)
    return PATTERNS[pattern](xi, eta)


def matrix(form, n) -> sp.csr_matrix:
    form.Assemble()
    rows, cols, values = form.mat.COO()
    return sp.csr_matrix((values.NumPy(), (rows.NumPy(), cols.NumPy())), shape=(n, n))


def stiffened(mesh, extension):
    """The Laplace extension with the coefficient V̄/V_T on each element T (Jacobian-based stiffening)."""
    nodes, _ = simplices(mesh)
    size = np.abs(np.linalg.det(extension.reference[nodes[:, 1:]] - extension.reference[nodes[:, :1]]))
    coefficient = ngs.GridFunction(ngs.L2(mesh, order=0))
    coefficient.vec.FV().NumPy()[:] = size.mean() / size
    fes = ngs.H1(mesh, order=1)
    u, v = fes.TnT()
    L = matrix(ngs.BilinearForm(coefficient * ngs.grad(u) * ngs.grad(v) * ngs.dx("body"), symmetric=True), mesh.nv)
    free, contact = extension.free, extension.contact
    factor, coupling = Pardiso(L[free][:, free]), L[free][:, contact]

    def move(wear):
        phi = np.zeros(mesh.nv)
        phi[contact], phi[free] = wear, -factor.solve(coupling @ wear)
        return extension.reference - np.outer(phi, NU)
    return move


def elastic(mesh, extension):
    """Linear elasticity (λ = η = 1) on the friction material: u = −W ν on Γ_C, 0 on the interface, sides free."""
    fes = ngs.VectorH1(mesh, order=1, dirichlet="contact|interface", definedon=mesh.Materials("body"))
    u, v = fes.TnT()
    strain = lambda w: ngs.Sym(ngs.Grad(w))  # noqa: E731
    K = matrix(ngs.BilinearForm((2 * ngs.InnerProduct(strain(u), strain(v)) + ngs.Trace(strain(u)) *
                                 ngs.Trace(strain(v))) * ngs.dx("body"), symmetric=True), fes.ndof)
    free = np.flatnonzero(np.array(list(fes.FreeDofs())))
    factor, nv = Pardiso(K[free][:, free]), mesh.nv

    def move(wear):
        U = np.zeros(fes.ndof)
        for k in range(3):                               # VectorH1 of order 1: component k of vertex v is k nv + v
            U[k * nv + extension.contact] = -wear * NU[k]
        U[free] = -factor.solve((K @ U)[free])
        return extension.reference + U.reshape(3, nv).T
    return move


def quality_rows(args) -> list[dict]:
    rows, steps = [], np.arange(0.5e-3, THICKNESS + 1e-9, 0.5e-3)
    for pattern in PATTERNS:
        for method in ("harmonic", "incremental", "stiffened", "elastic"):
            mesh = C.mesh_for(pad())
            extension = Extension(mesh, NU)
            nodes, _ = simplices(mesh)
            start, current, done = extension.reference, extension, np.zeros(len(extension.contact))
            weights = shape(start[extension.contact], pattern)
            move = {"harmonic": extension.moved, "stiffened": stiffened(mesh, extension) if method == "stiffened"
                    else None, "elastic": elastic(mesh, extension) if method == "elastic" else None}.get(method)
            row, failed = {"pattern": pattern, "extension": method}, None
            for mean in steps:
                wear = mean * weights
                moved = current.moved(wear - done) if method == "incremental" else move(wear)
                q = quality(moved, start, nodes)
                if method == "incremental" and not q.inverted:
                    place(mesh, moved)
                    current, done = Extension(mesh, NU), wear
                if failed is None and not q.acceptable:
                    failed = mean
                if abs(mean - THICKNESS / 2) < 1e-9:
                    row.update(q_half=q.worst, squeezed_half=q.squeezed, inverted_half=q.inverted,
                               off_sides_mm=1e3 * np.abs((moved - start)[:, :2]).max(),
                               deepest_half_mm=1e3 * wear.max())
                if q.inverted:
                    break
            row["fails_at_mm"] = None if failed is None else 1e3 * failed
            rows.append(row)
            print(f"  {pattern} {method}: q {row['q_half']:.3f} at half, fails at {row['fails_at_mm']} mm", flush=True)
    return rows


def response(scene, mesh) -> tuple[np.ndarray, np.ndarray]:
    """(Contact points, s = ν·u at them under a unit pressure on Γ_C): s = H m, H = ν·P K⁻¹ Pᵀ·ν."""
    disc = Discretization(scene, mesh, contact_solve="dense")
    return disc.points.coords, disc.condensation.normal_compliance @ disc.points.weights


def matched(reference: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The order of ``points`` that puts them at ``reference`` (the same surface mesh)."""
    from scipy.spatial import cKDTree
    distance, order = cKDTree(points).query(reference)
    assert distance.max() < 1e-12, "the meshes do not share their contact points"
    return order


def difference(scene, mesh, other) -> float:
    """L max|s − s'| of two meshes with the same contact points.

    The change of a pressure, relative to it, that the difference of their bodies' response causes through the
    layer (its slope L).
    """
    points, s = response(scene, mesh)
    others, t = response(scene, other)
    return scene.contact.stiffness * np.abs(s - t[matched(points, others)]).max()


def volume_remeshed(mesh, maxh):
    """The worn body with its moved surface mesh kept and its volume meshed anew by Netgen (the same contact points)."""
    import netgen.meshing as meshing

    old, new = mesh.ngmesh, meshing.Mesh(dim=3)
    for point in old.Coordinates():
        new.Add(meshing.MeshPoint(meshing.Pnt(*point)))
    for i in range(1, old.GetNFaceDescriptors() + 1):
        face = old.FaceDescriptor(i)
        new.Add(meshing.FaceDescriptor(surfnr=face.surfnr, domin=face.domin, domout=face.domout, bc=face.bc))
        new.SetBCName(i - 1, face.bcname)
    for i, name in enumerate(mesh.GetMaterials(), start=1):
        new.SetMaterial(i, name)
    surface = old.Elements2D().NumPy()
    for index, vertices in zip(surface["index"], surface["nodes"]):
        new.Add(meshing.Element2D(int(index), [meshing.PointId(int(v)) for v in vertices]))
    new.GenerateVolumeMesh(maxh=maxh)
    return ngs.Mesh(new)


def measures(mesh, other) -> float:
    """The largest relative difference of the regions' volumes and the boundaries' measures of two meshes."""
    def of(m):
        regions = {r: ngs.Integrate(ngs.CF(1.0), m, definedon=m.Materials(r)) for r in m.GetMaterials()}
        return regions | {b: ngs.Integrate(ngs.CF(1.0) * ngs.ds(b), m) for b in set(m.GetBoundaries())}
    a, b = of(mesh), of(other)
    return max(abs(b[k] / a[k] - 1) for k in a)


def bound_rows(args) -> list[dict]:
    scene, rows = pad(), []
    for mean in (0.0, 3e-3, 5e-3, 6e-3, 7e-3, 7.5e-3):
        mesh = C.mesh_for(scene)
        extension = Extension(mesh, NU)
        nodes, _ = simplices(mesh)
        wear = mean * shape(extension.reference[extension.contact], "taper")
        moved = extension.moved(wear)
        q = quality(moved, extension.reference, nodes)
        place(mesh, moved)
        fresh = volume_remeshed(mesh, scene.mesh.maxh)
        fresh_nodes, _ = simplices(fresh)
        seconds, new = C.timed(remeshed, mesh, scene.mesh.maxh, NU, KINDS["pad"].build(scene.geometry, scene.mesh))
        new_nodes, _ = simplices(new)
        rows.append({"mean_wear_mm": 1e3 * mean, "deepest_mm": 1e3 * wear.max(), "q_moved": q.worst,
                     "q_fresh": float(mean_ratio(coordinates(fresh), fresh_nodes).min()),
                     "q_remeshed": float(mean_ratio(coordinates(new), new_nodes).min()), "remesh_s": seconds,
                     "measures": measures(mesh, new),
                     "pressure_change": difference(scene, mesh, fresh)})
        print(f"  {rows[-1]}", flush=True)
    return rows


def cost_rows(args) -> list[dict]:
    rows = []
    for maxh in ((0.006,) if args.quick else (0.006, 0.003, 0.002)):
        scene = pad(maxh)
        mesh = C.mesh_for(scene)
        disc = Discretization(scene, mesh)
        state = {}

        def setup():
            state["extension"] = Extension(mesh, NU)

        def update():
            extension = state["extension"]
            moved = extension.moved(1e-3 * shape(extension.reference[extension.contact], "taper"))
            state["quality"] = quality(moved, extension.reference, simplices(mesh)[0])

        def rebuild():
            new = Discretization(scene, mesh)
            for _, build in new.stages():
                build()

        def elastic_solve():
            state["elastic"] = C.elastic_reference(scene, mesh)

        times, _ = C.interleaved({"setup": setup, "update": update, "rebuild": rebuild, "elastic": elastic_solve},
                                 args.reps)
        run = ngwear.simulate(scene.replace(**{"time.steps": 100, "output.every": scene.time.T}),
                              discretization=disc, progress=False)
        step = run.solve_time / 100
        row = {"maxh": maxh, "ndof": disc.fes.ndof, "vertices": mesh.nv, "contact_points": disc.points.n,
               **{f"{k}_s": C.median(v) for k, v in times.items()}, "step_s": step}
        row["update_vs_elastic"] = (row["update_s"] + row["rebuild_s"]) / row["elastic_s"]
        row["update_vs_step"] = (row["update_s"] + row["rebuild_s"]) / step
        row["setup_vs_elastic"] = row["setup_s"] / row["elastic_s"]
        rows.append(row)
        print(f"  maxh {maxh}: {row}", flush=True)
    return rows


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.add_argument("--part", default="quality,bound,cost")
    args = p.parse_args()
    parts = args.part.split(",")
    header = C.machine_lines(args) + [f"the shipped brake pad (12 mm friction material on 5.5 mm steel), quality bound "
                                      f"{QUALITY}"]
    with C.blas_limit(args.blas_threads):
        if "quality" in parts:
            rows = quality_rows(args)
            C.finish("motion_quality", "extensions of the wear into the pad: quality at half worn", header, rows,
                     [("pattern", "wear", None), ("extension", "extension", None), ("q_half", "q_min", ".3f"),
                      ("squeezed_half", "V/V0 min", ".3f"), ("inverted_half", "inverted", "d"),
                      ("off_sides_mm", "off sides mm", ".3f"), ("deepest_half_mm", "deepest mm", ".1f"),
                      ("fails_at_mm", "fails at mean mm", ".1f")], quick=args.quick)
        if "bound" in parts:
            rows = bound_rows(args)
            C.finish("motion_bound", "moved against fresh mesh: the contact compliance H", header, rows,
                     [("mean_wear_mm", "mean mm", ".1f"), ("deepest_mm", "deepest mm", ".2f"),
                      ("q_moved", "q moved", ".3f"), ("q_fresh", "q fresh volume", ".3f"),
                      ("q_remeshed", "q remeshed", ".3f"), ("remesh_s", "remesh s", ".1f"),
                      ("measures", "measures", ".1e"),
                      ("pressure_change", "L max|s - s_fresh|", ".2e")],
                     quick=args.quick)
        if "cost" in parts:
            rows = cost_rows(args)
            C.finish("motion_cost", "what an update costs", header, rows,
                     [("maxh", "maxh", "g"), ("ndof", "DOFs", "d"), ("contact_points", "points", "d"),
                      ("setup_s", "extension set-up s", ".3f"), ("update_s", "update s", ".4f"),
                      ("rebuild_s", "rebuild s", ".3f"), ("step_s", "one step s", ".4f"),
                      ("elastic_s", "elastic solve s", ".3f"), ("setup_vs_elastic", "set-up/elastic", ".2f"),
                      ("update_vs_elastic", "update+rebuild/elastic", ".2f"),
                      ("update_vs_step", "update+rebuild/step", ".1f")], quick=args.quick)


if __name__ == "__main__":
    main()
