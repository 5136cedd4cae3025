"""What a frame's stress and contact file cost, against a step, on the shipped brake pad.

``geometries/brake_pad.toml`` (P1, maxh 0.006 as shipped; and 0.003) run for 20 steps; then, at its last step, the
frame as before (VTKOutput of ``displacement`` and ``wear``), the frame as now (with ``stress`` and ``von_mises``,
:mod:`ngwear.results.bulk_stress`) and the contact file (``contact_stepNNN.vtu``,
:mod:`ngwear.results.contact_file`), each written into a scratch folder.  The stress recovery is the difference of
the two frames; a step is the run's time loop over its steps (``solve_time / steps``).  Medians of interleaved
repetitions.  The recovery is paid per frame only (``output.every``): no step computes a stress.

    .venv/bin/python benchmarks/frame_cost.py [--quick] [--reps 5]
"""
from __future__ import annotations

import tempfile
from pathlib import Path

import common as C
import ngsolve as ngs

import ngwear
from ngwear.results.bulk_stress import BulkStress
from ngwear.results.contact_file import surface, write_contact

STEPS = 20


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.set_defaults(reps=5)
    args = p.parse_args()
    header = C.machine_lines(args) + [f"the shipped pad, {STEPS} steps; frame at the last step; medians of {args.reps} "
                                      "interleaved repetitions; step = solve_time / steps (median of the runs)"]
    rows = []
    for maxh in (0.006,) if args.quick else (0.006, 0.003):
        scene = ngwear.load_scene(C.ROOT / "geometries" / "brake_pad.toml").replace(
            **{"mesh.maxh": maxh, "time.steps": STEPS, "time.T": float(STEPS), "output.every": float(STEPS)})
        mesh = C.mesh_for(scene)
        with C.blas_limit(args.blas_threads):
            runs = [C.fast_run(scene, mesh) for _ in range(args.reps)]
            step = C.median([r.solve_time / STEPS for r in runs])
            result = runs[-1]
            disc = result.discretization
            u = ngs.GridFunction(disc.fes)
            u.vec.FV().NumPy()[:] = result.displacement(-1)
            wear = ngs.GridFunction(ngs.H1(disc.mesh, order=scene.mesh.order))
            disc.set_nodal(wear, result.wear[-1])
            with tempfile.TemporaryDirectory() as scratch:
                def frame(coefs, names, name):
                    return lambda: ngs.VTKOutput(disc.mesh, coefs=coefs, names=names, filename=str(Path(scratch) / name),
                                                 subdivision=scene.mesh.order - 1).Do()

                stress = BulkStress(scene, disc.mesh, u)
                now = frame([u, wear, stress.tensor, stress.von_mises], ["displacement", "wear", "stress", "von_mises"],
                            "now")
                times, _ = C.interleaved({
                    "before": frame([u, wear], ["displacement", "wear"], "before"),
                    "now": lambda: (stress.update(), now()),
                    "contact": lambda: write_contact(result, result.steps, surface(disc), Path(scratch) / "c.vtu")},
                    args.reps)
        ms = {name: 1e3 * C.median(seconds) for name, seconds in times.items()}
        recovery = ms["now"] - ms["before"]
        rows.append({"maxh": maxh, "ndof": disc.fes.ndof, "contact_points": disc.points.n, "step_ms": 1e3 * step,
                     "frame_before_ms": ms["before"], "frame_now_ms": ms["now"], "stress_ms": recovery,
                     "contact_file_ms": ms["contact"], "added_per_step": (recovery + ms["contact"]) / (1e3 * step)})
        print(rows[-1], flush=True)
    C.finish("frame_cost", "a frame's stress and contact file against a step", header, rows,
             [("maxh", "maxh", "g"), ("ndof", "DOFs", "d"), ("contact_points", "points", "d"),
              ("step_ms", "step ms", ".1f"), ("frame_before_ms", "frame before ms", ".1f"),
              ("frame_now_ms", "frame now ms", ".1f"), ("stress_ms", "stress ms", ".1f"),
              ("contact_file_ms", "contact file ms", ".1f"), ("added_per_step", "added / step", ".2f")],
             quick=args.quick)


if __name__ == "__main__":
    main()
