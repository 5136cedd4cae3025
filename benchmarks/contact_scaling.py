"""Fine contact faces: set-up + 100 steps against one elastic solve, before and after, as Γ_C is refined.

Cases: the pin ``geometries/pin_on_disc.toml`` (a spherical cap on a turning disc, held by its plate alone; 100
steps over its 60 s) at ``mesh.contact_maxh`` = 0.3, 0.15, 0.1, 0.07 mm (a case ``pin:0.1``), and the shipped
brake pad ``geometries/brake_pad.toml`` (100 steps, k = 1 s) at ``mesh.maxh`` = 0.004, 0.002, 0.0011 m
(``pad:0.002``).  Two contact solves on the same mesh:

* ``before``: today's (main's) choice: dense with the Schur complement up to its limits, else matrix-free GCR with
  recycling (``contact_solve="krylov"``: the same result arrays as main's matrix-free path to the bit, compared on
  the pin and the pad at 0.004 when the patch was added);
* ``after``: ``auto``, which now solves a matrix-free problem on its contact patch (``numerics/systems/patch.py``) when the
  rigid body's patch is at most 90 % of Γ_C, and by GCR otherwise.

Every measurement runs in a fresh process: ``elastic`` is one NGSolve linear-elastic solve on the same mesh and
space (assemble + ``sparsecholesky`` + solve, the yardstick), ``ngwear`` is ``Discretization`` + its set-up
stages (assembly, PARDISO, loads, plate) + ``simulate``.  Reported: set-up, the first step (from rest), ms per later
step (mean; median of the steps that compute no column), ratio (set-up + steps) / elastic, in wall and in CPU time
(the machine is shared: CPU time is less sensitive to the load), Newton iterations, right-hand sides solved with K's
factor in the steps ("rhs": GCR's products, or the patch's columns) and the solves they took, and the largest
difference between before and after relative to the largest value (wear, pressure, normal displacement).
``--crossover`` runs both matrix-free solves on the pin at 0.15 mm pressed harder and with flatter ends (the rigid
body's patch from 8 % of Γ_C to all of it: "rigid share", ``numerics.systems.patch_share``; "touched": the share of the
points in contact at some step) and on the pad: the measured crossover behind ``PATCH_SHARE``.

``--profile`` counts, for GCR and the patch on the pins at 0.15, 0.1, 0.07 mm, step 0's and the later steps' Newton
iterations, back-substitutions, GCR's products and pattern changes, and splits the loop's time by cProfile.

    .venv/bin/python benchmarks/contact_scaling.py [--quick] [--reps 1] [--cases pin:0.1,pad:0.002] [--crossover]
    .venv/bin/python benchmarks/contact_scaling.py --profile
"""
from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import common as C
import numpy as np

SCENES = {"pin": C.ROOT / "geometries" / "pin_on_disc.toml", "pad": C.ROOT / "geometries" / "brake_pad.toml"}
CASES = ("pin:0.3", "pin:0.15", "pin:0.1", "pin:0.07", "pad:0.004", "pad:0.002", "pad:0.0011")
QUICK_CASES = ("pin:0.3", "pad:0.004")
PROFILED = ("pin:0.15", "pin:0.1", "pin:0.07")
CROSSOVER = ("pin:0.15", "pin:0.15:100", "pin:0.15:1000", "pin:0.15:10000", "pin:0.15:100:0.02", "pin:0.15:100:0.05",
             "pin:0.15:1000:0.05", "pad:0.004", "pad:0.002")
STEPS = 100
TARGET = 5.0
FIELDS = ("wear", "pressure", "normal_displacement")


def scene_of(case: str):
    """``pin:contact_maxh_mm[:force_N[:end_radius_m]]`` or ``pad:maxh_m``, 100 steps."""
    import ngwear
    kind, size, *more = case.split(":")
    scene = ngwear.load_scene(SCENES[kind])
    if kind == "pin":
        settings = {"mesh.contact_maxh": float(size) * 1e-3, "time.steps": STEPS}
        if more:
            settings["loads.plate.force"] = [0.0, 0.0, -float(more[0])]
        if len(more) > 1:
            settings["geometry.end_radius"] = float(more[1])
        return scene.replace(**settings)
    return scene.replace(**{"mesh.maxh": float(size), "time.steps": STEPS, "time.T": float(STEPS)})


