"""A part's life (issue 30 §5): ``geometries/brake_pad_life.toml`` with cycle jumps against stop by stop.

Each run is a fresh process (``python benchmarks/life.py --child MODE``), so neither gains from the other's caches
but the mesh file.  For each: the wall time of the whole run (meshing from the cache, factorising, the loop), the
stops simulated, the geometry updates and their time (``Surface.update``: the move, its quality and the rebuilt
discretization, factorised), the worn volume and the extreme total wear and remaining thickness.  The jumps' error is
measured against stop by stop; the update's cost against one step (the loop's time over its steps) and one
linear-elastic solve of the pad (``common.elastic_reference``).  ``--quick``: the first block's 400 stops only.

    python benchmarks/life.py [--quick]
"""
from __future__ import annotations

import json
import subprocess
import sys
import time

from common import ROOT, blas_limit, elastic_reference, machine_lines, mesh_for, parser, print_table, write_csv

import ngwear
from ngwear.runs import life

SCENE = ROOT / "geometries" / "brake_pad_life.toml"


def scene(quick: bool, jump: bool):
    loaded = ngwear.load_scene(SCENE)
    settings = {"programme.jump": jump}
    if quick:
        settings["programme.stops"] = [dict(loaded.programme.blocks[0].model_dump())]
        settings["output.every"] = 1000.0
    return loaded.replace(**settings)


def child(mode: str, quick: bool) -> dict:
    """One run in this process: its numbers as a dict (printed as JSON)."""
    spent = []
    update = life.Surface.update

    def timed_update(self, *args):
        began = time.perf_counter()
        try:
            return update(self, *args)
        finally:
            spent.append(time.perf_counter() - began)

    life.Surface.update = timed_update
    run = scene(quick, mode == "jumps")
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


def main() -> None:
    p = parser(__doc__.splitlines()[0])
    p.add_argument("--child", default=None)
    args = p.parse_args()
    if args.child:
        with blas_limit(args.blas_threads):
            print(json.dumps(child(args.child, args.quick)))
        return
    rows = []
    for mode in ("jumps", "stop by stop"):
        command = [sys.executable, __file__, "--child", mode, "--blas-threads", str(args.blas_threads)]
        done = subprocess.run(command + (["--quick"] if args.quick else []), capture_output=True, text=True,
                              check=True)
        rows.append(json.loads(done.stdout.strip().splitlines()[-1]))
    with blas_limit(args.blas_threads):
        pad = scene(args.quick, True)
        elastic = elastic_reference(pad, mesh_for(pad))["total"]
    reference = rows[1]
    for row in rows:
        row["speed_up"] = reference["wall_s"] / row["wall_s"]
        row["volume_error"] = row["worn_volume"] / reference["worn_volume"] - 1
        row["thickness_error"] = row["min_remaining"] / reference["min_remaining"] - 1
        row["step_s"] = row["loop_s"] / row["steps"]
        row["update_per_step"] = row["update_s"] / row["step_s"]
        row["update_per_elastic"] = row["update_s"] / elastic
    header = machine_lines(args) + [f"scene: {SCENE.name}{' (first block)' if args.quick else ''}; one elastic "
                                     f"solve of the pad: {elastic:.3g} s"]
    columns = [("mode", "mode", None), ("wall_s", "wall [s]", ".1f"), ("speed_up", "speed-up", ".1f"),
               ("stops", "stops", "d"), ("simulated", "simulated", "d"), ("updates", "updates", "d"),
               ("worn_share", "max worn share", ".3f"), ("volume_error", "volume err", ".1e"),
               ("thickness_error", "min thickness err", ".1e"), ("update_s", "update [s]", ".3f"),
               ("update_per_step", "update/step", ".0f"), ("update_per_elastic", "update/elastic", ".2f")]
    print_table("a part's life: jumps against stop by stop", header, rows, columns)
    write_csv("life_quick" if args.quick else "life", header, rows)


if __name__ == "__main__":
    main()
