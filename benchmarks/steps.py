"""Cost vs number of time steps (10, 100, 1000), marginal cost of one step vs one back-substitution.

Per size the Discretization is built once (its setup time is reported); then the time loop
``simulate(scene.replace(time.steps=S), discretization=disc)`` is timed for S = 10, 100, 1000 (T = 1
fixed, so k = T/S; S = 10 is the paper's literal k = 0.1, for which ngwear warns that explicit wear
oscillates), interleaved over repetitions, with the BLAS pools limited to 1 and to 2 threads.

Linear fit  t(S) = a + b (S + 1)  on the medians (relative least squares), and the local exponents
d log t / d log S (1 = linear; S = 10 → 100 also changes k, hence Newton iterations per step):
b is the marginal cost of one more step, compared
with one back-substitution with the elastic factorisation (``disc.elastic.operator.solve(rhs)``, SuperLU)
and with NGSolve's sparsecholesky back-substitution (``inv * f``).  ``Recording.append`` (the per-step
bookkeeping; O(S²) in total if it re-concatenated the arrays) is timed on
its own (S appends of arrays of the run's shapes) and extrapolated quadratically to 10 000 steps.
Targets: b ≤ one back-substitution; t(S) linear in S.

``--extra 10000`` adds single runs at larger step counts (shown, not fitted).

    /work/venv/bin/python benchmarks/steps.py [--quick] [--sizes 10k,50k] [--orders 1] [--extra 10000]
"""
from __future__ import annotations

import logging

import common as C
import numpy as np

import ngwear
from ngwear.numerics.contact import Instant
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.systems.newton import NewtonRecord
from ngwear.results.recording import Recording
from ngwear.runs.step import State

STEP_COUNTS = (10, 100, 1000)
THREADS = (1, 2)


def median_call(fn, n=20):
    return C.median([C.timed(fn)[0] for _ in range(n)])


def setup(scene, mesh) -> tuple[Discretization, float]:
    t = C.perf()
    disc = Discretization(scene, mesh)
    disc.condensation.normal_compliance, disc.loads.s_load, disc.loads.u_load  # noqa: B018 - all simulate needs
    return disc, C.perf() - t


def backsubstitutions(disc, scene, mesh) -> dict:
    rhs = disc.loads.load
    ours = median_call(lambda: disc.elastic.operator.solve(rhs))
    a = ngwear.numerics.forms.elastic_form(disc.fes, disc.elastic.laws)
    a.Assemble()
    f = ngwear.numerics.forms.load_form(disc.fes, scene)
    f.Assemble()
    inv = a.mat.Inverse(disc.fes.FreeDofs(), inverse="sparsecholesky")
    v = f.vec.CreateVector()

    def ngs_solve():
        v.data = inv * f.vec
    ngs_t = median_call(ngs_solve)
    return {"backsub_superlu_ms": 1e3 * ours, "backsub_ngs_ms": 1e3 * ngs_t}


def append_cost(disc, scene, steps: int) -> float:
    """Seconds of ``steps + 1`` Recording.append calls with arrays of this run's shapes."""
    n, d = disc.points.n, scene.dim
    recording = Recording.start(scene.replace(**{"time.steps": steps}), disc)
    z, f = np.zeros(n), np.zeros((n, d))
    states = [State(z, z, disc.contact.coefficients, z, Instant(j * 1e-3, 1.0, 1.0), normal=z, pressure=z,
                    plate=np.zeros(0), forces=f, record=NewtonRecord()) for j in range(steps + 1)]
    t = C.perf()
    for state in states:
        recording.append(state)
    return C.perf() - t


