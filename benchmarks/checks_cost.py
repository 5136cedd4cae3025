"""What the checks against lost work and unmeant input cost, against one step of the shipped brake pad.

Every check runs outside the steps: before the run (the plausibility of the scene and of its loads, the loads
against the programme's largest factor, ``wear.limit`` against the worn region's thickness), at a resume (every
number of the checkpoint finite, its embedded scene's SHA-256, each array's shape, its counts, times and
coefficients in range) or at a geometry update (the new mesh written as ``mesh.next.vol`` and renamed).  The
thickness that ``wear.limit`` is checked against is measured for the run anyway.  Each is timed alone, and as a
share of one step of ``geometries/brake_pad.toml`` (``solve_time / steps`` of a run from its discretization).  The
programme's set-up (read, checked and compiled into its schedule) is timed for 1 000 … 200 000 blocks, inline and
from a CSV file: its cost per block is flat when the set-up is linear.  Medians of ``--reps``.

    .venv/bin/python benchmarks/checks_cost.py [--quick] [--reps 5]
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import common as C

STEPS = 40
BLOCKS = (1_000, 4_000, 20_000, 200_000)
ROW = {"count": 2, "duration": 0.5, "speed": [1.0, 0.0], "load": 1.0, "dwell": 0.5}


def pad_checks(reps: int) -> list[dict]:
    """Each check on the shipped pad, with its share of one step."""
    import numpy as np

    import ngwear
    from ngwear.model import plausibility
    from ngwear.model.rules import _check_load_sizes
    from ngwear.results.checkpoint import CHECKPOINT, _check_shapes, _check_signs, _read, _scene
    from ngwear.runs.simulate import _checked_limit

    scene = ngwear.load_scene(C.ROOT / "geometries" / "brake_pad.toml").replace(
        **{"time.steps": STEPS, "output.checkpoint_seconds": 0})
    disc = ngwear.Discretization(scene)
    folder = Path(tempfile.mkdtemp())
    runs = [ngwear.simulate(scene, discretization=disc, progress=False, checkpoint=folder) for _ in range(reps)]
    step = C.median([r.solve_time / r.steps for r in runs])
    area = float(disc.points.weights.sum())
    limited = scene.replace(**{"wear.limit": 1e-4})
    data = _read(folder)
    mesh = folder / "mesh.vol"
    renamed = mesh.with_name("mesh.next.vol")

    def rename():
        os.replace(mesh, renamed)
        os.replace(renamed, mesh)

    checks = [("scene plausibility (moduli, κ, μ, temperatures)", "before the run", lambda: plausibility.warnings(scene)),
              ("loads' plausibility (mean contact pressure)", "before the run",
               lambda: plausibility.load_warnings(scene, area)),
              ("loads × largest programme factor", "before the run", lambda: _check_load_sizes(scene)),
              ("wear.limit below the thickness", "before the run", lambda: _checked_limit(limited, disc)),
              ("checkpoint: keys and every number finite", "at a resume", lambda: _read(folder)),
              ("checkpoint: embedded scene's SHA-256", "at a resume", lambda: _scene(data, folder / CHECKPOINT)),
              ("checkpoint: each array's shape", "at a resume", lambda: _check_shapes(folder / CHECKPOINT, data, disc)),
              ("checkpoint: counts, times, μ, κ in range", "at a resume", lambda: _check_signs(folder / CHECKPOINT, data)),
              ("mesh.next.vol renamed onto mesh.vol (twice)", "at a geometry update", rename)]
    rows = []
    for name, when, check in checks:
        seconds = C.median([C.timed(check)[0] for _ in range(reps)])
        rows.append({"check": name, "when": when, "seconds": seconds, "of_a_step": seconds / step,
                     "per_step": 0.0})
    rows.append({"check": f"one step of the shipped pad ({disc.points.n} contact points, "
                          f"{np.count_nonzero(disc.body.free)} free DOFs)", "when": "every step", "seconds": step,
                 "of_a_step": 1.0})
    return rows


def programme_setup(reps: int, quick: bool) -> list[dict]:
    """The programme of ``n`` blocks made into a scene (read, checked, its schedule compiled): inline and from CSV."""
    import ngwear
    from ngwear.model.programme import Schedule

    base = ngwear.load_scene(C.PAPER).to_dict()
    base.pop("time")
    base["output"].pop("every")
    folder = Path(tempfile.mkdtemp())
    rows = []
    for n in BLOCKS[:2] if quick else BLOCKS:
        path = folder / f"blocks{n}.csv"
        path.write_text("count,duration,speed,load,dwell\n" + '2,0.5,"[1.0, 0.0]",1.0,0.5\n' * n)
        for source, programme in (("inline", {"stops": [ROW] * n}), ("CSV", {"file": str(path)})):
            if source == "inline" and n > 4_000:
                continue                            # a table holds at most 10 000 rows: long programmes are CSV files

            def set_up():
                scene = ngwear.Scene.from_dict({**base, "programme": {**programme, "steps_per_stop": 1}})
                return Schedule.of(scene.programme).ends(1)

            seconds = C.median([C.timed(set_up)[0] for _ in range(reps)])
            rows.append({"check": f"programme of {n:,} blocks ({source})", "when": "before the run",
                         "seconds": seconds, "per_block_us": 1e6 * seconds / n})
            path.touch()                            # a new mtime: the next repetition reads the file anew
    return rows


def main():
    args = C.parser(__doc__.splitlines()[0]).parse_args()
    reps = max(args.reps, 1)
    rows = pad_checks(reps) + programme_setup(reps, args.quick)
    header = C.machine_lines(args) + [
        f"the shipped brake pad, {STEPS} steps from its discretization; a check's share is its time over one step's; "
        "per step: what a check adds to every step (none runs there)"]
    columns = [("check", "check", None), ("when", "when", None), ("seconds", "s", ".3g"),
               ("of_a_step", "of one step", ".2%"), ("per_step", "per step s", ".0f"),
               ("per_block_us", "µs per block", ".3g")]
    C.finish("checks_cost", "What the checks cost, against one step of the shipped pad", header, rows, columns,
             quick=args.quick)


if __name__ == "__main__":
    main()
