"""The material laws and coefficient fields: what they cost.

**Linear materials** (``--part linear``): the scenes of the strip, box and pad tables (``ratio.py``,
``scale3d.py``, ``pad.py``), 100 steps from the cached mesh (``Discretization(scene, mesh)`` + ``simulate``), with

* ``iso``: the scene as shipped (one isotropic linear material);
* ``backing``: ``geometry.backing`` = a quarter of the thickness, 100× stiffer (``material.regions.backing``);
  a second region, so more DOFs: its ratio is also given per DOF and against one elastic solve of its own mesh;
* ``transverse``: ``material.law = "transversely_isotropic"`` with the isotropic constants (E_plane = E_axis = E,
  G = E/(2 + 2ν)): the same problem (the same numbers) through the anisotropic law's code;
* ``fields``: ``contact.friction`` and ``contact.wear`` as expression fields of the same constant values.

The four run interleaved in one process (a burst of load hits all), medians of ``--reps``; the ratio to
``iso`` is of medians.  More than 10 % slower than ``iso`` (per DOF for the backing) is a regression.

**The compaction pad** (``--part compaction``): ``geometries/brake_pad.toml`` with ``material.law =
"compaction"`` and β = 10η and 100η at maxh 0.004, 0.002, 0.0011 (5k to 152k DOFs), each run in a fresh
process: ngwear's run (set-up from the cached mesh + the time loop; the tangents it factorised), ngwear's
linear run on the same mesh, and the reference: ONE nonlinear elastic solve of the same law on the same mesh
and space (back face clamped, as ngwear's factorisation holds it) under the pad's mean contact load as a
traction on Γ_C — the pressure P = F/|Γ_C| along −ν and the friction traction μP along the disc's velocity —
by NGSolve's own Newton (``NewtonSolver`` on the energy as ``Variation``, energy line search, tolerance
1e-10 of NGSolve's error √⟨K⁻¹r, r⟩ relative to its first) with PARDISO (MKL, as ngwear) and with
``sparsecholesky`` (the other tables' yardstick).  Target: ngwear ≤ 5× one nonlinear solve.

    .venv/bin/python benchmarks/materials.py [--part linear|compaction|all] [--reps 3] [--quick]
        [--steps 100] [--large-steps 100]
"""
from __future__ import annotations

import argparse
import json
import sys

import common as C

STRIP = [("strip", "10k"), ("strip", "50k"), ("strip", "200k")]
BOX_PAD = [("box", 0.04), ("box", 0.025), ("pad", 0.002), ("pad", 0.0011)]
QUICK_LINEAR = [("strip", "10k"), ("pad", 0.004)]
VARIANTS = ("iso", "backing", "transverse", "fields")
PAD_SIZES = (0.004, 0.002, 0.0011)
BETAS = (10.0, 100.0)                 # β / η
REGRESSION, TARGET = 1.10, 5.0
SCENES = {"box": C.ROOT / "geometries" / "box3d.toml", "pad": C.ROOT / "geometries" / "brake_pad.toml"}


# ---- scenes ---------------------------------------------------------------------------------------
def base_scene(kind: str, size, steps: int = 100):
    """The table's scene at its size: the paper strip (nominal free DOFs, P1), the box or the pad (maxh)."""
    import ngwear
    if kind == "strip":
        return C.scene_for(size, 1)
    settings = {"mesh.maxh": size, "time.steps": steps}
    if kind == "pad":           # the pad without regions: isotropic, E = 1 GPa, no backing plate
        settings.update({"time.T": float(steps), "output.every": float(steps), "geometry.backing": None,
                         "material": {"young": 1.0e9, "poisson": 0.25}})
    return ngwear.load_scene(SCENES[kind]).replace(**settings)


def young_poisson(material) -> tuple[float, float]:
    lam, eta = material.lame
    return eta * (3 * lam + 2 * eta) / (lam + eta), lam / (2 * (lam + eta))


