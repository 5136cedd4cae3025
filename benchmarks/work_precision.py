"""Run time against error on the paper's scene: which setting is cheapest for a given accuracy.

Every run is measured against ONE fine reference: P1, maxh = 0.025, 1600 trapezoidal steps (a
finer one, maxh 0.0125 with 3200 steps, makes every error evaluation 4× dearer: each step of each
run is interpolated onto the reference mesh, which would have four times the elements).
Errors in the paper's norms (:func:`ngwear.studies.verify.errors`): the displacement in ‖ε(u)‖
and the wear in L²(Γ_C), at T and summed over time; the table gives them relative to the reference's
own norms at T.  Families of runs:

* space: P1 at maxh 0.2 … 0.05 and P2 at 0.4 … 0.1, 400 trapezoidal steps (time error negligible);
* time: the three wear integrators at 25 … 800 uniform steps on the paper's mesh (maxh 0.05, P1);
* adaptive: ``time.adaptive`` at tolerances 1e-2 … 1e-4 (trapezoidal; implicit to 1e-3: a first-order
  stepper at 1e-4 takes thousands of steps, each evaluated against the reference), maxh 0.05.

Every error includes the space error of its mesh: the time and adaptive families level off at the
paper mesh's own error against the reference.

Wall time = ``simulate`` with the mesh cached (discretization, factorisation, time loop), median of
``--reps`` runs.  The Pareto front (no run both cheaper and more accurate) is marked; the summary
names the cheapest setting reaching 1 %, 0.1 % and 0.01 % relative wear error at T.
``--quick`` runs a small subset against a coarser reference (maxh 0.05, 800 steps).
"""
from __future__ import annotations

import common as C
import numpy as np

import ngwear
from ngwear.studies.verify import errors


def families(quick: bool) -> list[dict]:
    if quick:
        return ([{"family": "space P1", "mesh.maxh": h, "mesh.order": 1, "time.steps": 100,
                  "wear.integrator": "trapezoidal"} for h in (0.4, 0.2)]
                + [{"family": f"time {i}", "mesh.maxh": 0.2, "time.steps": n, "wear.integrator": i}
                   for i in ("explicit", "trapezoidal") for n in (25, 100)]
                + [{"family": "adaptive trapezoidal", "mesh.maxh": 0.2, "time.adaptive": True,
                    "time.tolerance": tol, "wear.integrator": "trapezoidal"} for tol in (1e-2, 1e-3)])
    space = ([{"family": "space P1", "mesh.maxh": h, "mesh.order": 1} for h in (0.2, 0.1, 0.05)]
             + [{"family": "space P2", "mesh.maxh": h, "mesh.order": 2} for h in (0.4, 0.2, 0.1)])
    for run in space:
        run.update({"time.steps": 400, "wear.integrator": "trapezoidal"})
    time = [{"family": f"time {i}", "mesh.maxh": 0.05, "time.steps": n, "wear.integrator": i}
            for i in ("explicit", "implicit", "trapezoidal") for n in (25, 50, 100, 200, 400, 800)]
    adaptive = [{"family": f"adaptive {i}", "mesh.maxh": 0.05, "time.adaptive": True, "time.tolerance": tol,
                 "wear.integrator": i} for i, tols in (("implicit", (1e-2, 1e-3)), ("trapezoidal", (1e-2, 1e-3, 1e-4)))
                for tol in tols]
    return space + time + adaptive


def norms(ref) -> tuple[float, float]:
    """‖ε(u_ref(T))‖ and ‖w_ref(T)‖_{L²(Γ_C)}: the scales of the relative errors."""
    import ngsolve as ngs
    disc = ref.discretization
    strain = ngs.Sym(ngs.Grad(disc.gridfunction(ref.displacement(-1))))
    energy = ngs.Integrate(ngs.InnerProduct(strain, strain), disc.mesh, definedon=disc.mesh.Materials("body"))
    return float(np.sqrt(energy)), float(np.sqrt(ref.wear[-1] @ (ref.weights * ref.wear[-1])))