# ---- one measurement, in its own process -------------------------------------------------------------
def run_ngwear(case: str, mode: str, out: str) -> dict:
    import time

    import ngwear
    from ngwear.numerics.discrete import Discretization
    from ngwear.numerics.systems import patch_share
    from ngwear.runs import loop

    scene = scene_of(case)
    mesh = C.mesh_for(scene)
    wall, cpu = C.perf(), time.process_time()
    disc = Discretization(scene, mesh, contact_solve=mode)
    for _, build in disc.stages():
        build()
    setup, setup_cpu = C.perf() - wall, time.process_time() - cpu
    solves = {"calls": 0, "rhs": 0}
    solve = disc.elastic.operator.solve

    def counted(rhs):
        solves["calls"] += 1
        solves["rhs"] += 1 if np.ndim(rhs) == 1 else np.shape(rhs)[1]
        return solve(rhs)
    disc.elastic.operator.solve = counted
    steps, chosen = [], {}
    step = loop.advance

    def timed(solved, caches, *args):
        wall, cpu, rhs = C.perf(), time.process_time(), solves["rhs"]
        try:
            return step(solved, caches, *args)
        finally:
            steps.append((C.perf() - wall, time.process_time() - cpu, solves["rhs"] - rhs))
            chosen["path"] = ("patch" if caches.base.caches.patch else "krylov") if disc.matrix_free else "dense"
    loop.advance = timed
    wall, cpu = C.perf(), time.process_time()
    result = ngwear.simulate(scene, discretization=disc, progress=False)
    loop, loop_cpu = C.perf() - wall, time.process_time() - cpu
    np.savez(out, **{name: getattr(result, name) for name in FIELDS})
    steps = np.array(steps)
    later = steps[1:]
    quiet = later[later[:, 2] == 0]
    return {"case": case, "mode": mode, "path": chosen.get("path"), "status": result.status,
            "share": patch_share(disc), "touched": float(np.logical_or.reduce(result.pressure > 0).mean()),
            "points": disc.points.n, "ndof": disc.fes.ndof, "setup_s": setup, "setup_cpu_s": setup_cpu,
            "first_s": steps[0, 0], "later_ms": 1e3 * later[:, 0].mean(), "later_cpu_ms": 1e3 * later[:, 1].mean(),
            "quiet_cpu_ms": 1e3 * np.median(quiet[:, 1]) if len(quiet) else None,
            "loop_s": loop, "loop_cpu_s": loop_cpu, "step_ms": 1e3 * loop / STEPS,
            "ngwear_s": setup + loop, "ngwear_cpu_s": setup_cpu + loop_cpu,
            "newton": C.newton_iterations(result), "rhs": solves["rhs"], "calls": solves["calls"],
            "max_wear": float(result.wear.max())}


def run_elastic(case: str) -> dict:
    import time
    scene = scene_of(case)
    cpu = time.process_time()
    reference = C.elastic_reference(scene, C.mesh_for(scene))
    return {"elastic_s": reference["total"], "elastic_cpu_s": time.process_time() - cpu}


def measure(case: str, modes: list[str], labels: list[str], reps: int, threads, folder: Path) -> list[dict]:
    """Elastic, then each mode, ``reps`` times interleaved (each in a fresh process); medians; the modes compared."""
    runs, elastic = {mode: [] for mode in modes}, []
    for _ in range(reps):
        elastic.append(C.in_subprocess(__file__, {"fn": "elastic", "case": case}, threads))
        for mode in modes:
            out = str(folder / f"{case.replace(':', '_')}_{mode}.npz")
            runs[mode].append(C.in_subprocess(__file__, {"fn": "ngwear", "case": case, "mode": mode, "out": out},
                                              threads))
    rows = []
    for mode, label in zip(modes, labels):
        row = dict(runs[mode][-1], version=label)
        for key in ("setup_s", "setup_cpu_s", "first_s", "later_ms", "later_cpu_ms", "loop_s", "loop_cpu_s", "step_ms",
                    "ngwear_s", "ngwear_cpu_s"):
            row[key] = C.median([r[key] for r in runs[mode]])
        row["elastic_s"] = C.median([r["elastic_s"] for r in elastic])
        row["elastic_cpu_s"] = C.median([r["elastic_cpu_s"] for r in elastic])
        row["ratio"] = row["ngwear_s"] / row["elastic_s"]
        row["ratio_cpu"] = row["ngwear_cpu_s"] / row["elastic_cpu_s"]
        row["reps"] = reps
        rows.append(row)
    if len(modes) == 2:
        first, second = (np.load(folder / f"{case.replace(':', '_')}_{mode}.npz") for mode in modes)
        rows[-1]["difference"] = max(np.abs(first[f] - second[f]).max() / np.abs(first[f]).max() for f in FIELDS)
    for row in rows:
        print(f"  {case} {row['version']} ({row['path']}): {row['points']} points, set-up {row['setup_s']:.2f} s, "
              f"100 steps {row['loop_s']:.2f} s, elastic {row['elastic_s']:.2f} s, ratio {row['ratio']:.2f} "
              f"(cpu {row['ratio_cpu']:.2f}), rhs {row['rhs']}", flush=True)
    return rows


