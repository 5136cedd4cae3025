"""Script mode: ``ngwear run SCENE.toml [--out DIR] [--set KEY=VALUE ...] [--no-pictures]``; ``ngwear explore``.

Bad input exits with status 2 and one line naming the field; a run that stops part-way writes the
steps it completed and exits with status 1.
"""
from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

from .model.scene import SceneError, load_scene, parse_override
from .views.app import DEFAULT_PORT


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="ngwear", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="simulate a scene and write results, VTU/PVD and pictures")
    run.add_argument("scene", help="scene TOML file, e.g. geometries/paper_strip.toml")
    run.add_argument("--out", help="output directory (default: out/<scene name>)")
    run.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE",
                     help="override scene fields, e.g. time.steps=10 mesh.maxh=0.05")
    run.add_argument("--no-pictures", action="store_true", help="skip the pyvista PNGs")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    ver = sub.add_parser("verify", help="convergence study (h and k) and the (H_S) check of a scene")
    ver.add_argument("scene", help="scene TOML file")
    ver.add_argument("--out", help="output directory (default: out/<scene name>-verify)")
    ver.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE", help="override scene fields")
    ver.add_argument("--quick", action="store_true", help="coarse meshes and few steps (about 10 s)")
    exp = sub.add_parser("explore", help="serve the explorer as a web app on 127.0.0.1 (needs ngwear[app])")
    exp.add_argument("scene", nargs="?", default="geometries/paper_strip.toml",
                     help="scene TOML file (default: geometries/paper_strip.toml)")
    exp.add_argument("--port", type=int, help=f"port (default: {DEFAULT_PORT} or the next free one)")
    exp.add_argument("--out", help="folder the save buttons write into (default: out/<scene name>-explore)")
    exp.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE", help="override scene fields")
    exp.add_argument("--kernel-timeout", type=int, default=60, metavar="SECONDS",
                     help="end the kernel of a closed page once idle this long (default: 60)")
    stress = sub.add_parser("stress", help="run the stability stress matrix and write its report")
    stress.add_argument("args", nargs=argparse.REMAINDER, help="passed on (see `ngwear stress -- --help`)")
    return parser


def _scene(args):
    scene = load_scene(args.scene)
    if args.set:
        scene = scene.replace(**dict(parse_override(item) for item in args.set))
    return scene


def verify(args) -> int:
    from .numerics.discrete import Discretization
    from .studies import verify as study
    from .studies.theory import smallness
    from .views import plots

    scene = _scene(args)
    out = Path(args.out or Path("out") / f"{scene.name}-verify")
    out.mkdir(parents=True, exist_ok=True)
    h0 = scene.mesh.maxh
    hs, h_ref = ([4 * h0, 2 * h0, h0], h0 / 2) if args.quick else ([8 * h0, 4 * h0, 2 * h0, h0], h0 / 4)
    steps = [10, 20, 40] if args.quick else [10, 20, 40, 80]
    base = scene.replace(**{"time.steps": 20, "output.every": 20})
    h_rows = study.h_study(base, hs, h_ref)
    sections = [f"# Convergence of {scene.name}\n",
                f"{smallness(Discretization(scene)).message()}\n",
                f"## h-refinement (P{scene.mesh.order}, {base.time.steps} steps, reference maxh = {h_ref:g})\n",
                study.markdown(h_rows, "h"), "\n![h](convergence_h.png)"]
    k_studies = {}
    for integrator in ("explicit", "implicit", "trapezoidal"):
        k_scene = base.replace(**{"wear.integrator": integrator, "mesh.maxh": 2 * h0})
        k_studies[integrator] = rows = study.k_study(k_scene, steps, 8 * steps[-1])
        sections += [f"\n## k-refinement, {integrator} wear (maxh = {2 * h0:g}, reference {8 * steps[-1]} steps)\n",
                     study.markdown(rows, "k")]
    sections.append("\n![k](convergence_k.png)")
    plots.convergence({f"P{scene.mesh.order}": h_rows}, "h", out / "convergence_h.png")
    plots.convergence(k_studies, "k", out / "convergence_k.png", columns=("W_sum",))
    sections += ["\n## Stability of the wear integrators (overshoot = max (w − u_ν)₊ / g; exact: 0)\n",
                 study.table(study.stability_study(base.replace(**{"mesh.maxh": 2 * h0}), [30, 15, 10, 6, 3]))]
    text = "\n".join(sections) + "\n"
    (out / "convergence.md").write_text(text)
    print(text)
    print(f"written  {out}/convergence.md")
    return 0


def run(args) -> int:
    from .runs.simulate import simulate

    scene = _scene(args)
    out = Path(args.out or Path("out") / scene.name)
    result = simulate(scene, progress=not args.quiet)
    result.save(out)
    pictures = []
    if not args.no_pictures and result.steps >= 0:
        from .views.render import paper_figures
        pictures = paper_figures(result, out)
    summary = result.summary()
    width = max(map(len, summary))
    for key, value in summary.items():
        print(f"{key:<{width}}  {value:.4g}" if isinstance(value, float) else f"{key:<{width}}  {value}")
    if scene.contact.friction > 0 and result.discretization is not None:
        from .studies.theory import smallness
        check = smallness(result.discretization)
        print(f"{'uniqueness' if check.holds else 'warning':<{width}}  {check.message()}")
    for warning in result.warnings:
        print(f"{'warning':<{width}}  {warning}")
    print(f"{'written':<{width}}  {out}/ (result.npz, fields.pvd, {len(pictures)} PNG)")
    if not result.completed:
        print(f"ngwear: run stopped early: {result.status}", file=sys.stderr)
        return 1
    return 0


def explore(args) -> int:
    from importlib.util import find_spec

    from .views import app
    if find_spec("voila") is None:
        print("ngwear: explore needs the optional packages of ngwear[app] (voila is missing): "
              "pip install 'ngwear[app]'", file=sys.stderr)
        return 2
    scene = _scene(args)
    if args.kernel_timeout < 1:
        raise SceneError(f"--kernel-timeout: must be >= 1 s (got {args.kernel_timeout})")
    try:
        port = app.free_port(args.port)
    except OSError as err:
        print(f"ngwear: --port: {err}", file=sys.stderr)
        return 2
    folder = Path(args.out or Path("out") / f"{scene.name}-explore")
    return app.serve(scene, port=port, folder=folder, kernel_timeout=args.kernel_timeout)


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="ngwear: %(message)s")
    if args.command == "stress":
        from .studies.stress import main as stress_main
        return stress_main([a for a in args.args if a != "--"])
    try:
        return {"run": run, "verify": verify, "explore": explore}[args.command](args)
    except SceneError as err:
        print(f"ngwear: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        print(f"ngwear: --out: cannot write {err.filename or args.out} ({err.strerror or err})", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
