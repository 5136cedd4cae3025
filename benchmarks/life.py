"""A part's life: ``geometries/brake_pad_life.toml`` with cycle jumps against stop by stop.

Each run is a fresh process (``python benchmarks/life.py --child MODE``), so neither gains from the other's caches
but the mesh file.  For each: the wall time of the whole run (meshing from the cache, factorising, the loop), the
stops simulated, the geometry updates and their time (``Surface.update``: the move, its quality and the rebuilt
discretization, factorised), the worn volume and the extreme total wear and remaining thickness.  The jumps' error is
measured against stop by stop; the update's cost against one step (the loop's time over its steps) and one
linear-elastic solve of the pad (``common.elastic_reference``).  ``--quick``: the first block's 400 stops only.

``--maxh H`` runs the pad on a finer mesh (0.001 m: about 230k DOFs); ``--modes jumps`` runs the jumps only and
extrapolates stop by stop from their measured parts: the set-up (wall − loop), the step time without the updates
times the stop-by-stop steps (S stops at the steps a simulated stop took) and the updates at their measured time.
It is an upper bound with the matrix-free contact solve: a stop that repeats the one before is solved from the kept
Krylov spans, so stop by stop's steps cost less than the jumps'.

    python benchmarks/life.py [--quick] [--maxh 0.001 --modes jumps]
"""
from __future__ import annotations

import json
import subprocess
import sys
import time

from common import ROOT, blas_limit, elastic_reference, machine_lines, mesh_for, parser, print_table, write_csv

import ngwear
from ngwear.runs import surface

SCENE = ROOT / "geometries" / "brake_pad_life.toml"


def scene(quick: bool, jump: bool, maxh: float | None = None):
    loaded = ngwear.load_scene(SCENE)
    settings = {"programme.jump": jump, **({"mesh.maxh": maxh} if maxh else {})}
    if quick:
        settings["programme.stops"] = [dict(loaded.programme.blocks[0].model_dump())]
        settings["output.every"] = 1000.0
    return loaded.replace(**settings)


def child(mode: str, quick: bool, maxh: float | None) -> dict:
    """One run in this process: its numbers as a dict (printed as JSON)."""
    spent = []
    update = surface.Surface.update

    def timed_update(self, *args):
        began = time.perf_counter()
        try:
            return update(self, *args)
        finally:
            spent.append(time.perf_counter() - began)

    surface.Surface.update = timed_update
    run = scene(quick, mode == "jumps", maxh)
    began = time.perf_counter()
    result = ngwear.simulate(run, progress=False)
    wall = time.perf_counter() - began
    stops = result.stops
    total = result.total_wear[-1]
    return {"mode": mode, "wall_s": wall, "loop_s": result.solve_time, "steps": result.steps,
            "stops": len(stops), "simulated": int(stops["simulated"].sum()), "updates": result.geometry_updates,
            "update_s": sum(spent) / max(len(spent), 1), "worn_volume": float(stops["worn_volume"].sum()),
            "max_total_wear": float(total.max()), "min_remaining": float(result.remaining_thickness[-1].min()),
            "worn_share": float(total.max() / result.thickness.max()), "status": result.status}


def extrapolated(jumps: dict) -> dict:
    """Stop by stop from the jumps' measured parts (see the module's doc; an upper bound): its wall time only."""
    stepping = (jumps["loop_s"] - jumps["updates"] * jumps["update_s"]) / jumps["steps"]
    steps = round(jumps["stops"] * jumps["steps"] / jumps["simulated"])
    wall = jumps["wall_s"] - jumps["loop_s"] + stepping * steps + jumps["updates"] * jumps["update_s"]
    return {**jumps, "mode": "stop by stop (extrapolated)", "wall_s": wall, "loop_s": wall - jumps["wall_s"] +
            jumps["loop_s"], "steps": steps, "simulated": jumps["stops"]}


def main() -> None:
    p = parser(__doc__.splitlines()[0])
    p.add_argument("--child", default=None)
    p.add_argument("--maxh", type=float, default=None, help="mesh.maxh of the pad (default: the shipped mesh)")
    p.add_argument("--modes", default="jumps,stop by stop", help="'jumps' alone extrapolates stop by stop")
    args = p.parse_args()
    if args.child:
        with blas_limit(args.blas_threads):
            print(json.dumps(child(args.child, args.quick, args.maxh)))
        return
    rows = []
    for mode in args.modes.split(","):
        command = [sys.executable, __file__, "--child", mode, "--blas-threads", str(args.blas_threads)]
        done = subprocess.run(command + (["--quick"] if args.quick else []) + (
            ["--maxh", str(args.maxh)] if args.maxh else []), capture_output=True, text=True, check=True)
        rows.append(json.loads(done.stdout.strip().splitlines()[-1]))
    if len(rows) == 1:
        rows.append(extrapolated(rows[0]))
    with blas_limit(args.blas_threads):
        pad = scene(args.quick, True, args.maxh)
        elastic = elastic_reference(pad, mesh_for(pad))
    dofs, elastic = elastic["ndof"], elastic["total"]
    reference = rows[1]
    for row in rows:
        row["speed_up"] = reference["wall_s"] / row["wall_s"]
        row["volume_error"] = row["worn_volume"] / reference["worn_volume"] - 1
        row["thickness_error"] = row["min_remaining"] / reference["min_remaining"] - 1
        row["step_s"] = row["loop_s"] / row["steps"]
        row["update_per_step"] = row["update_s"] / row["step_s"]
        row["update_per_elastic"] = row["update_s"] / elastic
    header = machine_lines(args) + [f"scene: {SCENE.name}{' (first block)' if args.quick else ''}, mesh.maxh = "
                                     f"{args.maxh or pad.mesh.maxh} m, {dofs} DOFs; one elastic solve of the pad: "
                                     f"{elastic:.3g} s"]
    columns = [("mode", "mode", None), ("wall_s", "wall [s]", ".1f"), ("speed_up", "speed-up", ".1f"),
               ("stops", "stops", "d"), ("simulated", "simulated", "d"), ("updates", "updates", "d"),
               ("worn_share", "max worn share", ".3f"), ("volume_error", "volume err", ".1e"),
               ("thickness_error", "min thickness err", ".1e"), ("update_s", "update [s]", ".3f"),
               ("update_per_step", "update/step", ".0f"), ("update_per_elastic", "update/elastic", ".2f")]
    print_table("a part's life: jumps against stop by stop", header, rows, columns)
    write_csv(("life_quick" if args.quick else "life") + (f"_maxh{args.maxh:g}" if args.maxh else ""), header, rows)


if __name__ == "__main__":
    main()
