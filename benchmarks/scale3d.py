"""3D at scale: time and peak memory against DOFs and contact points, P1 and P2.

Four series: ``geometries/box3d.toml`` at maxh 0.04, 0.025, 0.018 (P1) and 0.08,
0.05, 0.035 (P2, about the same DOFs), and the brake pad ``geometries/brake_pad.toml`` (held by its
rigid back plate only, on a disc turning about z) at maxh 0.002, 0.0011, 0.0007, 0.00063 (P1, the
last 844k DOFs and 18k contact points) and 0.004, 0.003, 0.002, 0.0014, 0.0012 (P2, the last 891k
DOFs and 15k contact points); 100 steps each (the pad with k = 1 s).  Every case runs in a fresh
subprocess, so its peak memory is the process's own (``ru_maxrss``, C allocations included):

* ``mesh``: Netgen meshing, or the cache's load when the mesh is cached (first-run cost: the
  ``mesh_first_s`` column, measured with ``--remesh``, or the build time when the cache was empty);
* ``ngwear``: ``Discretization(scene, mesh)`` + ``simulate`` (100 steps), split into assembly,
  factorisation (PARDISO, with the Schur complement on the contact DOFs for the dense path), the ν rows
  of the point compliance, loads/plate, and the time loop (matrix-free products counted);
* ``elastic``: one NGSolve linear-elastic solve on the same mesh (assemble + ``sparsecholesky`` + solve),
  sequential and inside ``TaskManager``, in its own subprocess: the denominator of the box target.

``--modes dense,krylov`` runs both contact solves on the same meshes (the crossover, written to
``results/scale3d_crossover.*``); the default is ``auto``.  A case is ``kind:maxh`` (P1) or
``kind:maxh:p2``.
Targets: the 166k box (maxh 0.018) ≤ 2× the elastic solve with ≤ 3 GB; the ≥ 500k-DOF pad in ≤ 15 min
from its mesh (meshing reported apart: it is cached after the first run).  NGSolve's reference is skipped
for the largest pads unless they are named in ``--cases``.

    .venv/bin/python benchmarks/scale3d.py [--quick] [--cases box:0.04,pad:0.002:p2] [--modes auto] [--name NAME]
"""
from __future__ import annotations

import json

import common as C
import numpy as np

SCENES = {"box": C.ROOT / "geometries" / "box3d.toml", "pad": C.ROOT / "geometries" / "brake_pad.toml"}
CASES = ("box:0.04", "box:0.025", "box:0.018", "box:0.08:p2", "box:0.05:p2", "box:0.035:p2",
         "pad:0.002", "pad:0.0011", "pad:0.0007", "pad:0.00063",
         "pad:0.004:p2", "pad:0.003:p2", "pad:0.002:p2", "pad:0.0014:p2", "pad:0.0012:p2")
QUICK_CASES = ("box:0.04", "pad:0.004", "pad:0.008:p2")
STEPS = 100
NO_ELASTIC = ("pad:0.0007", "pad:0.00063", "pad:0.0014:p2", "pad:0.0012:p2")   # no NGSolve reference by default
BOX_TARGET = ("box", 0.018)
BOX_RATIO, BOX_MEMORY_GB, PAD_MINUTES = 2.0, 3.0, 15.0
SERIES = [(kind, order, mode) for kind in ("box", "pad") for order in (1, 2) for mode in ("dense", "krylov")]


def parse_case(case: str) -> tuple[str, float, int]:
    """``kind:maxh`` (P1) or ``kind:maxh:p2``."""
    kind, maxh, *order = case.split(":")
    return kind, float(maxh), int(order[0].lstrip("p")) if order else 1


def label(kind: str, maxh: float, order: int) -> str:
    return f"{kind}:{maxh:g}" + (f":p{order}" if order > 1 else "")


def scene_of(kind: str, maxh: float, order: int = 1):
    """The case's scene: 100 steps (the pad keeps its k = 1 s)."""
    import ngwear
    settings = {"mesh.maxh": maxh, "mesh.order": order, "time.steps": STEPS}
    if kind == "pad":
        settings["time.T"] = float(STEPS)
    return ngwear.load_scene(SCENES[kind]).replace(**settings)


