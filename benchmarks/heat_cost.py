"""What heat costs a run: the shipped pad and a >= 100k-DOF pad with heat.model "none" and "conduction".

``geometries/brake_pad.toml`` (3 kN on a disc at 50 rad/s, 150 steps of 1 s; at the large size, maxh 0.00135 and
187k DOFs — maxh 0.0014 gives 83k —, 20 steps) in three variants, timed from the cached mesh
(``Discretization(scene, mesh)`` + ``simulate``: the heat's assembly and factorisation are in the run), interleaved,
medians of ``--reps`` (the shipped pad: at least 7), of the wall-clock and the process's CPU time (less disturbed
by other work on the machine; BLAS on one thread):

* ``none``: the paper's model (heat.model = "none");
* ``conduction``: the temperature of pad and backing (pad: k = 1.2, ρ = 2600, c = 1465; steel backing), η = 0.15,
  the back convected; μ and κ constant: per step one back-substitution of the heat matrix;
* ``coupled``: and thermal expansion (the load: one back-substitution of K per step), μ(T), κ(T) (the dense
  Newton matrices of a reference μ refine each step's; the matrix-free products are recomputed for each μ).

On the shipped pad also each coupling of ``coupled`` alone on ``conduction`` (``expansion``, ``mu``: μ(T), ``kappa``:
κ(T)): where its cost goes.  Target: ``conduction`` and ``coupled`` at most 30 % above ``none`` on the shipped pad.

    .venv/bin/python benchmarks/heat_cost.py [--quick] [--reps 3]
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import common as C
import tomli_w

import ngwear
from ngwear.model.examples import scene_file
from ngwear.model.scene_mesh import build_mesh
from ngwear.numerics.discrete import Discretization

TARGET = 1.30
PAD = {"material.conductivity": 1.2, "material.density": 2600.0, "material.heat_capacity": 1465.0,
       "material.regions.backing.conductivity": 50.0, "material.regions.backing.density": 7850.0,
       "material.regions.backing.heat_capacity": 460.0, "heat.model": "conduction", "heat.partition": 0.15,
       "heat.ambient": 20.0, "heat.convection": [{"boundary": "back", "coefficient": 30.0}]}
COUPLED = {**PAD, "material.expansion": 2e-5, "material.regions.backing.expansion": 1.2e-5,
           "contact.friction": "0.42 - 0.0008 * max(T - 120, 0)",
           "contact.wear": "8e-13 * (1 + min(exp((T - 150) / 30), 4))"}
VARIANTS = {"none": {}, "conduction": PAD, "coupled": COUPLED}
PARTS = {"expansion": {**PAD, **{k: COUPLED[k] for k in ("material.expansion", "material.regions.backing.expansion")}},
         "mu": {**PAD, "contact.friction": COUPLED["contact.friction"]},
         "kappa": {**PAD, "contact.wear": COUPLED["contact.wear"]}}
SHIPPED = 0.006


def run(scene, mesh, cpu: list) -> None:
    """A run from the cached mesh: its discretization and its time loop; its CPU time appended to ``cpu``."""
    start = time.process_time()
    result = ngwear.simulate(scene, discretization=Discretization(scene, mesh), progress=False)
    cpu.append(time.process_time() - start)
    assert result.completed, result.status


def cli_runs(args, header) -> None:
    """``ngwear run`` of the shipped pad with each variant, fresh processes, interleaved (``--cli``)."""
    base = ngwear.load_scene(scene_file("brake_pad"))
    with tempfile.TemporaryDirectory() as folder:
        files = {}
        for name, changes in VARIANTS.items():
            files[name] = Path(folder) / f"{name}.toml"
            files[name].write_text(tomli_w.dumps(base.replace(**changes).to_dict()))

        def run_cli(name):
            subprocess.run([sys.executable, "-m", "ngwear.cli", "run", str(files[name]), "--out",
                            str(Path(folder) / f"out-{name}"), "--quiet"], check=True, capture_output=True)

        times, _ = C.interleaved({name: (lambda n=name: run_cli(n)) for name in VARIANTS}, args.reps)
    rows = [{"variant": name, "seconds": C.median(times[name]), "reps": args.reps,
             "ratio": C.median(times[name]) / C.median(times["none"])} for name in VARIANTS]
    for row in rows:
        row["target"] = C.verdict(row["ratio"] <= TARGET) if row["variant"] != "none" else ""
    columns = [("variant", "heat", None), ("seconds", "ngwear run s", ".2f"), ("ratio", "/ none", ".2f"),
               ("target", "target", None)]
    C.finish("heat_cost_cli", "ngwear run of the shipped brake pad: heat.model none vs conduction", header + [
        "ngwear run of each variant's scene file (mesh from the cache, results, frames, pictures), fresh processes"],
        rows, columns, quick=False)


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.add_argument("--cli", action="store_true", help="time `ngwear run` of the shipped pad instead")
    args = p.parse_args()
    header = C.machine_lines(args) + [
        "brake_pad.toml from the cached mesh, Discretization + simulate in one process; medians of interleaved "
        f"repetitions; target: conduction, coupled <= {TARGET:g} x none on the shipped pad"]
    if args.cli:
        return cli_runs(args, header)
    base = ngwear.load_scene(scene_file("brake_pad"))
    sizes = ((SHIPPED, 150),) if args.quick else ((SHIPPED, 150), (0.00135, 20))
    rows = []
    for maxh, steps in sizes:
        reps, variants = (max(args.reps, 7), {**VARIANTS, **PARTS}) if maxh == SHIPPED else (args.reps, VARIANTS)
        scenes = {name: base.replace(**{"mesh.maxh": maxh, "time.T": float(steps), "time.steps": steps,
                                        "output.every": float(steps), **changes})
                  for name, changes in variants.items()}
        mesh = build_mesh(scenes["none"])
        cpu = {name: [] for name in scenes}
        with C.blas_limit(args.blas_threads):
            times, _ = C.interleaved({name: (lambda s=s, c=cpu[name]: run(s, mesh, c)) for name, s in scenes.items()},
                                     reps)
        disc = Discretization(scenes["none"], mesh)
        for name in variants:
            row = {"maxh": maxh, "steps": steps, "ndof": disc.fes.ndof, "contact_points": disc.points.n,
                   "variant": name, "seconds": C.median(times[name]), "reps": reps}
            row["ratio"] = row["seconds"] / C.median(times["none"])
            row["cpu"], row["cpu_ratio"] = C.median(cpu[name]), C.median(cpu[name]) / C.median(cpu["none"])
            row["target"] = C.verdict(row["ratio"] <= TARGET) if maxh == SHIPPED and name in VARIANTS and name != "none" \
                else ""
            rows.append(row)
            print(f"  maxh {maxh}: {name:10s} {row['seconds']:.2f} s, x{row['ratio']:.2f} (CPU x{row['cpu_ratio']:.2f})",
                  flush=True)
    columns = [("maxh", "maxh", "g"), ("ndof", "DOFs", "d"), ("contact_points", "points", "d"), ("steps", "steps", "d"),
               ("variant", "heat", None), ("seconds", "run s", ".2f"), ("ratio", "/ none", ".2f"),
               ("cpu", "CPU s", ".2f"), ("cpu_ratio", "CPU / none", ".2f"), ("target", "target", None)]
    C.finish("heat_cost", "heat.model none vs conduction on the brake pad", header, rows, columns, quick=args.quick)


if __name__ == "__main__":
    main()
