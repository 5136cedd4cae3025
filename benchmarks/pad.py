"""The brake pad: 100 steps at three mesh sizes up to ≥ 100k DOFs, against one elastic solve.

``geometries/brake_pad.toml`` (an annular-sector pad held by its rigid back plate alone, pressed with
3 kN on a disc turning at 50 rad/s) at maxh 0.004, 0.002, 0.0011 (about 5k, 32k, 150k DOFs), 100 steps
with k = 1 s.  Numerator: ``Discretization(scene, mesh)`` + ``simulate`` from the cached mesh (the
contact solve chosen by size: dense with the Schur complement, or matrix-free); denominator: one
NGSolve linear-elastic solve on the same mesh and space (the back face clamped as in the pad's
factorisation: assemble + ``sparsecholesky`` + solve, sequential and inside ``TaskManager``).  Each
measurement runs in a fresh process (peak memory = its ``ru_maxrss``); repetitions alternate the two
and the ratio is of medians.  Target: ratio ≤ 10.

    .venv/bin/python benchmarks/pad.py [--quick] [--reps 3]
"""
from __future__ import annotations

import common as C
import scale3d as S

SIZES = (0.004, 0.002, 0.0011)
TARGET = 10.0


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.set_defaults(blas_threads=None)
    args = p.parse_args()
    sizes = SIZES[:1] if args.quick else SIZES
    header = C.machine_lines(args) + [
        f"{S.STEPS} steps (k = 1 s) from the cached mesh, each run in a fresh process; elastic = NGSolve assemble + "
        "sparsecholesky + 1 solve (seq.; tm = in TaskManager); medians of interleaved repetitions",
        f"target: ngwear / elastic <= {TARGET:g}"]
    rows = []
    for maxh in sizes:
        runs, refs = [], []
        for _ in range(args.reps):
            refs.append(S.in_subprocess({"fn": "elastic", "kind": "pad", "maxh": maxh}, args.blas_threads))
            runs.append(S.in_subprocess({"fn": "ngwear", "kind": "pad", "maxh": maxh, "mode": "auto",
                                         "remesh": False}, args.blas_threads))
        row = {k: runs[-1][k] for k in ("maxh", "mode", "ndof", "free_dofs", "contact_points", "status",
                                         "newton_its", "max_wear")}
        for key in ("ngwear_s", "assemble_s", "factorise_s", "rows_s", "loop_s", "peak_gb"):
            row[key] = C.median([r[key] for r in runs])
        for key in ("elastic_s", "elastic_tm_s", "elastic_peak_gb"):
            row[key] = C.median([r[key] for r in refs])
        row["ratio"] = row["ngwear_s"] / row["elastic_s"]
        row["ratio_tm"] = row["ngwear_s"] / row["elastic_tm_s"]
        row["reps"] = args.reps
        row["target"] = C.verdict(max(row["ratio"], row["ratio_tm"]) <= TARGET)
        rows.append(row)
        print(f"  maxh {maxh}: {row['ndof']} DOFs, {row['contact_points']} points, ngwear {row['ngwear_s']:.2f}s, "
              f"elastic {row['elastic_s']:.2f}s, ratio {row['ratio']:.2f}", flush=True)
    columns = [("maxh", "maxh", "g"), ("ndof", "DOFs", "d"), ("contact_points", "points", "d"), ("mode", "solve", None),
               ("ngwear_s", "ngwear s", ".2f"), ("loop_s", "100 steps", ".2f"), ("elastic_s", "elastic s", ".2f"),
               ("ratio", "ratio", ".2f"), ("elastic_tm_s", "elastic tm", ".2f"), ("ratio_tm", "ratio tm", ".2f"),
               ("peak_gb", "peak GB", ".2f"), ("elastic_peak_gb", "elastic GB", ".2f"), ("newton_its", "Newton", "d"),
               ("target", "target", None)]
    fig, (ax,) = C.new_figure(1)
    ax.loglog([r["ndof"] for r in rows], [r["ngwear_s"] for r in rows], "o-", label="ngwear, 100 steps")
    ax.loglog([r["ndof"] for r in rows], [r["elastic_s"] for r in rows], "s--", label="one NGSolve elastic solve")
    ax.set(xlabel="DOFs", ylabel="seconds", title="brake pad")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    C.finish("pad", "Brake pad: 100 steps vs one elastic solve", header, rows, columns, fig, args.quick)


if __name__ == "__main__":
    main()