def label(run: dict) -> str:
    if run.get("time.adaptive"):
        return f"tol {run['time.tolerance']:.0e}"
    if run["family"].startswith("space"):
        return f"maxh {run['mesh.maxh']}"
    return f"{run['time.steps']} steps"


def pareto(rows: list[dict]) -> None:
    """Mark the rows that no other row beats in both wall time and wear error."""
    for r in rows:
        r["pareto"] = "*" if not any(o["seconds"] <= r["seconds"] and o["W_final_rel"] < r["W_final_rel"]
                                     or o["seconds"] < r["seconds"] and o["W_final_rel"] <= r["W_final_rel"]
                                     for o in rows) else ""


def main() -> None:
    args = C.parser(__doc__.splitlines()[0]).parse_args()
    base = C.paper_scene()
    ref_settings = {"mesh.maxh": 0.05 if args.quick else 0.025, "time.steps": 800 if args.quick else 1600,
                    "wear.integrator": "trapezoidal", "output.every": 1.0}
    with C.blas_limit(args.blas_threads):
        ref = ngwear.simulate(base.replace(**ref_settings), progress=False)
        scale_u, scale_w = norms(ref)
        rows = []
        for run in families(args.quick):
            scene = base.replace(**{k: v for k, v in run.items() if k != "family"}, **{"output.every": 1.0})
            mesh = C.mesh_for(scene)
            seconds = []
            for _ in range(args.reps):
                start = C.perf()
                result = C.fast_run(scene, mesh)
                seconds.append(C.perf() - start)
            e = errors(result, ref)
            rows.append({"family": run["family"], "setting": label(run), "steps": result.steps,
                         "free_dofs": C.free_dofs(result.discretization), "seconds": C.median(seconds),
                         "W_final_rel": e.W_final / scale_w, "V_final_rel": e.V_final / scale_u,
                         "W_sum": e.W_sum, "V_sum": e.V_sum})
            print(f"{run['family']:22s} {label(run):12s} {rows[-1]['seconds']:8.3f} s  "
                  f"wear {rows[-1]['W_final_rel']:.2e}", flush=True)
    pareto(rows)
    header = C.machine_lines(args) + [
        f"reference: P1 maxh {ref_settings['mesh.maxh']}, {ref_settings['time.steps']} trapezoidal steps "
        f"(‖ε(u)‖ = {scale_u:.4g}, ‖w‖ = {scale_w:.4g} at T)"]
    for target in (1e-2, 1e-3, 1e-4):
        reached = [r for r in rows if r["W_final_rel"] <= target]
        best = min(reached, key=lambda r: r["seconds"]) if reached else None
        cheapest = f"{best['family']}, {best['setting']} ({best['seconds']:.3g} s)" if best else "not reached"
        header.append(f"wear error ≤ {target:.2%}: {cheapest}")
    fig, (ax,) = C.new_figure(1, width=8.0)
    for family in dict.fromkeys(r["family"] for r in rows):
        mine = [r for r in rows if r["family"] == family]
        ax.loglog([r["seconds"] for r in mine], [r["W_final_rel"] for r in mine], "o-", ms=4, label=family)
    front = sorted((r for r in rows if r["pareto"]), key=lambda r: r["seconds"])
    ax.loglog([r["seconds"] for r in front], [r["W_final_rel"] for r in front], "k--", lw=1, label="Pareto front")
    ax.set(xlabel="wall time [s]", ylabel="relative wear error at T, L²(Γ_C)", title="work–precision, paper's scene")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    columns = [("family", "family", None), ("setting", "setting", None), ("steps", "steps", "d"),
               ("free_dofs", "free DOFs", "d"), ("seconds", "wall [s]", ".3g"), ("W_final_rel", "wear err", ".2e"),
               ("V_final_rel", "‖ε(u)‖ err", ".2e"), ("W_sum", "W_sum", ".2e"), ("V_sum", "V_sum", ".2e"),
               ("pareto", "Pareto", None)]
    C.finish("work_precision", "run time against error (paper's scene)", header, rows, columns, fig, quick=args.quick)
    for line in header[-3:]:
        print(line)


if __name__ == "__main__":
    main()