def measure(size, order, args) -> list[dict]:
    scene = C.scene_for(size, order)
    mesh = C.mesh_for(scene)
    with C.blas_limit(args.blas_threads):
        disc, setup_s = setup(scene, mesh)
        bs = backsubstitutions(disc, scene, mesh)
    base = {"size": size, "order": order, "free_dofs": C.free_dofs(disc), "contact_points": disc.points.n,
            "setup_s": setup_s, **bs}
    scenes = {s: scene.replace(**{"time.steps": s}) for s in STEP_COUNTS}
    rows = []
    for threads in THREADS:
        with C.blas_limit(threads):
            funcs = {s: (lambda sc=sc: ngwear.simulate(sc, discretization=disc, progress=False))
                     for s, sc in scenes.items()}
            C.interleaved({10: funcs[10]}, 1)  # warm-up (first-call overheads)
            times, outs = C.interleaved(funcs, args.reps)
        med = {s: C.median(times[s]) for s in STEP_COUNTS}
        x = np.array([s + 1 for s in STEP_COUNTS], float)
        y = np.array([med[s] for s in STEP_COUNTS])
        b, a = np.polyfit(x, y, 1, w=1 / y)  # relative least squares: the points span 2 decades
        fit = a + b * x
        rel_res = np.abs(fit - y) / y
        r2 = 1 - np.sum((y - fit) ** 2) / np.sum((y - y.mean()) ** 2)
        exp_hi = np.log(med[1000] / med[100]) / np.log(1001 / 101)
        exp_lo = np.log(med[100] / med[10]) / np.log(101 / 11)
        slope_hi = (med[1000] - med[100]) / 900
        slope_lo = (med[100] - med[10]) / 90
        for s in STEP_COUNTS:
            its = C.newton_iterations(outs[s])
            rows.append({**base, "blas_threads": threads, "steps": s, "loop_s": med[s],
                         "loop_min_s": min(times[s]), "total_s": setup_s + med[s], "newton_its": its,
                         "its_per_step": its / (s + 1), "ms_per_step": 1e3 * med[s] / (s + 1),
                         "ms_per_newton_it": 1e3 * med[s] / its, "status": outs[s].status,
                         "fit_ms_per_step": 1e3 * b, "fit_intercept_s": a, "fit_r2": r2,
                         "fit_max_rel_residual": float(rel_res.max()),
                         "marginal_100_1000_ms": 1e3 * slope_hi, "marginal_10_100_ms": 1e3 * slope_lo,
                         "exponent_10_100": exp_lo, "exponent_100_1000": exp_hi})
    # O(S²) bookkeeping, measured alone
    ap = {s: append_cost(disc, scene, s) for s in (100, 1000, 3000)}
    quad = np.polyfit([101, 1001, 3001], [ap[100], ap[1000], ap[3000]], 2)
    for r in rows:
        r["append_s"] = ap.get(r["steps"], append_cost(disc, scene, r["steps"]))
        r["append_10000_extrap_s"] = float(np.polyval(quad, 10001))
    best = min(THREADS, key=lambda t: next(r["loop_s"] for r in rows
                                           if r["blas_threads"] == t and r["steps"] == 1000))
    for r in rows:
        r["faster_threads_1000"] = best
        backsub = min(r["backsub_superlu_ms"], r["backsub_ngs_ms"])
        r["target_marginal"] = C.verdict(r["fit_ms_per_step"] <= backsub)
        r["target_linear"] = C.verdict(r["exponent_100_1000"] <= 1.10 and r["fit_max_rel_residual"] <= 0.25)
    return rows


