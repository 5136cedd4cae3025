"""Where the time goes: meshing, assembly, factorisation + Schur extraction, G, time loop, output.

For each size (default ~10k, 50k, 200k free DOFs, P1) and repetition:

* meshing: ``build_mesh(scene, use_cache=False)`` (Netgen) and the cached load (``use_cache=True``);
* a fresh ``Discretization(scene, mesh)`` whose lazy properties are accessed in dependency order,
  each timed with ``time.perf_counter``: init (space, free DOFs, contact points), ``stiffness``
  (NGSolve assembly + CSR + symmetric completion), ``load``, ``operator`` (METIS + SuperLU + Schur
  extraction + dense inverse), ``u_load``/``s_load``, ``point_compliance`` (G), ``normal_compliance`` (H);
* the 100-step time loop ``simulate(scene, discretization=disc)``, split by wrapping (in this
  process only) ``semismooth_newton``, ``CondensedSystem.step`` / ``.merit``, the dense solve
  ``scipy.linalg.solve`` called in ``ngwear.numerics.solver``, the per-step ``CondensedSystem`` construction,
  the wear integrator's methods, ``Discretization.contact_forces`` and ``Result.append``;
* output: recovery of the stored steps (``Result.displacement``, one back-substitution each) and
  ``Result.save`` into a scratch folder (npz + json + mesh + VTU series, the VTU part timed apart).

The ``operator`` is then re-run step by step by an instrumented copy of ``ElasticOperator.__init__``
(checked to give the same (K⁻¹)_cc) to split it into: submatrix/index preparation, METIS nested
dissection of K_ii (graph build + pymetis), permutation, ``splu``, materialising ``lu.L``,
extracting the trailing blocks, and the dense ``inv(L_cc U_cc)``; plus two what-ifs that ngwear does
not do (marked "what-if"): METIS on the vertex graph (one node per mesh vertex instead of per DOF)
and S⁻¹ from the triangular factors (``dtrtri`` of L_cc and U_cc, one product) instead of
``inv(L_cc @ U_cc)``.  The dense Newton solves are replayed (a second, untimed run of the loop) to
time ``numpy.linalg.solve`` and LU reuse (``lu_factor`` only when the Newton matrix differs from the
previous one, else ``lu_solve``) on the same systems, against ``scipy.linalg.solve`` in the same replay.

    /work/venv/bin/python benchmarks/breakdown.py [--quick] [--sizes 10k,50k,200k] [--orders 1]
"""
from __future__ import annotations

import gc
import importlib
import shutil
import types

import common as C
import numpy as np
import pymetis
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import ngwear
import ngwear.numerics.solver as SV
import ngwear.numerics.wear as W
import ngwear.results.result as R
import ngwear.results.vtk as V
from ngwear.model.geometry import build_mesh
from ngwear.numerics.condense import nested_dissection
from ngwear.numerics.discrete import Discretization, _complete_symmetric
from ngwear.numerics.forms import contact_points, displacement_space, elastic_form

S = importlib.import_module("ngwear.simulate")  # (ngwear.simulate the attribute is the function)
SCRATCH = C.RESULTS / "_scratch_breakdown"