def variant(scene, name: str):
    """The scene with one of :data:`VARIANTS` applied (same loads, mesh size and steps)."""
    young, poisson = young_poisson(scene.material)
    if name == "iso":
        return scene
    if name == "backing":
        thickness = scene.geometry.size[-1] if scene.geometry.kind == "pad" else scene.geometry.size[1]
        return scene.replace(**{"geometry.backing": thickness / 4,
                                "material.regions": {"backing": {"young": 100 * young, "poisson": 0.3}}})
    if name == "transverse":
        return scene.replace(**{"material.law": "transversely_isotropic", "material.young_plane": young,
                                "material.young_axis": young, "material.poisson_plane": poisson,
                                "material.poisson_axis": poisson, "material.shear_axis": young / (2 + 2 * poisson),
                                "material.lame_lambda": None, "material.lame_mu": None, "material.young": None,
                                "material.poisson": None})
    contact = scene.contact
    return scene.replace(**{"contact.friction": f"{contact.friction!r} + 0*x", "contact.wear": f"{contact.wear!r} + 0*y"})


def compaction_scene(maxh: float, beta: float | None, steps: int):
    """The pad with the compaction law at β = ``beta`` η (None: the pad's linear material)."""
    scene = base_scene("pad", maxh, steps)
    if beta is None:
        return scene
    _, eta = scene.material.lame
    return scene.replace(**{"material.law": "compaction", "material.compaction_modulus": beta * eta})


# ---- linear materials: one process, interleaved --------------------------------------------------
def linear_case(kind: str, size, reps: int, variants=VARIANTS) -> list[dict]:
    scenes = {name: variant(base_scene(kind, size), name) for name in variants}
    meshes = {name: C.mesh_for(scene) for name, scene in scenes.items()}
    funcs = {name: (lambda s=scene, m=meshes[name]: C.fast_run(s, m)) for name, scene in scenes.items()}
    for name in {"iso", "backing"} & set(variants):
        funcs[f"elastic {name}"] = lambda s=scenes[name], m=meshes[name]: C.elastic_reference(s, m)
    C.interleaved(funcs, 1)                                  # warm-up: first calls compile and cache
    times, outs = C.interleaved(funcs, reps)
    base = C.median(times["iso"])
    rows = []
    for name in variants:
        disc = outs[name].discretization
        row = {"case": f"{kind} {size}", "variant": name, "ndof": disc.fes.ndof, "points": disc.points.n,
               "mode": "krylov" if disc.matrix_free else "dense", "status": outs[name].status,
               "run_s": C.median(times[name]), "min_s": min(times[name]), "max_s": max(times[name]), "reps": reps}
        row["ratio"] = row["run_s"] / base
        row["ratio_min"] = row["min_s"] / min(times["iso"])
        row["ratio_per_dof"] = row["ratio"] * rows[0]["ndof"] / row["ndof"] if rows else 1.0
        if name in ("iso", "backing"):
            row["elastic_s"] = C.median(times[f"elastic {name}"])
            row["to_elastic"] = row["run_s"] / row["elastic_s"]
        slower = row["ratio_per_dof"] if name == "backing" else row["ratio"]
        row["regression"] = "-" if name == "iso" else ("YES" if slower > REGRESSION else "no")
        rows.append(row)
        print(f"  {row['case']} {name}: {row['ndof']} DOFs, {row['run_s']:.3f}s, ratio {row['ratio']:.2f}", flush=True)
    return rows


def linear_cases(args) -> list[tuple]:
    if args.cases:
        return [(kind, size if kind == "strip" else float(size))
                for kind, size in (case.split(":") for case in args.cases.split(","))]
    return QUICK_LINEAR if args.quick else STRIP + BOX_PAD


# ---- the compaction pad: each measurement in its own process -------------------------------------------
def run_ngwear(maxh: float, beta: float | None, steps: int) -> dict:
    import ngwear
    from ngwear.numerics import operators
    from ngwear.numerics.discrete import Discretization
    scene = compaction_scene(maxh, beta, steps)
    mesh = C.mesh_for(scene)
    factorised = []                                 # PARDISO factorisations (K₀ and the tangents not updated)
    init = operators.ElasticOperator.__init__
    operators.ElasticOperator.__init__ = lambda self, *a, **k: (factorised.append(1), init(self, *a, **k))[1]
    t0 = C.perf()
    disc = Discretization(scene, mesh)
    result = ngwear.simulate(scene, discretization=disc, progress=False)
    run = C.perf() - t0
    record = result.newton[-1]
    return {"ndof": disc.fes.ndof, "points": disc.points.n, "steps": steps, "status": result.status, "run_s": run,
            "loop_s": result.solve_time, "tangents": int(record.tangents), "factorised": len(factorised),
            "bulk": int(sum(r.bulk for r in result.newton)), "max_wear": float(result.wear.max())}