def extra_runs(size, order, counts, args) -> list[dict]:
    """One run each at larger step counts (not in the fit), to check linearity beyond 1000 steps."""
    scene = C.scene_for(size, order)
    mesh = C.mesh_for(scene)
    rows = []
    with C.blas_limit(args.blas_threads):
        disc, setup_s = setup(scene, mesh)
        for s in counts:
            sc = scene.replace(**{"time.steps": s})
            dt, res = C.timed(ngwear.simulate, sc, discretization=disc, progress=False)
            its = C.newton_iterations(res)
            rows.append({"size": size, "order": order, "free_dofs": C.free_dofs(disc),
                         "contact_points": disc.points.n, "blas_threads": args.blas_threads, "steps": s,
                         "loop_s": dt, "total_s": setup_s + dt, "newton_its": its,
                         "its_per_step": its / (s + 1),
                         "ms_per_step": 1e3 * dt / (s + 1), "ms_per_newton_it": 1e3 * dt / its,
                         "append_s": append_cost(disc, scene, s), "status": res.status, "extra": True})
    return rows


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.set_defaults(orders="1")
    p.add_argument("--extra", default="", help="extra step counts, one run each, not fitted (e.g. 10000)")
    args = p.parse_args()
    # S = 10 has k α L = 1.5 > 1: ngwear warns (once per run) that explicit wear oscillates
    logging.getLogger("ngwear").setLevel(logging.ERROR)
    sizes = C.selected_sizes(args, default=("10k", "50k"))
    header = C.machine_lines(args) + [
        "loop = simulate(scene.replace(time.steps=S), discretization=disc) with disc built once (setup); "
        "BLAS threads 1 vs 2 in the loop",
        "targets: fitted marginal cost per step <= one back-substitution (SuperLU disc.elastic.operator.solve and "
        "NGSolve sparsecholesky); t(S) linear: local exponent d log t / d log S between 100 and 1000 steps "
        "<= 1.10 and every point within 25% of the (relative least-squares) linear fit"]
    rows = []
    for order in C.selected_orders(args):
        for size in sizes:
            new = measure(size, order, args)
            rows += new
            for r in new:
                if r["steps"] == 1000:
                    print(f"  P{order} {size} {r['blas_threads']} thr: {r['fit_ms_per_step']:.3f} ms/step "
                          f"(backsub {r['backsub_superlu_ms']:.2f} ms SuperLU, "
                          f"{r['backsub_ngs_ms']:.2f} ms NGSolve)",
                          flush=True)
    extra = [int(x) for x in args.extra.split(",") if x.strip()]
    if extra:
        for order in C.selected_orders(args):
            for size in sizes:
                rows += extra_runs(size, order, extra, args)
    columns = [("order", "P", None), ("size", "size", None), ("free_dofs", "free DOFs", "d"),
               ("contact_points", "n_c", "d"), ("blas_threads", "BLAS thr", "d"), ("steps", "steps", "d"),
               ("loop_s", "loop [s]", ".3f"), ("total_s", "setup+loop [s]", ".3f"),
               ("its_per_step", "its/step", ".2f"), ("ms_per_newton_it", "ms/it", ".3f"),
               ("append_s", "append [s]", ".3f"), ("fit_ms_per_step", "fit ms/step", ".3f"),
               ("marginal_100_1000_ms", "Δ100→1000 ms/step", ".3f"),
               ("backsub_superlu_ms", "backsub SuperLU ms", ".2f"),
               ("backsub_ngs_ms", "backsub NGS ms", ".2f"),
               ("exponent_10_100", "exp 10→100", ".2f"), ("exponent_100_1000", "exp 100→1000", ".2f"),
               ("fit_max_rel_residual", "fit max rel res", ".2f"),
               ("target_marginal", "marginal<=backsub", None), ("target_linear", "linear", None)]
    fig, (ax1, ax2) = C.new_figure(2)
    for (order, size), marker in zip(sorted({(r["order"], r["size"]) for r in rows}), "osd^v<>"):
        for threads, ls in zip(THREADS, ("-", ":")):
            sub = [r for r in rows if r["order"] == order and r["size"] == size
                   and r["blas_threads"] == threads and not r.get("extra")]
            x = np.array([r["steps"] + 1 for r in sub])
            ax1.loglog(x, [r["loop_s"] for r in sub], marker + ls, label=f"P{order} {size}, {threads} thr")
            fx = np.geomspace(x.min(), x.max(), 50)
            ax1.loglog(fx, sub[0]["fit_intercept_s"] + 1e-3 * sub[0]["fit_ms_per_step"] * fx, "k-", lw=0.5)
        one = [r for r in rows if r["order"] == order and r["size"] == size and not r.get("extra")]
        ext = [r for r in rows if r["order"] == order and r["size"] == size and r.get("extra")]
        if ext:
            ax1.loglog([r["steps"] + 1 for r in ext], [r["loop_s"] for r in ext], "k*", ms=10,
                       label=f"P{order} {size} extra (1 run)")
        lab = f"P{order} {size}"
        ax2.bar([lab + "\nstep 1thr", lab + "\nstep 2thr", lab + "\nSuperLU", lab + "\nNGS"],
                [next(r["fit_ms_per_step"] for r in one if r["blas_threads"] == 1),
                 next(r["fit_ms_per_step"] for r in one if r["blas_threads"] == 2),
                 one[0]["backsub_superlu_ms"], one[0]["backsub_ngs_ms"]],
                color=["C0", "C1", "C2", "C3"])
    ax1.set(xlabel="steps + 1", ylabel="loop time [s]", title="time loop vs steps (black: linear fit)")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=7)
    ax2.set(ylabel="ms", title="marginal cost per step vs one back-substitution", yscale="log")
    ax2.tick_params(axis="x", labelsize=6, rotation=90)
    C.finish("steps", "cost vs number of steps", header, rows, columns, fig, quick=args.quick)


if __name__ == "__main__":
    main()
