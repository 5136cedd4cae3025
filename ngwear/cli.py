"""Script mode: ``ngwear run SCENE.toml [--out DIR] [--set KEY=VALUE ...] [--no-pictures]``.

Bad input exits with status 2 and one line naming the field; a run that stops part-way writes the
steps it completed and exits with status 1.
"""
from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

from .scene import SceneError, load_scene, parse_override


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
    return parser


def run(args) -> int:
    from .simulate import simulate

    scene = load_scene(args.scene)
    if args.set:
        scene = scene.replace(**dict(parse_override(item) for item in args.set))
    out = Path(args.out or Path("out") / scene.name)
    result = simulate(scene, progress=not args.quiet)
    result.save(out)
    pictures = []
    if not args.no_pictures and result.steps >= 0:
        from .render import paper_figures
        pictures = paper_figures(result, out)
    summary = result.summary()
    width = max(map(len, summary))
    for key, value in summary.items():
        print(f"{key:<{width}}  {value:.4g}" if isinstance(value, float) else f"{key:<{width}}  {value}")
    for warning in result.warnings:
        print(f"{'warning':<{width}}  {warning}")
    print(f"{'written':<{width}}  {out}/ (result.npz, fields.pvd, {len(pictures)} PNG)")
    if not result.completed:
        print(f"ngwear: run stopped early: {result.status}", file=sys.stderr)
        return 1
    return 0


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="ngwear: %(message)s")
    try:
        return run(args)
    except SceneError as err:
        print(f"ngwear: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        print(f"ngwear: --out: cannot write {err.filename or args.out} ({err.strerror or err})", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