# ---- one case, in its own process -------------------------------------------------------------------
def run_ngwear(kind: str, maxh: float, mode: str, remesh: bool, order: int = 1) -> dict:
    import resource

    import ngwear
    from ngwear.model.scene_mesh import build_mesh, cache_dir, mesh_key
    from ngwear.numerics import systems
    from ngwear.numerics.discrete import Discretization

    scene = scene_of(kind, maxh, order)
    cached = (cache_dir() / "meshes" / f"{mesh_key(scene)}.vol").is_file()
    t0 = C.perf()
    mesh = build_mesh(scene, use_cache=not remesh)
    t1 = C.perf()
    products = []
    respond = systems.normal_response
    systems.normal_response = lambda *a: (products.append(1), respond(*a))[1]
    disc = Discretization(scene, mesh, contact_solve=mode)
    t2 = C.perf()
    disc.elastic.stiffness  # noqa: B018 - timed stages, in dependency order
    t3 = C.perf()
    disc.elastic.operator  # noqa: B018
    t4 = C.perf()
    if not disc.matrix_free:
        disc.condensation.normal_compliance  # noqa: B018
    t5 = C.perf()
    disc.loads.u_load, disc.loads.s_load, disc.condensation.plate, disc.loads.plate_load  # noqa: B018
    t6 = C.perf()
    result = ngwear.simulate(scene, discretization=disc, progress=False)
    t7 = C.perf()
    loop_solves = None
    if disc.matrix_free:   # the loop's back-substitutions, timed apart on the same operator
        rhs = np.random.default_rng(0).standard_normal(disc.fes.ndof)
        times = [C.timed(disc.elastic.operator.solve, rhs)[0] for _ in range(5)]
        loop_solves = len(products) * C.median(times)
    return {
        "case": label(kind, maxh, order), "kind": kind, "maxh": maxh, "order": order,
        "mode": "krylov" if disc.matrix_free else "dense",
        "ndof": disc.fes.ndof, "free_dofs": C.free_dofs(disc), "contact_points": disc.points.n,
        "contact_dofs": len(disc.body.contact_dofs), "factor_nnz": disc.elastic.operator.factor_nonzeros,
        "mesh_cached": cached and not remesh, "mesh_s": t1 - t0,
        "mesh_first_s": None if cached and not remesh else t1 - t0,
        "init_s": t2 - t1, "assemble_s": t3 - t2, "factorise_s": t4 - t3, "rows_s": t5 - t4, "loads_s": t6 - t5,
        "loop_s": t7 - t6, "products": len(products), "loop_solves_s": loop_solves,
        "ngwear_s": t7 - t1, "status": result.status, "newton_its": C.newton_iterations(result),
        "max_wear": float(result.wear.max()), "peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6,
    }


