"""A 64-case study of the paper's scene: Dask local cluster vs a plain loop, and 1 vs 2 workers.

The study is ``geometries/studies/paper_grid64.toml`` (8 × 8 grid of μ and κ at the paper's resolution,
maxh 0.05, 100 steps; one mesh and material).  Each repetition times, interleaved:

* ``loop``: the cases one by one in this process without reuse, ``simulate(scene)`` + ``Result.save``
  (the mesh comes from the on-disk cache, as in every other row);
* ``loop_reuse``: the same loop passing each result's discretization to the next case;
* ``sweep_1`` / ``sweep_2``: ``ngwear.sweep(study, workers=N)`` end to end — a new ``LocalCluster`` of N
  worker processes (started and closed, workers import ngwear), every case's folder, the table and the
  plots — into a fresh output folder.

``cluster_N`` is the part of that which is not the cases: start a LocalCluster of N workers, import
ngwear on them, close it.  Medians over ``--reps``; speed-ups are ratios of medians of the same run.

    .venv/bin/python benchmarks/sweep.py [--quick] [--reps 3]
"""
from __future__ import annotations

import logging
import shutil
import tempfile
import tomllib
from pathlib import Path

import common as C

import ngwear
from ngwear.model.keys import Level
from ngwear.studies.study import study_from_dict

STUDY = C.ROOT / "geometries" / "studies" / "paper_grid64.toml"


def load(quick: bool):
    """The benchmark study; ``--quick``: its first 2 × 4 grid points at maxh 0.1 and 20 steps."""
    data = tomllib.loads(STUDY.read_text())
    if quick:
        data["grid"] = {key: values[:n] for (key, values), n in zip(data["grid"].items(), (2, 4))}
        data["set"] = {"mesh.maxh": 0.1, "time.steps": 20}
    return study_from_dict(data, base_dir=STUDY.parent, name=data["name"])


def loop(study, reuse: bool) -> int:
    """Run and save every case in this process; returns the number of new factorisations."""
    disc, count = None, 0
    with tempfile.TemporaryDirectory() as tmp:
        for case in study.cases:
            kept = disc is not None and reuse and disc.reuse(case.scene).rebuilt > Level.STIFFNESS
            result = ngwear.simulate(case.scene, discretization=disc if reuse else None, progress=False)
            result.save(Path(tmp) / case.id)
            disc = result.discretization
            count += not kept
    return count


def sweep(study, workers: int) -> dict:
    out = Path(tempfile.mkdtemp(prefix="ngwear-sweep-"))
    try:
        return ngwear.sweep(study, out=out, workers=workers, progress=False).attrs["summary"]
    finally:
        shutil.rmtree(out)


def cluster(workers: int) -> None:
    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=":0",
                      silence_logs=logging.CRITICAL) as local, Client(local) as client:
        client.run(__import__, "ngwear")


def main():
    p = C.parser(__doc__.splitlines()[0])
    args = p.parse_args()
    study = load(args.quick)
    header = C.machine_lines(args) + [
        f"study: {study.name}, {len(study.cases)} cases, maxh {study.base.mesh.maxh}, {study.base.time.steps} steps; "
        "loop = simulate + save one by one in this process; sweep_N = ngwear.sweep on a new LocalCluster of N "
        "worker processes, end to end; cluster_N = its start, imports and close alone"]
    funcs = {"loop": lambda: loop(study, reuse=False), "loop_reuse": lambda: loop(study, reuse=True),
             "sweep_1": lambda: sweep(study, 1), "sweep_2": lambda: sweep(study, 2),
             "cluster_1": lambda: cluster(1), "cluster_2": lambda: cluster(2)}
    C.mesh_for(study.base)  # the mesh cache is warm for every row
    with C.blas_limit(args.blas_threads):
        times, outs = C.interleaved(funcs, args.reps)
    base = C.median(times["loop"])
    factorisations = {"loop": outs["loop"], "loop_reuse": outs["loop_reuse"],
                      "sweep_1": outs["sweep_1"]["factorisations"], "sweep_2": outs["sweep_2"]["factorisations"]}
    rows = []
    for name, seconds in times.items():
        wall = C.median(seconds)
        rows.append({"run": name, "cases": len(study.cases) if name in factorisations else 0,
                     "wall_s": wall, "min_s": min(seconds), "max_s": max(seconds),
                     "per_case_ms": 1000 * wall / len(study.cases) if name in factorisations else None,
                     "speedup_vs_loop": base / wall if name in factorisations else None,
                     "factorisations": factorisations.get(name)})
    scaling = C.median(times["sweep_1"]) / C.median(times["sweep_2"])
    cases_only = ((C.median(times["sweep_1"]) - C.median(times["cluster_1"]))
                  / (C.median(times["sweep_2"]) - C.median(times["cluster_2"])))
    header.append(f"scaling 1 -> 2 workers: {scaling:.2f} end to end, {cases_only:.2f} without the cluster's "
                  "start and close")
    for status in ("completed", "stopped", "rejected", "crashed"):
        assert outs["sweep_2"][status] == (len(study.cases) if status == "completed" else 0), outs["sweep_2"]
    columns = [("run", "run", None), ("cases", "cases", "d"), ("wall_s", "wall [s]", ".2f"),
               ("min_s", "min [s]", ".2f"), ("max_s", "max [s]", ".2f"), ("per_case_ms", "per case [ms]", ".0f"),
               ("speedup_vs_loop", "speed-up vs loop", ".2f"), ("factorisations", "factorisations", "d")]
    fig, (ax,) = C.new_figure(1, width=7)
    ax.barh([r["run"] for r in rows], [r["wall_s"] for r in rows],
            xerr=[[r["wall_s"] - r["min_s"] for r in rows], [r["max_s"] - r["wall_s"] for r in rows]])
    ax.invert_yaxis()
    ax.set(xlabel="wall time [s] (median, min-max)", title=f"{study.name}: {len(study.cases)} cases")
    C.finish("sweep", f"{study.name}: local cluster vs loop", header, rows, columns, fig=fig, quick=args.quick)


if __name__ == "__main__":
    main()
