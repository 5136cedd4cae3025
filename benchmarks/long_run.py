"""A long run on a 3D part: what checkpoints and the per-step rows cost as the steps grow.

The brake pad (``geometries/brake_pad.toml``, P1, maxh 0.002: 32k DOFs, 1 889 contact points) runs N
steps of k = 0.02 s into an output folder with a checkpoint every 5 s of wall time, as ``ngwear run``
does, in a fresh process per case.  Reported: the time loop (checkpoints included), the time spent
writing checkpoints (all of them, and the last one), the result's final save (``result.npz``, VTU
frames), and the process's memory at the end: anonymous (``RssAnon``: the heap, which the kernel
cannot drop) and file-backed (``RssFile``: mapped files, which it can write out and drop), and the
peak (``ru_maxrss``, both).  A run records (4 + d) n_c numbers a step, 106 kB here; the 18k-point pad
of ``scale3d.py`` records 1 MB a step.

    .venv/bin/python benchmarks/long_run.py [--quick] [--steps 5000,10000,20000]
"""
from __future__ import annotations

import json
import tempfile
from pathlib import Path

import common as C

MAXH, STEP, CHECKPOINT_SECONDS = 0.002, 0.02, 5.0
STEPS = (5000, 10000, 20000)
QUICK_STEPS = (500,)


def run(steps: int) -> dict:
    import resource

    import ngwear
    import ngwear.runs.loop as checkpoint_module  # where the run's checkpoints are written from
    from ngwear.numerics.discrete import Discretization

    scene = ngwear.load_scene(C.ROOT / "geometries" / "brake_pad.toml").replace(**{
        "mesh.maxh": MAXH, "time.T": steps * STEP, "time.steps": steps, "output.every": steps * STEP / 4,
        "output.checkpoint_seconds": CHECKPOINT_SECONDS})
    disc = Discretization(scene, C.mesh_for(scene))
    writes = []
    write = checkpoint_module.write_checkpoint
    checkpoint_module.write_checkpoint = lambda *args: writes.append(C.timed(write, *args)[0])
    with tempfile.TemporaryDirectory() as out:
        t0 = C.perf()
        result = ngwear.simulate(scene, discretization=disc, progress=False, checkpoint=out)
        t1 = C.perf()
        result.save(out)
        t2 = C.perf()
        status = {k: int(v.split()[0]) / 1e6 for k, v in (line.split(":") for line in
                                                           Path("/proc/self/status").read_text().splitlines())
                  if k in ("RssAnon", "RssFile")}
        on_disk = sum(p.stat().st_size for p in Path(out).rglob("*") if p.is_file()) / 1e9
    row_bytes = sum(getattr(result, name)[0].nbytes for name in ("wear", "normal_displacement", "pressure",
                                                                 "reaction", "forces"))
    return {"steps": steps, "status": result.status, "contact_points": result.weights.size, "ndof": disc.fes.ndof,
            "rows_gb": row_bytes * (steps + 1) / 1e9, "loop_s": t1 - t0, "checkpoints": len(writes),
            "checkpoint_s": sum(writes), "last_checkpoint_s": writes[-1], "save_s": t2 - t1,
            "anon_gb": status["RssAnon"], "file_gb": status["RssFile"],
            "peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6, "disk_gb": on_disk,
            "max_wear": float(result.wear.max())}


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.add_argument("--steps", default=None, help="comma-separated step counts")
    p.add_argument("--job", default=None)
    p.set_defaults(blas_threads=None)
    args = p.parse_args()
    if args.job:
        print(json.dumps(run(**json.loads(args.job))))
        return
    counts = [int(s) for s in args.steps.split(",")] if args.steps else list(QUICK_STEPS if args.quick else STEPS)
    header = C.machine_lines(args) + [
        f"brake pad P1 maxh {MAXH:g}, k = {STEP:g} s, a checkpoint every {CHECKPOINT_SECONDS:g} s of wall time; "
        "each case in a fresh process; memory at the end of the run (RssAnon: heap; RssFile: mapped files)"]
    rows = []
    for steps in counts:
        row = C.in_subprocess(__file__, {"steps": steps}, args.blas_threads)
        row["checkpoint_share"] = row["checkpoint_s"] / row["loop_s"]
        rows.append(row)
        print(f"  {steps} steps: loop {row['loop_s']:.1f}s, {row['checkpoints']} checkpoints {row['checkpoint_s']:.2f}s "
              f"(last {row['last_checkpoint_s']:.3f}s), save {row['save_s']:.1f}s, heap {row['anon_gb']:.2f} GB",
              flush=True)
    columns = [("steps", "steps", "d"), ("contact_points", "points", "d"), ("rows_gb", "rows GB", ".2f"),
               ("loop_s", "time loop s", ".1f"), ("checkpoints", "checkpoints", "d"),
               ("checkpoint_s", "in checkpoints s", ".2f"), ("checkpoint_share", "share", ".1%"),
               ("last_checkpoint_s", "last s", ".3f"), ("save_s", "save s", ".1f"), ("anon_gb", "heap GB", ".2f"),
               ("file_gb", "mapped GB", ".2f"), ("peak_gb", "peak GB", ".2f"), ("disk_gb", "disk GB", ".2f"),
               ("status", "status", None)]
    fig, (ax_t, ax_m) = C.new_figure(2)
    steps = [r["steps"] for r in rows]
    ax_t.plot(steps, [r["loop_s"] for r in rows], "o-", label="time loop")
    ax_t.plot(steps, [r["checkpoint_s"] for r in rows], "s-", label="of which checkpoints")
    ax_t.plot(steps, [r["save_s"] for r in rows], "^-", label="final save")
    ax_m.plot(steps, [r["anon_gb"] for r in rows], "o-", label="heap (RssAnon)")
    ax_m.plot(steps, [r["file_gb"] for r in rows], "s-", label="mapped files (RssFile)")
    ax_m.plot(steps, [r["rows_gb"] for r in rows], "k:", label="the rows")
    ax_t.set(xlabel="steps", ylabel="seconds")
    ax_m.set(xlabel="steps", ylabel="GB at the end")
    for ax in (ax_t, ax_m):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    C.finish("long_run", "A long run on the brake pad: checkpoints and rows", header, rows, columns, fig, args.quick)


if __name__ == "__main__":
    main()