def run_elastic(kind: str, maxh: float, order: int = 1) -> dict:
    import resource
    scene = scene_of(kind, maxh, order)
    mesh = C.mesh_for(scene)
    el = C.elastic_reference(scene, mesh)
    row = {"elastic_s": el["total"], "elastic_assemble_s": el["assemble"], "elastic_factorise_s": el["factorise"],
           "elastic_solve_s": el["solve"], "elastic_peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6}
    row["elastic_tm_s"] = C.elastic_reference(scene, mesh, taskmanager=True)["total"]
    return row


def in_subprocess(job: dict, blas_threads: int | None) -> dict:
    """Run ``job`` ({"fn": ..., args}) in a fresh interpreter of this script; its JSON result."""
    return C.in_subprocess(__file__, job, blas_threads)


# ---- the table ----------------------------------------------------------------------------------------
def fit(rows, x, y):
    """Least-squares slope of log y against log x over ``rows`` (None with fewer than 2 points)."""
    pts = [(r[x], r[y]) for r in rows if r.get(y)]
    if len(pts) < 2:
        return None
    return float(np.polyfit(*np.log(np.array(pts)).T, 1)[0])


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.add_argument("--cases", default=None, help="comma-separated kind:maxh (kind box or pad)")
    p.add_argument("--modes", default="auto", help="contact solve(s): auto, dense, krylov (comma-separated)")
    p.add_argument("--remesh", action="store_true", help="mesh every case anew (the first run's cost)")
    p.add_argument("--no-elastic", action="store_true", help="skip the NGSolve reference")
    p.add_argument("--name", default=None, help="results/NAME.* (default scale3d, or scale3d_crossover for two modes)")
    p.add_argument("--job", default=None, help=argparse_suppress())
    p.set_defaults(blas_threads=None)
    args = p.parse_args()
    if args.job:
        job = json.loads(args.job)
        with C.blas_limit(args.blas_threads):
            fn = run_ngwear if job.pop("fn") == "ngwear" else run_elastic
            print(json.dumps(fn(**job)))
        return
    cases = args.cases.split(",") if args.cases else list(QUICK_CASES if args.quick else CASES)
    modes = args.modes.split(",")
    header = C.machine_lines(args) + [
        f"{STEPS} steps per case (pad: k = 1 s); every case in a fresh process (peak memory = its ru_maxrss); "
        "elastic = NGSolve assemble + sparsecholesky + 1 solve (own process; sequential, and tm = in TaskManager); "
        "ngwear with the default threads (PARDISO and BLAS on both cores)",
        f"targets: box maxh 0.018 <= {BOX_RATIO:g}x elastic and <= {BOX_MEMORY_GB:g} GB; "
        f"pad >= 500k DOFs and >= 10k contact points in <= {PAD_MINUTES:g} min"]
    rows = []
    for case in cases:
        kind, maxh, order = parse_case(case)
        skip = args.no_elastic or (case in NO_ELASTIC and not args.cases)
        job = {"kind": kind, "maxh": maxh, "order": order}
        elastic = {} if skip else in_subprocess({"fn": "elastic", **job}, args.blas_threads)
        for mode in modes:
            row = in_subprocess({"fn": "ngwear", **job, "mode": mode, "remesh": args.remesh}, args.blas_threads)
            row.update(elastic)
            if elastic:
                row["ratio"] = row["ngwear_s"] / row["elastic_s"]
                row["ratio_tm"] = row["ngwear_s"] / row["elastic_tm_s"]
            row["target"] = verdict_of(row)
            rows.append(row)
            print(f"  {row['case']} {row['mode']}: {row['ndof']} DOFs, {row['contact_points']} points, "
                  f"ngwear {row['ngwear_s']:.1f}s (loop {row['loop_s']:.1f}s), elastic {row.get('elastic_s', 0):.1f}s, "
                  f"peak {row['peak_gb']:.2f} GB", flush=True)
    for kind, order, mode in SERIES:
        same = [r for r in rows if (r["kind"], r.get("order", 1), r["mode"]) == (kind, order, mode)]
        if len(same) >= 2:
            header.append(f"fitted growth, {kind} P{order} {mode}: time ~ DOFs^{fit(same, 'ndof', 'ngwear_s'):.2f}, "
                          f"~ points^{fit(same, 'contact_points', 'ngwear_s'):.2f}; memory ~ DOFs^"
                          f"{fit(same, 'ndof', 'peak_gb'):.2f}, ~ points^{fit(same, 'contact_points', 'peak_gb'):.2f}")
    columns = [("case", "case", None), ("mode", "solve", None), ("ndof", "DOFs", "d"),
               ("contact_points", "points", "d"), ("mesh_s", "mesh s", ".1f"), ("mesh_cached", "cached", None),
               ("assemble_s", "assemble", ".1f"), ("factorise_s", "factorise", ".1f"), ("rows_s", "ν rows", ".1f"),
               ("loop_s", "100 steps", ".1f"), ("products", "solves", "d"), ("ngwear_s", "ngwear s", ".1f"),
               ("elastic_s", "elastic s", ".1f"), ("ratio", "ratio", ".2f"), ("elastic_tm_s", "elastic tm", ".1f"),
               ("ratio_tm", "ratio tm", ".2f"), ("peak_gb", "peak GB", ".2f"),
               ("newton_its", "Newton", "d"), ("target", "target", None)]
    fig, (ax_t, ax_m) = C.new_figure(2)
    for (kind, order, mode), marker in zip(SERIES, "osD^v<>p"):
        same = [r for r in rows if (r["kind"], r.get("order", 1), r["mode"]) == (kind, order, mode)]
        if same:
            name = f"{kind} P{order}, {'matrix-free' if mode == 'krylov' else mode}"
            ax_t.loglog([r["ndof"] for r in same], [r["ngwear_s"] for r in same], marker + "-", label=name)
            ax_m.loglog([r["ndof"] for r in same], [r["peak_gb"] for r in same], marker + "-", label=name)
    with_elastic = [r for r in rows if r.get("elastic_s")]
    if with_elastic:
        ax_t.loglog([r["ndof"] for r in with_elastic], [r["elastic_s"] for r in with_elastic], "k+",
                    label="one NGSolve elastic solve")
    ax_t.set(xlabel="DOFs", ylabel="seconds (ngwear: 100 steps from the mesh)")
    ax_m.set(xlabel="DOFs", ylabel="peak memory, GB")
    for ax in (ax_t, ax_m):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    name = args.name or ("scale3d_crossover" if len(modes) > 1 else "scale3d")
    C.finish(name, "3D at scale", header, rows, columns, fig, args.quick and name == "scale3d")


def verdict_of(row) -> str:
    if (row["kind"], row["maxh"], row.get("order", 1)) == (*BOX_TARGET, 1) and row.get("ratio"):
        return C.verdict(row["ratio"] <= BOX_RATIO and row["peak_gb"] <= BOX_MEMORY_GB)
    if row["kind"] == "pad" and row["ndof"] >= 500_000 and row["contact_points"] >= 10_000:
        return C.verdict(row["ngwear_s"] <= PAD_MINUTES * 60)
    return "-"


def argparse_suppress():
    import argparse
    return argparse.SUPPRESS


if __name__ == "__main__":
    main()