# (key, label, in "fast total")
STAGES = [
    ("mesh_uncached", "meshing, uncached (Netgen)", False),
    ("mesh_cached", "meshing, cached load", False),
    ("init", "Discretization init (space, free, contact points)", True),
    ("init_fes", "  of which: VectorH1 space", False),
    ("init_free", "  of which: free-DOF mask (list(FreeDofs))", False),
    ("init_points", "  of which: contact points + P, Q", False),
    ("stiffness", "stiffness K (assemble + CSR + symmetric)", True),
    ("stiff_assemble", "  of which: NGSolve BilinearForm.Assemble", False),
    ("stiff_csr", "  of which: mat.CSR() -> scipy csr_matrix", False),
    ("stiff_sym", "  of which: _complete_symmetric (triu/tril + add)", False),
    ("load", "load vector f", True),
    ("operator", "operator: METIS + splu + Schur + inverse", True),
    ("op_prep", "  prep: free/interior submatrices", False),
    ("op_metis", "  METIS nested dissection of K_ii (graph + pymetis)", False),
    ("op_permute", "  permute K to (interior ND, contact)", False),
    ("op_splu", "  SuperLU splu", False),
    ("op_L", "  materialise lu.L (whole factor)", False),
    ("op_trailing", "  trailing blocks L_cc, U_cc (incl. lu.U)", False),
    ("op_inverse", "  dense inv(L_cc @ U_cc)", False),
    ("whatif_metis_vertex", "  what-if: METIS on vertex graph", False),
    ("whatif_splu_vertex", "  what-if: splu with vertex-METIS order", False),
    ("whatif_inverse_trtri", "  what-if: S^-1 = trtri(U_cc) trtri(L_cc)", False),
    ("u_load", "u_load = K^-1 f, s_load", True),
    ("G", "point compliance G = P K^-1 P^T", True),
    ("H", "normal compliance H", True),
    ("loop", "time loop, 100 steps (simulate)", True),
    ("newton", "  semismooth Newton", False),
    ("newton_step", "    Newton step: Jacobian + system", False),
    ("newton_dense_solve", "      dense solve (scipy.linalg.solve)", False),
    ("newton_merit", "    merit / residual evaluations", False),
    ("system", "  CondensedSystem setup per step", False),
    ("wear", "  wear integrator (law, w, advance)", False),
    ("forces", "  contact forces", False),
    ("append", "  Result.append (per-step bookkeeping)", False),
    ("loop_other", "  rest of the loop", False),
    ("whatif_np_solve", "  what-if: dense solves by numpy.linalg.solve", False),
    ("whatif_lu_reuse", "  what-if: lu_factor only when M changes, else lu_solve", False),
    ("replay_sla_solve", "  (replay: scipy.linalg.solve as in ngwear)", False),
    ("fast_total", "FAST TOTAL (mesh given)", False),
    ("recover", "output: recover stored steps", False),
    ("save", "output: Result.save (npz, json, mesh, VTU)", False),
    ("save_npz", "  of which: np.savez_compressed", False),
    ("save_vtk", "  of which: VTU series (write_series)", False),
    ("save_rest", "  of which: rest (mesh.vol, json, summary)", False),
    ("elastic", "reference: one NGSolve elastic solve", False),
]
LABELS = {k: label for k, label, _ in STAGES}
IN_TOTAL = [k for k, _, t in STAGES if t]


# ---- instrumentation of the loop (this process only) -------------------------------------------------
class Instrument:
    def __init__(self):
        self.acc = {}
        self._undo = []

    def wrap(self, owner, name, key):
        orig = getattr(owner, name)
        acc = self.acc

        def timed(*a, **kw):
            t = C.perf()
            try:
                return orig(*a, **kw)
            finally:
                acc[key] = acc.get(key, 0.0) + C.perf() - t
        setattr(owner, name, timed)
        self._undo.append((owner, name, orig))

    def __enter__(self):
        self.wrap(S, "semismooth_newton", "newton")
        self.wrap(S, "CondensedSystem", "system")
        self.wrap(SV.CondensedSystem, "step", "newton_step")
        self.wrap(SV.CondensedSystem, "merit", "newton_merit")
        proxy = types.SimpleNamespace(solve=sla.solve)
        self._undo.append((SV, "sla", SV.sla))
        SV.sla = proxy
        self.wrap(proxy, "solve", "newton_dense_solve")
        for name in ("point_law", "wear_at", "advance"):
            self.wrap(W.WearIntegrator, name, "wear")
        self.wrap(Discretization, "contact_forces", "forces")
        self.wrap(R.Result, "append", "append")
        self.wrap(V, "write_series", "save_vtk")
        self.wrap(np, "savez_compressed", "save_npz")
        return self

    def __exit__(self, *exc):
        for owner, name, orig in reversed(self._undo):
            setattr(owner, name, orig)


