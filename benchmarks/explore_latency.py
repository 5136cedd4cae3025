"""Latency of the explorer: a slider change must give a new picture in ≤ 0.5 s.

For each slider (load, speed ‖v*‖, κ, μ, g, time steps) the explorer on the paper scene is moved
through 5 values (``--reps``, cycled), each update doing what the widget does: ``Explorer.set``
(re-solve reusing mesh and factorisation), ``Explorer.picture`` (pyvista, plotter reused),
``Explorer.plots`` (matplotlib, figure reused) and the PNG encoding of both for the
``ipywidgets.Image``; plus scrubbing the time slider (no solve).  Medians over the updates per
slider.  "new picture" = solve + picture + its PNG, the target; "all shown" adds the plots.  The
first run (mesh from the cache, factorisation) and the first picture and plots (render window,
shaders, figure) are reported once as "start".

Resolutions: the explorer's default (maxh 0.05, 100 steps: the paper's) and maxh 0.1, 50 steps
(``--quick``: the default only).

    /work/venv/bin/python benchmarks/explore_latency.py [--quick] [--blas-threads N]
"""
from __future__ import annotations

import common as C

from ngwear.views.explore import Explorer
from ngwear.views.widget import png_bytes

TARGET = 0.5
SLIDERS = {
    "load": (0.12, 0.08, 0.15, 0.05, 0.1),
    "speed": (1.5, 0.5, 2.0, 0.8, 1.0),
    "wear": (0.5, 3.0, 0.0, 2.0, 1.5),
    "friction": (0.5, 0.0, 1.5, 0.2, 1.0),
    "gap": (0.15, 0.3, 0.1, 0.25, 0.2),
    "steps": None,  # multiples of the resolution's steps, see below
    "time": None,   # scrubbing: steps of the current run
}
RESOLUTIONS = ((0.05, 100), (0.1, 50))  # the paper scene's own resolution (the explorer's default), coarser


def update(ex: Explorer, name: str, value) -> dict:
    """One slider change as the widget does it; the times of its parts [s]."""
    if name == "time":
        solve = 0.0
        ex.scrub(value)
    else:
        ex.set(**{name: value})
        solve = ex.updates[-1].solve
    t0 = C.perf()
    picture = ex.picture()
    t1 = C.perf()
    png_picture = png_bytes(picture)
    t2 = C.perf()
    plots = png_bytes(ex.plots())
    t3 = C.perf()
    assert png_picture and plots
    return {"solve": solve, "picture": t1 - t0, "png": t2 - t1, "plots": t3 - t2,
            "refactorised": name != "time" and ex.updates[-1].refactorised}


def measure(maxh: float, steps: int, updates: int) -> list[dict]:
    scene = C.paper_scene()
    t0 = C.perf()
    ex = Explorer(scene, maxh=maxh, steps=steps)
    t1 = C.perf()
    ex.picture()
    ex.plots()
    t2 = C.perf()
    base = {"maxh": maxh, "steps": steps, "free_dofs": C.free_dofs(ex.disc),
            "contact_points": ex.disc.points.n}
    rows = [dict(base, slider="start", solve=t1 - t0, picture=t2 - t1)]
    for name, values in SLIDERS.items():
        if name == "steps":
            values = tuple(round(f * steps) for f in (0.5, 1.5, 0.8, 1.2, 1.0))
        elif name == "time":
            values = tuple(round(f * steps) for f in (0.1, 0.3, 0.5, 0.7, 0.9))
        parts = [update(ex, name, values[i % len(values)]) for i in range(updates)]
        row = dict(base, slider=name)
        for key in ("solve", "picture", "png", "plots"):
            row[key] = C.median([p[key] for p in parts])
        row["new_picture"] = C.median([p["solve"] + p["picture"] + p["png"] for p in parts])
        row["all_shown"] = C.median([p["solve"] + p["picture"] + p["png"] + p["plots"] for p in parts])
        row["refactorised"] = sum(p["refactorised"] for p in parts)
        row["target"] = C.verdict(row["new_picture"] <= TARGET)
        rows.append(row)
    ex.close()
    return rows


def main():
    parser = C.parser(__doc__.splitlines()[0])
    parser.set_defaults(reps=5)
    args = parser.parse_args()
    header = C.machine_lines(args) + [
        f"paper scene; per slider the median of {args.reps} updates; times in ms; "
        f"target: new picture (solve + picture + PNG) <= {1000 * TARGET:.0f} ms"]
    rows = []
    with C.blas_limit(args.blas_threads):
        for maxh, steps in RESOLUTIONS[:1] if args.quick else RESOLUTIONS:
            rows += measure(maxh, steps, args.reps)
    shown = [{k: (1000 * v if isinstance(v, float) and k not in ("maxh",) else v) for k, v in r.items()}
             for r in rows]
    columns = [("slider", "slider", None), ("maxh", "maxh", ".3g"), ("steps", "steps", "d"),
               ("free_dofs", "free DOFs", "d"), ("solve", "solve", ".0f"), ("picture", "picture", ".0f"),
               ("png", "PNG", ".0f"), ("plots", "plots+PNG", ".0f"), ("new_picture", "new picture", ".0f"),
               ("all_shown", "all shown", ".0f"), ("refactorised", "refactorised", None),
               ("target", "≤ 500 ms", None)]
    C.finish("explore_latency", "explorer latency per slider [ms]", header, shown, columns, quick=args.quick)


if __name__ == "__main__":
    main()