def before(case: str) -> str:
    """The path of main for the case: dense where ``auto`` keeps the Schur complement, else GCR (``krylov``)."""
    return "krylov" if C.in_subprocess(__file__, {"fn": "matrix_free", "case": case}, None)["matrix_free"] else "dense"


def run_profile(case: str, mode: str) -> dict:
    """Step 0 and the later steps' mean of the counts and the CPU time; where the loop's seconds go (cProfile, wall).

    Counted: Newton iterations, back-substitutions (and their right-hand sides), GCR's products, pattern changes.
    """
    import cProfile
    import pstats
    import time

    import ngwear
    from ngwear.numerics import recycle
    from ngwear.numerics.discrete import Discretization
    from ngwear.numerics.systems import condensed
    from ngwear.runs import step as stepping

    scene = scene_of(case)
    disc = Discretization(scene, C.mesh_for(scene), contact_solve=mode)
    for _, build in disc.stages():
        build()
    count = {"solves": 0, "rhs": 0, "gcr": 0, "changes": 0, "active_changes": 0}
    solve, minimise, step, newton = (disc.elastic.operator.solve, recycle.Recycler._minimise,
                                     condensed.CondensedSystem.step, stepping._newton)
    last, rows = {}, []

    def counted(rhs):
        count["solves"] += 1
        count["rhs"] += 1 if np.ndim(rhs) == 1 else np.shape(rhs)[1]
        return solve(rhs)

    def gcr(self, *args):
        products = self.memory.products
        try:
            return minimise(self, *args)
        finally:
            count["gcr"] += self.memory.products - products

    def stepped(self, x, lam, active):
        pattern = (self.law.derivative(x[:self.n] - self.d0) > 0, active.copy())
        if last:
            count["changes"] += not all(np.array_equal(a, b) for a, b in zip(pattern, last["pattern"]))
            count["active_changes"] += not np.array_equal(active, last["pattern"][1])
        last["pattern"] = pattern
        return step(self, x, lam, active)

    def timed(*args):
        before, cpu = dict(count), time.process_time()
        out = newton(*args)
        rows.append({"newton": out[2].iterations, "cpu_ms": 1e3 * (time.process_time() - cpu),
                     **{key: count[key] - before[key] for key in count}})
        return out
    disc.elastic.operator.solve, recycle.Recycler._minimise = counted, gcr
    condensed.CondensedSystem.step, stepping._newton = stepped, timed
    profile = cProfile.Profile()
    wall = C.perf()
    profile.runcall(ngwear.simulate, scene, discretization=disc, progress=False)
    loop = C.perf() - wall
    stats = pstats.Stats(profile).stats

    def seconds(*names):
        return sum(v[3] for k, v in stats.items() if any(k[0].endswith(f) and k[2] == fn for f, fn in names))
    out = {"case": case, "mode": mode, "points": disc.points.n, "loop_s": loop,
           "backsub_s": seconds(("pardiso.py", "_call")), "memory_s": seconds(("recycle.py", "__call__")) - seconds(
               ("pardiso.py", "_call")) if mode == "krylov" else 0.0,
           "recall_s": seconds(("recycle.py", "_recall")), "extend_s": seconds(("recycle.py", "_extend")),
           "lu_s": seconds(("_decomp_lu.py", "lu_factor"))}
    for key, part in (("step0", rows[:1]), ("later", rows[1:])):
        for name in rows[0]:
            out[f"{key}_{name}"] = float(np.mean([r[name] for r in part]))
    return out


def run_matrix_free(case: str) -> dict:
    from ngwear.numerics.discrete import Discretization
    scene = scene_of(case)
    return {"matrix_free": Discretization(scene, C.mesh_for(scene)).matrix_free}


def profile(args) -> None:
    """``--profile``: GCR (main's path) and the patch on the pins, each in a fresh process (results/contact_profile.*)."""
    cases = args.cases.split(",") if args.cases else list(PROFILED)
    rows = [C.in_subprocess(__file__, {"fn": "profile", "case": case, "mode": mode}, args.blas_threads)
            for case in cases for mode in ("krylov", "patch")]
    header = C.machine_lines(args) + [f"{STEPS} steps, cProfile on; step 0 and the later steps' mean: Newton iterations, "
                                      "back-substitutions (rhs), GCR's products, pattern changes (active set), CPU ms; "
                                      "the loop's wall seconds by part"]
    columns = [("case", "case", None), ("mode", "solve", None), ("points", "points", "d")] + [
        (f"{part}_{name}", f"{label} {name}", ".2f") for part, label in (("step0", "step 0:"), ("later", "later:"))
        for name in ("newton", "solves", "rhs", "gcr", "changes", "active_changes", "cpu_ms")] + [
        ("loop_s", "loop s", ".1f"), ("backsub_s", "back-subst. s", ".1f"), ("memory_s", "memory s", ".1f"),
        ("recall_s", "recall s", ".1f"), ("extend_s", "GCR QR s", ".1f"), ("lu_s", "LU s", ".2f")]
    C.finish(args.name or "contact_profile", "Profile of the pin's contact solve", header, rows, columns,
             None, args.quick)