def run_reference(maxh: float, beta: float) -> dict:
    """One nonlinear elastic solve by NGSolve's Newton under the pad's mean contact load (see the docstring)."""
    import ngsolve as ngs

    from ngwear.model.materials import region_laws
    from ngwear.numerics.forms import displacement_space
    sys.path.insert(0, str(C.ROOT / "tests"))      # the reference solver lives beside the tests that use it
    from energy_minimum import energy_form, minimise
    scene = compaction_scene(maxh, beta, 1)
    mesh = C.mesh_for(scene)
    fes = displacement_space(mesh, scene)
    area = ngs.Integrate(ngs.CF(1.0), mesh, definedon=mesh.Boundaries("contact"))
    pressure = abs(scene.loads.plate.force[2]) / area
    nu = ngs.CF(tuple(scene.contact.direction))
    velocity = ngs.CF((-ngs.y, ngs.x, 0)) / ngs.sqrt(ngs.x ** 2 + ngs.y ** 2)     # the disc turns about +z
    traction = -pressure * nu + scene.contact.friction * pressure * velocity
    row = {"ref_ndof": fes.ndof}
    for inverse in ("pardiso", "sparsecholesky"):
        gfu = ngs.GridFunction(fes)
        t0 = C.perf()
        form = energy_form(fes, region_laws(scene), tractions={"contact": traction})
        first = minimise(form, gfu, maxit=1, inverse=inverse)            # NGSolve's error of the initial guess
        solved = minimise(form, gfu, tol=1e-10 * first.errors[0], inverse=inverse)
        row[f"ref_{inverse}_s"] = C.perf() - t0
        row[f"ref_{inverse}_iterations"] = 1 + solved.iterations
        row[f"ref_{inverse}_converged"] = solved.converged
    return row


def compaction_case(maxh: float, beta: float, steps: int, reps: int, blas_threads) -> dict:
    job = {"maxh": maxh, "steps": steps}
    runs, linear, refs = [], [], []
    for _ in range(reps):      # interleaved, each in a fresh process
        refs.append(C.in_subprocess(__file__, {"fn": "reference", "maxh": maxh, "beta": beta}, blas_threads))
        runs.append(C.in_subprocess(__file__, {"fn": "ngwear", **job, "beta": beta}, blas_threads))
        linear.append(C.in_subprocess(__file__, {"fn": "ngwear", **job, "beta": None}, blas_threads))
    row = {"maxh": maxh, "beta_over_eta": beta, **{k: runs[-1][k] for k in ("ndof", "points", "steps", "status",
                                                                              "tangents", "factorised", "bulk",
                                                                              "max_wear")}}
    row.update({k: C.median([r[k] for r in runs]) for k in ("run_s", "loop_s")})
    row["linear_s"] = C.median([r["run_s"] for r in linear])
    for key in ("ref_pardiso_s", "ref_sparsecholesky_s"):
        row[key] = C.median([r[key] for r in refs])
    row["ref_iterations"] = refs[-1]["ref_pardiso_iterations"]
    row["ref_converged"] = all(r["ref_pardiso_converged"] and r["ref_sparsecholesky_converged"] for r in refs)
    row["to_reference"] = row["run_s"] / row["ref_pardiso_s"]
    row["to_reference_chol"] = row["run_s"] / row["ref_sparsecholesky_s"]
    row["to_linear"] = row["run_s"] / row["linear_s"]
    row["reps"] = reps
    row["target"] = C.verdict(row["to_reference"] <= TARGET) if steps == 100 else f"({steps} steps)"
    print(f"  pad {maxh} β = {beta:g}η: {row['ndof']} DOFs, {steps} steps {row['run_s']:.1f}s ({row['tangents']} "
          f"tangents, {row['factorised']} factorised), one NGSolve solve {row['ref_pardiso_s']:.2f}s, ratio "
          f"{row['to_reference']:.1f}, linear {row['linear_s']:.2f}s", flush=True)
    return row


