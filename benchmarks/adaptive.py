"""Adaptive steps against uniform steps of the same time error, on the paper's scene.

The time error alone: every run on the paper's mesh (P1, maxh 0.05) against 8000 trapezoidal steps on the same
mesh, measured as ``time.tolerance`` is meant, max_i |w_i(T) − w_ref,i(T)| / g.  Uniform runs of each integrator
at 10 … 3200 steps; adaptive runs of each at tolerances 1e-2 … 1e-4, and ``time.adaptive`` with the integrator
not named (the trapezoidal rule).  For each adaptive run: its steps (and rejected ones), its error
against its tolerance, and the uniform steps of the same integrator and of the paper's explicit scheme that reach
its error (log–log interpolation between the uniform runs: error ∝ N^(−q)).  Wall times: medians of ``--reps``.

    .venv/bin/python benchmarks/adaptive.py [--quick] [--reps 3]
"""
from __future__ import annotations

import common as C
import numpy as np

INTEGRATORS = ("explicit", "implicit", "trapezoidal")


def uniform_steps_for(target: float, runs: list[tuple[int, float]]) -> float:
    """Steps of a uniform run with error ``target``: log–log interpolation in (steps, error); NaN outside the runs."""
    steps, errors = np.log([n for n, _ in runs]), np.log([e for _, e in runs])
    order = np.argsort(errors)
    if not errors.min() <= np.log(target) <= errors.max():
        return float("nan")
    return float(np.exp(np.interp(np.log(target), errors[order], steps[order])))


def main():
    args = C.parser(__doc__.splitlines()[0]).parse_args()
    base = C.paper_scene().replace(**{"mesh.maxh": 0.2 if args.quick else 0.05, "output.every": 1.0})
    g = base.contact.gap
    mesh = C.mesh_for(base)
    with C.blas_limit(args.blas_threads):
        ref = C.fast_run(base.replace(**{"time.steps": 8000, "wear.integrator": "trapezoidal"}), mesh)
        error = lambda r: float(np.abs(r.wear[-1] - ref.wear[-1]).max() / g)  # noqa: E731

        def timed(scene):
            seconds = []
            for _ in range(args.reps):
                start = C.perf()
                result = C.fast_run(scene, mesh)
                seconds.append(C.perf() - start)
            return result, C.median(seconds)

        uniform = {}
        for integrator in INTEGRATORS:
            uniform[integrator] = []
            for n in (10, 25, 50, 100, 200, 400, 800, 1600, 3200):        # k·α·L ≤ 1.5: no step refused
                result, _ = timed(base.replace(**{"time.steps": n, "wear.integrator": integrator}))
                uniform[integrator].append((n, error(result)))
            print(integrator, "uniform", [f"{n}: {e:.2e}" for n, e in uniform[integrator]], flush=True)
        rows = []
        for integrator in (*INTEGRATORS, None):
            for tol in ((1e-2, 1e-3) if args.quick else (1e-2, 1e-3, 1e-4)):
                named = {"wear.integrator": integrator} if integrator else {}
                scene = C.paper_scene().replace(**{"mesh.maxh": base.mesh.maxh, "output.every": 1.0,
                                                   "time.adaptive": True, "time.tolerance": tol, **named})
                result, seconds = timed(scene)
                e, used = error(result), scene.wear.integrator
                rows.append({"integrator": integrator or f"not named ({used})", "tolerance": tol,
                             "steps": result.steps, "rejected": result.rejected, "error": e,
                             "tolerance_over_error": tol / e, "seconds": seconds,
                             "uniform_same_integrator": uniform_steps_for(e, uniform[used]),
                             "uniform_explicit": uniform_steps_for(e, uniform["explicit"])})
                print(f"{rows[-1]['integrator']:28s} tol {tol:.0e}: {result.steps} steps, error {e:.2e}", flush=True)
    header = C.machine_lines(args) + [
        f"paper's scene, P1 maxh {base.mesh.maxh}; error = max |w(T) − w_ref(T)| / g against 8000 trapezoidal steps "
        "on the same mesh (the time error alone); uniform steps of the same error interpolated log-log"]
    columns = [("integrator", "integrator", None), ("tolerance", "tol", ".0e"), ("steps", "steps", "d"),
               ("rejected", "rejected", "d"), ("error", "error", ".2e"), ("tolerance_over_error", "tol / error", ".2f"),
               ("uniform_same_integrator", "uniform, same integrator", ".0f"),
               ("uniform_explicit", "uniform explicit", ".0f"), ("seconds", "wall [s]", ".3f")]
    C.finish("adaptive", "adaptive against uniform steps of the same error", header, rows, columns, quick=args.quick)


if __name__ == "__main__":
    main()