# ---- the operator, step by step -------------------------------------------------------------------------
def operator_parts(disc: Discretization) -> dict:
    """An instrumented copy of ElasticOperator.__init__ (same calls, same order)."""
    t = {}
    K, free = disc.stiffness, disc.free
    contact_dofs = np.unique(disc.points.P.indices)
    p0 = C.perf()
    ndof = K.shape[0]
    fr = np.flatnonzero(free)
    local = np.full(ndof, -1)
    local[fr] = np.arange(len(fr))
    cdofs = np.asarray([d for d in contact_dofs if free[d]], dtype=int)
    c = local[cdofs]
    Kf = K[fr][:, fr].tocsr()
    interior = np.setdiff1d(np.arange(len(fr)), c)
    Kii = Kf[interior][:, interior]
    p1 = C.perf()
    perm = nested_dissection(Kii)
    p2 = C.perf()
    order = np.concatenate([interior[perm], c]).astype(int)
    A = Kf[order][:, order].tocsc()
    p3 = C.perf()
    lu = spla.splu(A, permc_spec="NATURAL", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    p4 = C.perf()
    n, nc = len(order), len(c)
    Lall = lu.L
    p5 = C.perf()
    L = Lall[:, n - nc:][n - nc:].toarray()
    U = lu.U[:, n - nc:][n - nc:].toarray()
    p6 = C.perf()
    Ci = sla.inv(L @ U)
    Ci = 0.5 * (Ci + Ci.T)
    p7 = C.perf()
    t.update(op_prep=p1 - p0, op_metis=p2 - p1, op_permute=p3 - p2, op_splu=p4 - p3, op_L=p5 - p4,
             op_trailing=p6 - p5, op_inverse=p7 - p6)
    info = {"lu_nnz": lu.nnz, "nc": nc, "n_free": n,
            "replica_maxdiff": float(np.abs(Ci - disc.operator.contact_inverse).max())}
    del Lall, lu, A  # (the SuperLU object caches CSC copies of L and U once .L is read: free them)
    gc.collect()
    # what-if 1: S^-1 from the triangular factors
    q0 = C.perf()
    Li, _ = sla.lapack.dtrtri(L, lower=1, unitdiag=1)
    Ui, _ = sla.lapack.dtrtri(U, lower=0)
    Ci2 = Ui @ Li
    Ci2 = 0.5 * (Ci2 + Ci2.T)
    t["whatif_inverse_trtri"] = C.perf() - q0
    info["whatif_inverse_maxrel"] = float(np.abs(Ci2 - Ci).max() / np.abs(Ci).max())
    # what-if 2: METIS on the vertex graph (VectorH1 numbers component-wise: dof = k * ndof_s + node)
    dim = disc.scene.dim
    ndof_s = ndof // dim
    q0 = C.perf()
    node_of = fr[interior] % ndof_s
    nodes, inverse = np.unique(node_of, return_inverse=True)
    Rm = sp.csr_matrix((np.ones(len(interior)), (inverse, np.arange(len(interior)))),
                       shape=(len(nodes), len(interior)))
    Gn = (Rm @ (abs(Kii) @ Rm.T)).tocsr()
    Gn.setdiag(0)
    Gn.eliminate_zeros()
    nperm, _ = pymetis.nested_dissection(pymetis.CSRAdjacency(Gn.indptr.astype(np.int32),
                                                                Gn.indices.astype(np.int32)))
    rank = np.empty(len(nodes), int)
    rank[np.asarray(nperm)] = np.arange(len(nodes))
    perm_v = np.lexsort((np.arange(len(interior)), rank[inverse]))
    t["whatif_metis_vertex"] = C.perf() - q0
    order_v = np.concatenate([interior[perm_v], c]).astype(int)
    Av = Kf[order_v][:, order_v].tocsc()
    q1 = C.perf()
    luv = spla.splu(Av, permc_spec="NATURAL", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    t["whatif_splu_vertex"] = C.perf() - q1
    info["whatif_lu_nnz_vertex"] = luv.nnz
    return t, info


def init_parts(scene, mesh) -> dict:
    """An instrumented copy of Discretization.__init__ (space, free mask, contact points)."""
    p0 = C.perf()
    fes = displacement_space(mesh, scene)
    p1 = C.perf()
    np.array(list(fes.FreeDofs()), dtype=bool)
    p2 = C.perf()
    contact_points(fes, scene.dim, scene.mesh.order)
    p3 = C.perf()
    return {"init_fes": p1 - p0, "init_free": p2 - p1, "init_points": p3 - p2}


def stiffness_parts(disc) -> dict:
    """An instrumented copy of Discretization.stiffness."""
    p0 = C.perf()
    a = elastic_form(disc.fes, disc.scene)
    a.Assemble()
    p1 = C.perf()
    vals, cols, ptr = a.mat.CSR()
    n = disc.fes.ndof
    K = sp.csr_matrix((np.array(vals), np.array(cols), np.array(ptr)), shape=(n, n))
    p2 = C.perf()
    _complete_symmetric(K)
    p3 = C.perf()
    return {"stiff_assemble": p1 - p0, "stiff_csr": p2 - p1, "stiff_sym": p3 - p2}


def dense_solve_whatifs(scene, disc) -> tuple[dict, dict]:
    """Replay the loop's dense Newton solves: numpy.linalg.solve, and LU reuse while M repeats.

    A second (untimed) run of the loop with ``ngwear.numerics.solver.sla.solve`` replaced by a recorder that,
    at every call, times the alternatives on the very same (M, rhs) and checks the answer.
    """
    acc = {"whatif_np_solve": 0.0, "whatif_lu_reuse": 0.0, "sla": 0.0}
    state = {"prev": None, "lu": None, "calls": 0, "repeats": 0, "maxdiff": 0.0}

    def recorder(M, rhs, **kw):
        t0 = C.perf()
        ref = sla.solve(M, rhs, **kw)
        t1 = C.perf()
        np.linalg.solve(M, rhs)
        t2 = C.perf()
        prev = state["prev"]
        same = prev is not None and prev.shape == M.shape and np.array_equal(prev, M)
        t3 = C.perf()
        if not same:
            state["lu"] = sla.lu_factor(M, check_finite=False)
        x = sla.lu_solve(state["lu"], rhs, check_finite=False)
        t4 = C.perf()
        acc["sla"] += t1 - t0
        acc["whatif_np_solve"] += t2 - t1
        acc["whatif_lu_reuse"] += t4 - t3
        state["calls"] += 1
        state["repeats"] += same
        rel = float(np.abs(x - ref).max() / max(np.abs(ref).max(), 1e-300))
        state["maxdiff"] = max(state["maxdiff"], rel)
        state["prev"] = M.copy()
        return ref

    orig = SV.sla
    SV.sla = types.SimpleNamespace(solve=recorder)
    try:
        ngwear.simulate(scene, discretization=disc, progress=False)
    finally:
        SV.sla = orig
    times = {"whatif_np_solve": acc["whatif_np_solve"], "whatif_lu_reuse": acc["whatif_lu_reuse"],
             "replay_sla_solve": acc["sla"]}
    return times, {"newton_matrix_repeats": f"{state['repeats']}/{state['calls']}",
                   "lu_reuse_maxrel": state["maxdiff"]}


def one_rep(scene, mesh) -> tuple[dict, dict]:
    t = {}
    with C.stopwatch(t, "init"):
        disc = Discretization(scene, mesh)
    for key, prop in (("stiffness", "stiffness"), ("load", "load"), ("operator", "operator"),
                      ("u_load", "u_load"), ("u_load", "s_load"), ("G", "point_compliance"),
                      ("H", "normal_compliance")):
        with C.stopwatch(t, key):
            getattr(disc, prop)
    with Instrument() as ins:
        with C.stopwatch(t, "loop"):
            result = ngwear.simulate(scene, discretization=disc, progress=False)
        t.update({k: v for k, v in ins.acc.items() if k not in ("save_vtk", "save_npz")})
        top = ("newton", "system", "wear", "forces", "append")
        t["loop_other"] = t["loop"] - sum(t.get(k, 0.0) for k in top)
        t["fast_total"] = sum(t[k] for k in IN_TOTAL)
        with C.stopwatch(t, "recover"):
            for s in result.stored_steps:
                result.displacement(s)
        ins.acc["save_vtk"] = ins.acc["save_npz"] = 0.0
        shutil.rmtree(SCRATCH, ignore_errors=True)
        with C.stopwatch(t, "save"):
            result.save(SCRATCH)
        t["save_vtk"] = ins.acc["save_vtk"]
        t["save_npz"] = ins.acc["save_npz"]
        t["save_rest"] = t["save"] - t["save_vtk"] - t["save_npz"]
    shutil.rmtree(SCRATCH, ignore_errors=True)
    t.update(init_parts(scene, mesh))
    t.update(stiffness_parts(disc))
    parts, info = operator_parts(disc)
    t.update(parts)
    reuse, reuse_info = dense_solve_whatifs(scene, disc)
    t.update(reuse)
    info.update(reuse_info)
    info.update(free_dofs=C.free_dofs(disc), contact_points=disc.points.n,
                newton_its=C.newton_iterations(result), stored_steps=len(result.stored_steps))
    return t, info


def measure(size, order, reps) -> tuple[dict, dict]:
    scene = C.scene_for(size, order)
    times = {}
    mesh_reps = reps if C.SIZES[size] < 200_000 else 1
    for _ in range(mesh_reps):
        dt, _ = C.timed(build_mesh, scene, use_cache=False)
        times.setdefault("mesh_uncached", []).append(dt)
    mesh = C.mesh_for(scene)  # makes sure it is cached
    for _ in range(reps):
        dt, mesh = C.timed(build_mesh, scene, use_cache=True)
        times.setdefault("mesh_cached", []).append(dt)
    info = {}
    for _ in range(reps):
        t, info = one_rep(scene, mesh)
        for k, v in t.items():
            times.setdefault(k, []).append(v)
        times.setdefault("elastic", []).append(C.elastic_reference(scene, mesh)["total"])
    return {k: C.median(v) for k, v in times.items()}, info


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.set_defaults(orders="1")
    p.add_argument("--reps-200k", type=int, default=1, help="repetitions at 200k")
    args = p.parse_args()
    sizes = C.selected_sizes(args, default=("10k", "50k", "200k"))
    header = C.machine_lines(args) + [
        "paper strip, 100 steps; medians of the repetitions; % = share of FAST TOTAL "
        "(Discretization + simulate, mesh given); indented rows are parts of the row above"]
    cols, infos, med = [], {}, {}
    with C.blas_limit(args.blas_threads):
        for order in C.selected_orders(args):
            for size in sizes:
                reps = args.reps_200k if C.SIZES[size] >= 200_000 else args.reps
                label = f"P{order} {size}"
                med[label], infos[label] = measure(size, order, reps)
                cols.append(label)
                m = med[label]
                print(f"  {label}: {infos[label]['free_dofs']} DOFs, fast total {m['fast_total']:.3f}s, "
                      f"operator {m['operator']:.3f}s, loop {m['loop']:.3f}s", flush=True)
    rows = []
    for key, label, _ in STAGES:
        row = {"stage": label, "key": key}
        for c in cols:
            v = med[c].get(key)
            row[f"{c} [s]"] = v
            row[f"{c} %"] = 100 * v / med[c]["fast_total"] if v is not None else None
        rows.append(row)
    for ikey, ilabel in (("free_dofs", "free DOFs"), ("contact_points", "contact points"),
                         ("nc", "contact DOFs (Schur block)"), ("lu_nnz", "nnz(L+U)"),
                         ("whatif_lu_nnz_vertex", "nnz(L+U), vertex-METIS"),
                         ("newton_its", "Newton iterations"),
                         ("newton_matrix_repeats", "Newton matrices M equal to the previous"),
                         ("lu_reuse_maxrel", "LU-reuse what-if rel. diff"),
                         ("replica_maxdiff", "replica max|ΔC|"),
                         ("whatif_inverse_maxrel", "trtri inverse rel. diff")):
        rows.append({"stage": ilabel, "key": ikey, **{f"{c} [s]": infos[c].get(ikey) for c in cols}})
    columns = [("stage", "stage", None)]
    for c in cols:
        columns += [(f"{c} [s]", f"{c} [s]", ".4g"), (f"{c} %", "%", ".1f")]
    fig, (ax,) = C.new_figure(1, width=9)
    parts = ["init", "stiffness", "load", "op_prep", "op_metis", "op_permute", "op_splu", "op_L",
             "op_trailing", "op_inverse", "u_load", "G", "H", "newton", "append", "loop_other"]
    left = np.zeros(len(cols))
    cmap = __import__("matplotlib").colormaps["tab20"]
    for i, key in enumerate(parts):
        vals = np.array([med[c].get(key, 0.0) if key != "loop_other" else
                         med[c]["loop"] - med[c].get("newton", 0) - med[c].get("append", 0) for c in cols])
        share = 100 * vals / np.array([med[c]["fast_total"] for c in cols])
        ax.barh(cols, share, left=left, color=cmap(i), label=LABELS.get(key, key).strip()[:40])
        left += share
    ax.set(xlabel="% of fast total (mesh given)", title="where the time goes (operator split by the replica)")
    ax.legend(fontsize=6, loc="center left", bbox_to_anchor=(1.0, 0.5))
    C.finish("breakdown", "time breakdown", header, rows, columns, fig, quick=args.quick)


if __name__ == "__main__":
    main()
