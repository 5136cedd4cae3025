"""Fast (condensed) vs straightforward (solver.method = "full") on the same mesh and 100 steps.

Both timed from a given mesh: fast = ``Discretization`` + ``simulate`` (condensed; factorisation,
Schur extraction, G, all steps); full = ``Discretization`` + ``simulate`` with
``solver.method = "full"`` (NGSolve ``AssembleLinearization`` + scipy saddle-point ``spsolve`` at every
Newton iteration).

The full path is first *probed* on the first few steps of the same time grid (``time.steps = P``,
``time.T = P k``, identical to steps 0..P of the 100-step run): setup (Discretization, stiffness,
load, NGSolve contact form) and seconds per Newton iteration.  Its 100-step time is estimated as
setup + (s / iteration) × (Newton iterations of the fast 100-step run; both paths take the same
iterations, checked where both run).  If the estimate is within ``--full-budget`` seconds the full
100-step run is measured (its time is used); otherwise the extrapolated time is reported and marked
so.  ``--full-skip`` (default ``200k:2``) skips the full path entirely.
Target: full / fast ≥ 30.

    /work/venv/bin/python benchmarks/speedup.py [--quick] [--full-budget 150] [--full-skip 200k:2]
"""
from __future__ import annotations

import common as C
import numpy as np

import ngwear
from ngwear.numerics.discrete import Discretization

TARGET = 30.0
STEPS = 100


def full_probe(scene, mesh, probe_steps: int) -> dict:
    k = scene.dt
    probe = scene.replace(**{"time.steps": probe_steps, "time.T": probe_steps * k, "solver.method": "full"})
    t0 = C.perf()
    disc = Discretization(probe, mesh)
    disc.elastic.stiffness, disc.loads.load, disc.full_form  # noqa: B018 - what the full path builds before its loop
    t1 = C.perf()
    res = ngwear.simulate(probe, discretization=disc, progress=False)
    t2 = C.perf()
    its = C.newton_iterations(res)
    return {"setup": t1 - t0, "loop": t2 - t1, "its": its, "per_it": (t2 - t1) / max(its, 1),
            "result": res, "steps": probe_steps}


def max_diff(a, b, steps):
    m = min(steps + 1, len(a.normal_displacement), len(b.normal_displacement))
    return float(np.abs(a.normal_displacement[:m] - b.normal_displacement[:m]).max())


def measure(size, order, args, skip) -> dict:
    scene = C.scene_for(size, order)
    mesh = C.mesh_for(scene)
    times, outs = C.interleaved({"fast": lambda: C.fast_run(scene, mesh)}, args.reps)
    fast = outs["fast"]
    fast_s = C.median(times["fast"])
    its_fast = C.newton_iterations(fast)
    row = {"size": size, "order": order, "maxh": scene.mesh.maxh,
           "free_dofs": C.free_dofs(fast.discretization), "contact_points": fast.discretization.points.n,
           "steps": STEPS, "fast_s": fast_s, "fast_its": its_fast, "fast_reps": args.reps}
    if f"{size}:{order}" in skip:
        row.update(full_mode="skipped", full_s=None, speedup=None, target="-")
        return row
    probe_steps = 1 if C.SIZES[size] >= 200_000 else 2
    pr = full_probe(scene, mesh, probe_steps)
    estimate = pr["setup"] + pr["per_it"] * its_fast
    row.update(full_probe_steps=probe_steps, full_probe_its=pr["its"], full_setup_s=pr["setup"],
               full_per_it_s=pr["per_it"], full_estimate_s=estimate,
               probe_vs_fast_maxdiff=max_diff(pr["result"], fast, probe_steps))
    if estimate <= args.full_budget:
        reps = args.reps if estimate * args.reps <= 30 else 1
        full_scene = scene.replace(**{"solver.method": "full"})
        t, o = C.interleaved({"full": lambda: C.fast_run(full_scene, mesh)}, reps)
        full = o["full"]
        row.update(full_mode="measured", full_s=C.median(t["full"]), full_reps=reps,
                   full_its=C.newton_iterations(full), full_status=full.status,
                   full_vs_fast_maxdiff=max_diff(full, fast, STEPS))
    else:
        row.update(full_mode=f"extrapolated ({probe_steps}-step probe)", full_s=estimate, full_reps=0)
    row["speedup"] = row["full_s"] / fast_s
    row["target"] = C.verdict(row["speedup"] >= TARGET)
    return row


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.add_argument("--full-budget", type=float, default=150.0,
                   help="measure the full 100-step run only if its estimate is below this [s]")
    p.add_argument("--full-skip", default="200k:2",
                   help="size:order pairs without full path (comma-separated)")
    args = p.parse_args()
    skip = {s.strip() for s in args.full_skip.split(",") if s.strip()}
    header = C.machine_lines(args) + [
        f"paper strip, {STEPS} steps, mesh given; fast = condensed, full = solver.method 'full'; "
        f"full measured if estimated <= {args.full_budget:g} s, else extrapolated per Newton iteration",
        f"target: full / fast >= {TARGET:g}"]
    rows = []
    with C.blas_limit(args.blas_threads):
        for order in C.selected_orders(args):
            for size in C.selected_sizes(args):
                row = measure(size, order, args, skip)
                rows.append(row)
                full = C._fmt(row.get("full_s"), ".2f")
                print(f"  P{order} {size}: fast {row['fast_s']:.3f}s, full {full}s "
                      f"[{row['full_mode']}], speedup {C._fmt(row.get('speedup'), '.0f')}", flush=True)
    columns = [("order", "P", None), ("size", "size", None), ("free_dofs", "free DOFs", "d"),
               ("fast_its", "Newton its", "d"), ("fast_s", "fast [s]", ".3f"),
               ("full_per_it_s", "full s/it", ".3f"), ("full_estimate_s", "full est. [s]", ".1f"),
               ("full_s", "full [s]", ".2f"), ("full_mode", "full timing", None),
               ("full_its", "full its", "d"), ("full_vs_fast_maxdiff", "max|Δs|", ".1e"),
               ("speedup", "full/fast", ".0f"), ("target", "target >=30", None)]
    fig, (ax1, ax2) = C.new_figure(2)
    for order, marker in ((1, "o"), (2, "s")):
        sub = [r for r in rows if r["order"] == order]
        if not sub:
            continue
        x = [r["free_dofs"] for r in sub]
        ax1.loglog(x, [r["fast_s"] for r in sub], marker + "-", label=f"P{order} fast")
        xf = [r["free_dofs"] for r in sub if r.get("full_s")]
        ax1.loglog(xf, [r["full_s"] for r in sub if r.get("full_s")], marker + "--", label=f"P{order} full")
        ax2.semilogx(xf, [r["speedup"] for r in sub if r.get("full_s")], marker + "-", label=f"P{order}")
        ext = [r for r in sub if str(r.get("full_mode", "")).startswith("extrap")]
        ax2.semilogx([r["free_dofs"] for r in ext], [r["speedup"] for r in ext], "x", color="k", ms=10,
                     label="extrapolated" if order == 1 else None)
    ax1.set(xlabel="free DOFs", ylabel="time [s] (100 steps)", title="fast vs full")
    ax2.axhline(TARGET, color="r", lw=1, label="target 30")
    ax2.set(xlabel="free DOFs", ylabel="full / fast", title="speed-up (same mesh and steps)", yscale="log")
    for ax in (ax1, ax2):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    C.finish("speedup", "fast (condensed) vs straightforward (full) Newton", header, rows, columns, fig,
             quick=args.quick)


if __name__ == "__main__":
    main()