def fit(rows, y) -> float | None:
    """Slope of log y against log points over ``rows``."""
    points = [(r["points"], r[y]) for r in rows if r.get(y)]
    return float(np.polyfit(*np.log(np.array(points)).T, 1)[0]) if len(points) >= 2 else None


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.add_argument("--cases", default=None, help="comma-separated pin:contact_maxh_mm[:force_N] or pad:maxh_m")
    p.add_argument("--crossover", action="store_true", help="both matrix-free solves on harder-pressed pins and pads")
    p.add_argument("--after-only", action="store_true", help="skip the path of before (e.g. to compare BLAS threads)")
    p.add_argument("--profile", action="store_true", help="counts and a cProfile of GCR and the patch on the pins")
    p.add_argument("--name", default=None, help="results/NAME.* (default contact_scaling, or contact_crossover)")
    p.add_argument("--job", default=None, help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.job:
        job = json.loads(args.job)
        with C.blas_limit(args.blas_threads):
            print(json.dumps({"ngwear": run_ngwear, "elastic": run_elastic, "matrix_free": run_matrix_free,
                              "profile": run_profile}[job.pop("fn")](**job)))
        return
    if args.profile:
        profile(args)
        return
    cases = args.cases.split(",") if args.cases else list(
        CROSSOVER if args.crossover else QUICK_CASES if args.quick else CASES)
    header = C.machine_lines(args) + [
        f"{STEPS} steps per case from the cached mesh, every measurement in a fresh process; elastic = NGSolve "
        "assemble + sparsecholesky + 1 solve; ratio = (set-up + steps) / elastic (wall; cpu: process time)",
        "before = main's path (dense, or GCR with recycling: contact_solve='krylov'); after = auto "
        f"(the patch, numerics/systems/patch.py, or GCR); target: pin after <= {TARGET:g}x elastic at 3.5k and 6.8k points"]
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for case in cases:
            modes, labels = (["krylov", "patch"], ["krylov", "patch"]) if args.crossover else (
                ["auto"], ["after"]) if args.after_only else ([before(case), "auto"], ["before", "after"])
            rows += measure(case, modes, labels, args.reps, args.blas_threads, Path(folder))
    for version in ("before", "after"):
        pins = [r for r in rows if r["case"].startswith("pin") and r["version"] == version and r["case"].count(":") == 1]
        if len(pins) >= 2:
            header.append(f"pin, {version}: ms per step ~ points^{fit(pins, 'step_ms'):.2f} (wall), later steps' cpu ~ "
                          f"points^{fit(pins, 'later_cpu_ms'):.2f}, steps computing no column ~ points^"
                          f"{fit(pins, 'quiet_cpu_ms') or float('nan'):.2f}; total ~ points^{fit(pins, 'ngwear_s'):.2f}")
    columns = [("case", "case", None), ("version", "version", None), ("path", "solve", None),
               ("points", "points", "d"), ("ndof", "DOFs", "d"), ("share", "rigid share", ".2f"),
               ("touched", "touched", ".2f"), ("setup_s", "set-up s", ".2f"),
               ("first_s", "first step s", ".2f"), ("later_ms", "ms/later step", ".1f"),
               ("quiet_cpu_ms", "cpu ms, no column", ".1f"), ("step_ms", "ms/step", ".1f"),
               ("ngwear_s", "ngwear s", ".2f"), ("elastic_s", "elastic s", ".2f"), ("ratio", "ratio", ".2f"),
               ("ratio_cpu", "ratio cpu", ".2f"), ("newton", "Newton", "d"), ("rhs", "rhs", "d"),
               ("calls", "solves", "d"), ("difference", "before-after", ".1e")]
    fig, (ax,) = C.new_figure(1)
    for kind, version, marker in (("pin", "before", "o--"), ("pin", "after", "o-"), ("pad", "before", "s--"),
                                  ("pad", "after", "s-")):
        same = [r for r in rows if r["case"].startswith(kind) and r["version"] == version]
        if same:
            ax.loglog([r["points"] for r in same], [r["ratio"] for r in same], marker, label=f"{kind}, {version}")
    ax.axhline(TARGET, color="k", lw=0.8, ls=":")
    ax.set(xlabel="contact points", ylabel="(set-up + 100 steps) / one elastic solve")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    name = args.name or ("contact_crossover" if args.crossover else "contact_scaling")
    C.finish(name, "Fine contact faces: set-up + 100 steps / one elastic solve", header, rows, columns, fig,
             args.quick)


if __name__ == "__main__":
    main()
