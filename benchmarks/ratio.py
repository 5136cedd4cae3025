"""Simulation time / one linear-elastic solve, at ~2k, 10k, 50k, 200k free DOFs, P1 and P2.

Numerator ("fast"): the whole fast path from a given mesh, ``Discretization(scene, mesh)`` +
``ngwear.simulate`` of the 100-step paper scene (space, contact points, stiffness, factorisation
with Schur extraction, G, H, K⁻¹f and all time steps; no output).
Denominator ("elastic"): one linear-elastic solve with NGSolve on the same mesh and space:
``BilinearForm`` + ``Assemble`` (and the load form), ``Inverse(FreeDofs, "sparsecholesky")``, one
solve; once sequential (as ngwear runs) and once inside ``ngs.TaskManager()`` (2 threads).
Repetitions are interleaved (elastic, elastic+TaskManager, fast, elastic, ...) and the ratios are
of medians measured in the same run.  Target: ratio ≤ 10 at ~10k and ~50k DOFs, P1.

    /work/venv/bin/python benchmarks/ratio.py [--quick] [--reps 3] [--sizes 2k,10k] [--orders 1,2]
"""
from __future__ import annotations

import common as C

TARGET = 10.0
TARGET_SIZES = ("10k", "50k")


def measure(size: str, order: int, reps: int) -> dict:
    scene = C.scene_for(size, order)
    mesh = C.mesh_for(scene)
    funcs = {
        "elastic": lambda: C.elastic_reference(scene, mesh),
        "elastic_tm": lambda: C.elastic_reference(scene, mesh, taskmanager=True),
        "fast": lambda: C.fast_run(scene, mesh),
    }
    times, outs = C.interleaved(funcs, reps)
    result = outs["fast"]
    disc = result.discretization
    fast, ref, ref_tm = (C.median(times[k]) for k in ("fast", "elastic", "elastic_tm"))
    per_rep = [f / e for f, e in zip(times["fast"], times["elastic"])]
    per_rep_tm = [f / e for f, e in zip(times["fast"], times["elastic_tm"])]
    el = outs["elastic"]
    row = {
        "size": size, "order": order, "maxh": scene.mesh.maxh, "free_dofs": C.free_dofs(disc),
        "contact_points": disc.points.n, "steps": scene.time.steps, "status": result.status,
        "newton_its": C.newton_iterations(result), "reps": reps,
        "fast_s": fast, "fast_min_s": min(times["fast"]), "fast_max_s": max(times["fast"]),
        "elastic_s": ref, "elastic_assemble_s": el["assemble"], "elastic_factorise_s": el["factorise"],
        "elastic_solve_s": el["solve"], "elastic_tm_s": ref_tm,
        "ratio": fast / ref, "ratio_rep_median": C.median(per_rep),
        "ratio_tm": fast / ref_tm, "ratio_tm_rep_median": C.median(per_rep_tm),
    }
    row["target"] = (C.verdict(max(row["ratio"], row["ratio_tm"]) <= TARGET)
                     if order == 1 and size in TARGET_SIZES else "-")
    return row


def main():
    p = C.parser(__doc__.splitlines()[0])
    args = p.parse_args()
    header = C.machine_lines(args) + [
        "fast = Discretization(scene, mesh) + simulate (100 steps, mesh given); elastic = NGSolve assemble "
        "+ sparsecholesky + 1 solve (seq.; tm = inside TaskManager)",
        f"target: fast / elastic <= {TARGET:g} at ~10k and ~50k free DOFs, P1 "
        "(checked against both references)"]
    rows = []
    with C.blas_limit(args.blas_threads):
        for order in C.selected_orders(args):
            for size in C.selected_sizes(args):
                row = measure(size, order, args.reps)
                rows.append(row)
                print(f"  P{order} {size}: {row['free_dofs']} DOFs, fast {row['fast_s']:.3f}s, elastic "
                      f"{row['elastic_s']:.3f}s (tm {row['elastic_tm_s']:.3f}s), ratio {row['ratio']:.2f} "
                      f"(tm {row['ratio_tm']:.2f})", flush=True)
    columns = [("order", "P", None), ("size", "size", None), ("free_dofs", "free DOFs", "d"),
               ("contact_points", "n_c", "d"), ("newton_its", "Newton its", "d"),
               ("fast_s", "fast [s]", ".3f"), ("elastic_s", "elastic [s]", ".3f"),
               ("elastic_factorise_s", "(factorise)", ".3f"), ("elastic_tm_s", "elastic tm [s]", ".3f"),
               ("ratio", "fast/elastic", ".2f"), ("ratio_tm", "fast/elastic tm", ".2f"),
               ("ratio_rep_median", "median of rep ratios", ".2f"), ("target", "target <=10", None)]
    fig, (ax1, ax2) = C.new_figure(2)
    for order, marker in ((1, "o"), (2, "s")):
        sub = [r for r in rows if r["order"] == order]
        if not sub:
            continue
        x = [r["free_dofs"] for r in sub]
        ax1.loglog(x, [r["fast_s"] for r in sub], marker + "-", label=f"P{order} fast (sim, 100 steps)")
        ax1.loglog(x, [r["elastic_s"] for r in sub], marker + "--", label=f"P{order} one elastic solve")
        ax1.loglog(x, [r["elastic_tm_s"] for r in sub], marker + ":", label=f"P{order} elastic, TaskManager")
        ax2.semilogx(x, [r["ratio"] for r in sub], marker + "-", label=f"P{order} / elastic")
        ax2.semilogx(x, [r["ratio_tm"] for r in sub], marker + ":", label=f"P{order} / elastic (tm)")
    ax1.set(xlabel="free DOFs", ylabel="time [s]", title="time (median)")
    ax2.axhline(TARGET, color="r", lw=1, label="target 10")
    ax2.set(xlabel="free DOFs", ylabel="simulation / elastic solve", title="ratio (same run)", ylim=(0, None))
    for ax in (ax1, ax2):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    C.finish("ratio", "simulation time / one elastic solve (paper strip, 100 steps)", header, rows, columns,
             fig, quick=args.quick)


if __name__ == "__main__":
    main()
