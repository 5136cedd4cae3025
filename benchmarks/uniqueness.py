"""The uniqueness check (H_S) of ``ngwear run`` against the run itself, on the brake pad.

``geometries/brake_pad.toml`` as shipped (150 steps) at maxh 0.002 (32k DOFs, 1 889 contact points; ``--quick``:
0.004): the run (``Discretization`` from the cached mesh + ``simulate``), then the check in the paper's form
(:func:`ngwear.studies.theory.smallness`: c₀ with a second factorisation, of the strain form) and as ``ngwear run``
makes it (the energy form, :func:`ngwear.studies.theory.uniqueness`: Lanczos on the contact compliance with the run's
own factorisation).  Repetitions interleave the three; medians.

    .venv/bin/python benchmarks/uniqueness.py [--quick] [--reps 3]
"""
from __future__ import annotations

import common as C

import ngwear
from ngwear.numerics.discrete import Discretization
from ngwear.studies.theory import smallness, uniqueness

SIZES = (0.004, 0.002)


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.set_defaults(blas_threads=None)
    args = p.parse_args()
    sizes = SIZES[:1] if args.quick else SIZES
    header = C.machine_lines(args) + [
        "brake_pad.toml as shipped (150 steps); run = Discretization from the cached mesh + simulate; "
        "before = the paper's c0 (second factorisation), after = c_K² with the run's factorisation; medians"]
    rows = []
    for maxh in sizes:
        scene = ngwear.load_scene(C.ROOT / "geometries" / "brake_pad.toml").replace(**{"mesh.maxh": maxh})
        Discretization(scene).mesh                                   # mesh once, into the cache
        runs, before, after = [], [], []
        for _ in range(args.reps):
            start = C.perf()
            result = ngwear.simulate(scene, discretization=Discretization(scene), progress=False)
            runs.append(C.perf() - start)
            disc = result.discretization
            start = C.perf()
            paper = smallness(disc)
            before.append(C.perf() - start)
            start = C.perf()
            energy = uniqueness(disc)
            after.append(C.perf() - start)
        row = {"maxh": maxh, "dofs": disc.fes.ndof, "contact_points": disc.points.n,
               "solve": "matrix-free" if disc.matrix_free else "dense", "run_s": C.median(runs),
               "before_s": C.median(before), "after_s": C.median(after),
               "c0": paper.c0, "paper_product": paper.product, "paper_m_F": paper.monotonicity,
               "c_K2": energy.trace, "energy_product": energy.product, "reps": args.reps}
        row["before_of_run"] = row["before_s"] / row["run_s"]
        row["after_of_run"] = row["after_s"] / row["run_s"]
        rows.append(row)
        print(f"  maxh {maxh}: run {row['run_s']:.2f} s, (H_S) before {row['before_s']:.2f} s, "
              f"after {row['after_s']:.2f} s", flush=True)
    columns = [("maxh", "maxh", None), ("dofs", "DOFs", None), ("contact_points", "points", None),
               ("solve", "contact solve", None), ("run_s", "run [s]", ".2f"), ("before_s", "(H_S) before [s]", ".2f"),
               ("before_of_run", "before / run", ".2f"), ("after_s", "(H_S) after [s]", ".2f"),
               ("after_of_run", "after / run", ".3f"), ("paper_product", "c0² L μ", ".3g"),
               ("paper_m_F", "m_F", ".3g"), ("energy_product", "c_K² L μ", ".3g")]
    C.finish("uniqueness", "(H_S) against the run, brake pad", header, rows, columns, quick=args.quick)


if __name__ == "__main__":
    main()