# ---- main -----------------------------------------------------------------------------------------------
LINEAR_COLUMNS = [("case", "case", None), ("variant", "variant", None), ("ndof", "DOFs", "d"),
                  ("points", "points", "d"), ("mode", "solve", None), ("run_s", "run s", ".3f"),
                  ("min_s", "min", ".3f"), ("max_s", "max", ".3f"), ("ratio", "/ iso", ".2f"),
                  ("ratio_min", "min / iso min", ".2f"), ("ratio_per_dof", "/ iso per DOF", ".2f"),
                  ("to_elastic", "/ elastic", ".2f"),
                  ("regression", "> 10 %", None)]
COMPACTION_COLUMNS = [("maxh", "maxh", "g"), ("beta_over_eta", "β/η", "g"), ("ndof", "DOFs", "d"),
                      ("points", "points", "d"), ("steps", "steps", "d"), ("run_s", "ngwear s", ".1f"),
                      ("loop_s", "loop s", ".1f"), ("tangents", "tangents", "d"), ("factorised", "factorised", "d"),
                      ("bulk", "images", "d"),
                      ("ref_pardiso_s", "NGSolve Newton s", ".2f"), ("ref_iterations", "its", "d"),
                      ("ref_sparsecholesky_s", "(sparsecholesky)", ".2f"), ("to_reference", "/ Newton", ".1f"),
                      ("to_reference_chol", "/ (chol.)", ".1f"), ("linear_s", "linear s", ".2f"),
                      ("to_linear", "/ linear", ".1f"), ("target", "≤ 5×", None)]


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.add_argument("--part", default="all", choices=("linear", "compaction", "all"))
    p.add_argument("--steps", type=int, default=100, help="steps of the compaction runs")
    p.add_argument("--large-steps", type=int, default=None, help="steps at the largest pad (default --steps)")
    p.add_argument("--betas", default=",".join(f"{b:g}" for b in BETAS), help="β/η of the compaction runs")
    p.add_argument("--pads", default=None, help="maxh of the compaction pads (comma-separated)")
    p.add_argument("--name", default="materials", help="results/NAME.* of the compaction part")
    p.add_argument("--cases", default=None, help="linear cases, e.g. strip:10k,pad:0.002 (default: all)")
    p.add_argument("--variants", default=",".join(VARIANTS), help="linear variants, iso first (default: all)")
    p.add_argument("--suffix", default="", help="results/materials_linearSUFFIX.* of the linear part")
    p.add_argument("--job", default=None, help=argparse.SUPPRESS)
    p.set_defaults(blas_threads=None)
    args = p.parse_args()
    if args.job:
        job = json.loads(args.job)
        with C.blas_limit(args.blas_threads):
            fn = run_ngwear if job.pop("fn") == "ngwear" else run_reference
            print(json.dumps(fn(**job)))
        return
    header = C.machine_lines(args)
    if args.part in ("linear", "all"):
        rows = []
        with C.blas_limit(args.blas_threads):
            for kind, size in linear_cases(args):
                rows += linear_case(kind, size, args.reps, args.variants.split(","))
        C.finish(f"materials_linear{args.suffix}", "Linear materials against the isotropic one", header + [
            "100 steps from the cached mesh; variants interleaved in one process, medians; elastic = NGSolve "
            f"assemble + sparsecholesky + 1 solve; regression: > {REGRESSION - 1:.0%} slower than iso (per DOF "
            "for the backing)"], rows, LINEAR_COLUMNS, quick=args.quick)
    if args.part in ("compaction", "all"):
        pads = [float(h) for h in args.pads.split(",")] if args.pads else list(PAD_SIZES[:1] if args.quick else PAD_SIZES)
        rows = []
        for maxh in pads:
            steps = args.large_steps if maxh == min(PAD_SIZES) and args.large_steps else args.steps
            for beta in (float(b) for b in args.betas.split(",")):
                rows.append(compaction_case(maxh, beta, steps, args.reps, args.blas_threads))
                C.write_csv(f"{args.name}_partial", header, rows)          # kept should the run be stopped
        C.finish(args.name, "The compaction pad against one nonlinear elastic solve", header + [
            "ngwear = Discretization + simulate from the cached mesh, each run in a fresh process; NGSolve Newton = "
            "one nonlinear solve of the same law under the pad's mean contact load (back clamped), PARDISO; "
            f"target: ngwear / Newton <= {TARGET:g} at 100 steps"], rows, COMPACTION_COLUMNS, quick=args.quick)


if __name__ == "__main__":
    main()
