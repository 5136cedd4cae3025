"""The commands of the command line: its parser, ``ngwear verify``, ``examples``, ``schema``, ``sweep``, ``explore``.

:func:`dispatch` parses the arguments and runs the command (``ngwear run``: :mod:`ngwear.cli.run`); bad input is
one line naming the field, exit 2 (see :mod:`ngwear.cli`).
"""
from __future__ import annotations

import argparse
import secrets
import sys
from pathlib import Path

from ..model.scene import SceneError, parse_override
from ..results.folder import FolderError
from ..studies.study import StudyError
from ..version import __version__
from ..views.app import DEFAULT_PORT
from .run import run, written
from .shell import OneLineParser, log_lines, scene_of
from .signals import on_signals

FLAGS = {"checkpoint": "--out", "resume": "--resume", "out": "--out"}
"""The flag of each Python argument a FolderError may name."""


SCENE_HELP = "scene TOML file, or the name of a shipped scene (see `ngwear examples`), e.g. paper_strip"
DESCRIPTION = ("An elastic body in frictional contact with a moving rigid foundation while its soft layer wears: "
               "run a scene, verify it, study it on Dask, explore it in the browser.  `ngwear COMMAND --help` "
               "shows a command's options.")
"""The parser's description.  Help texts are plain text (`code` in single backquotes), read in a terminal; the
documentation's CLI reference turns them into reST (``docs/_ext/ngwear_reference.py``)."""


def _parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="ngwear", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    talk = argparse.ArgumentParser(add_help=False)
    how = talk.add_mutually_exclusive_group()
    how.add_argument("-q", "--quiet", action="store_true", help="no progress bar or stage lines: warnings and errors only")
    how.add_argument("-v", "--verbose", action="store_true",
                     help="also the solver's notes and the log of the libraries (Dask's included)")
    run = sub.add_parser("run", help="simulate a scene and write results, VTU/PVD and pictures", parents=[talk])
    run.add_argument("scene", nargs="?", help=SCENE_HELP)
    run.add_argument("--out", help="output directory (default: out/<scene name>)")
    _overrides(run)
    run.add_argument("--resume", metavar="OUTDIR", help="go on from the checkpoint in OUTDIR (a SCENE or --set "
                                                         "may extend time.T); with --out, in that folder instead "
                                                         "(OUTDIR stays as it is)")
    run.add_argument("--no-pictures", action="store_true", help="skip the pictures and plots (PNG)")
    run.add_argument("--no-check", action="store_true", help="skip the uniqueness check (H_S) after the run")
    ver = sub.add_parser("verify", help="convergence study (h and k) and the (H_S) check of a scene", parents=[talk])
    ver.add_argument("scene", nargs="?", help=SCENE_HELP)
    ver.add_argument("--out", help="output directory (default: out/<scene name>-verify)")
    _overrides(ver)
    ver.add_argument("--quick", action="store_true", help="coarse meshes and few steps (about 10 s)")
    schema = sub.add_parser("schema", help="write the scene files' JSON Schema (for editors)", parents=[talk])
    schema.add_argument("--out", help="file to write (default: print it)")
    sweep = sub.add_parser("sweep", help="run a parameter study on Dask and tabulate its outputs", parents=[talk])
    sweep.add_argument("study", help="study TOML file, e.g. geometries/studies/friction_wear.toml")
    sweep.add_argument("--out", help="output directory (default: out/<study name>); finished cases are kept")
    sweep.add_argument("--scheduler", metavar="ADDRESS",
                       help="Dask scheduler of an existing cluster, e.g. tcp://host:8786 (default: a local cluster)")
    sweep.add_argument("--workers", type=int, metavar="N",
                       help="local cluster: worker processes (default: one per core); --scheduler: workers to wait for")
    sweep.add_argument("--set", nargs="+", action="extend", default=[], metavar="KEY=VALUE",
                       help="override the base scene (may be given several times)")
    exp = sub.add_parser("explore", help="serve the explorer as a web app on 127.0.0.1 (needs ngwear[app])", parents=[talk])
    exp.add_argument("scene", nargs="?", default="paper_strip", help=f"{SCENE_HELP} (default: paper_strip)")
    exp.add_argument("--port", type=int, help=f"port (default: {DEFAULT_PORT} or the next free one)")
    exp.add_argument("--out", help="folder the save buttons write into (default: out/<scene name>-explore)")
    _overrides(exp)
    exp.add_argument("--kernel-timeout", type=int, default=60, metavar="SECONDS",
                     help="end the kernel of a closed page once idle this long (default: 60)")
    exp.add_argument("--max-kernels", type=int, default=4, metavar="N",
                     help="most kernels at once, ~500 MB each, the preheated one included: a page beyond gets "
                          "'busy' (default: 4)")
    exp.add_argument("--allow-origin", action="append", default=[], metavar="ORIGIN",
                     help="also serve requests from ORIGIN and for its host, e.g. https://ngwear.example.org "
                          "behind a reverse proxy (may be given several times)")
    exp.add_argument("--no-token", action="store_true",
                     help="no token in the URL: anyone who can reach the port can use the app (not recommended)")
    examples = sub.add_parser("examples", help="list the shipped scenes, or copy them into a folder to start from",
                              parents=[talk])
    examples.add_argument("--copy", metavar="DIR", help="copy the shipped scenes, the CAD part they read, the studies "
                                                        "and scene.schema.json into DIR (nothing there is overwritten)")
    stress = sub.add_parser("stress", help="run the stability stress matrix and write its report", parents=[talk])
    stress.add_argument("args", nargs=argparse.REMAINDER, help="passed on (see `ngwear stress -- --help`)")
    return parser


def _overrides(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--set", nargs="+", action="extend", default=[], metavar="KEY=VALUE",
                        help="override scene fields, e.g. time.steps=10 mesh.maxh=0.05 (may be given several times)")


def verify(args) -> int:
    import json

    from ..results.folder import hold, replacing
    from ..studies import convergence
    from ..studies.verify import StoppedRun
    from ..views import plots

    scene, _ = scene_of(args)
    out = Path(args.out or Path("out") / f"{scene.name}-verify")
    with hold(out, "--out"):                        # as a run's: one study at a time writes there
        try:
            report = convergence.run(scene, quick=args.quick)
        except StoppedRun as err:
            print(f"ngwear: verify: a run of the study stopped: {err}", file=sys.stderr)
            return 1
        if report.h_rows:
            columns = [c for c in ("V_sum", "W_sum") if all(r[c] > 0 for r in report.h_rows)]   # no wear: V alone
            plots.convergence({f"P{scene.mesh.order}": report.h_rows}, "h", out / "convergence_h.png",
                              columns=columns)
        if report.k_rows:
            plots.convergence(report.k_rows, "k", out / "convergence_k.png", columns=("W_sum",))
        text = report.markdown()
        for name, content in (("convergence.md", text),
                              ("convergence.json", json.dumps(report.to_dict(), indent=1, default=float))):
            with replacing(out / name) as tmp:
                tmp.write_text(content)
    print(text)
    print(f"written  {out}/convergence.md, convergence.json")
    return 0


def examples(args) -> int:
    from ..model import examples as shipped

    if args.copy is None:
        names = shipped.names()
        width = max(map(len, names))
        for name in names:
            print(f"{name:<{width}}  {shipped.title(name)}")
        return 0
    try:
        written = shipped.copy(args.copy)
    except FileExistsError as err:
        print(f"ngwear: --copy: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        print(f"ngwear: --copy: cannot write {err.filename or args.copy} ({err.strerror or err})", file=sys.stderr)
        return 2
    print(f"copied {len(written)} files into {args.copy}; run one with: ngwear run {Path(args.copy) / 'paper_strip.toml'}")
    return 0


def schema(args) -> int:
    import json

    from ..model.scene import json_schema

    text = json.dumps(json_schema(), indent=1, ensure_ascii=False) + "\n"
    if args.out:
        Path(args.out).write_text(text, encoding="utf-8")
    else:
        print(text, end="")
    return 0


def sweep(args) -> int:
    import shlex
    import threading

    from ..studies.sweep import summary_text
    from ..studies.sweep import sweep as run_study

    overrides = dict(parse_override(item) for item in args.set)
    stop, received = threading.Event(), []

    def interrupt(number):      # stop at the next case boundary
        received.append(number)
        stop.set()

    with on_signals(interrupt):
        table = run_study(args.study, args.scheduler, out=args.out, workers=args.workers, overrides=overrides,
                          progress=not args.quiet, stop=stop)
    summary = table.attrs["summary"]
    if summary["interrupted"]:
        again = shlex.join(["ngwear", "sweep", args.study, "--out", summary["out"],
                            *(["--scheduler", args.scheduler] if args.scheduler else []),
                            *(["--workers", str(args.workers)] if args.workers else []),
                            *(["--set", *args.set] if args.set else [])])
        finished = summary["cases"] - summary["interrupted"] - summary["crashed"]
        print(f"ngwear: interrupted after {finished} of {summary['cases']} cases (kept in {summary['out']}); "
              f"resume with: {again}", file=sys.stderr)
        return 128 + received[0]
    shown = table.drop(columns=["warnings", "worker", "case_id"])
    print(shown.to_string(index=False, float_format=lambda v: f"{v:.4g}", max_colwidth=60))
    print(summary_text(summary))
    failed = summary["cases"] - summary["completed"]
    if failed:
        print(f"ngwear: {failed} of {summary['cases']} cases did not complete (see the error column)", file=sys.stderr)
        return 1
    return 0


def explore(args) -> int:
    from importlib.util import find_spec

    from ..views import app
    if find_spec("voila") is None:
        print("ngwear: explore: needs the optional packages of ngwear[app] (voila is missing): "
              "pip install 'ngwear[app]'", file=sys.stderr)
        return 2
    scene, _ = scene_of(args)
    if args.kernel_timeout < 1:
        raise SceneError(f"--kernel-timeout: must be >= 1 s (got {args.kernel_timeout})")
    if args.port is not None and not 1 <= args.port <= 65535:
        raise SceneError(f"--port: must be in 1..65535 (got {args.port})")
    if args.max_kernels < 1:
        raise SceneError(f"--max-kernels: must be >= 1 (got {args.max_kernels})")
    try:
        origins = tuple(app.check_origin(origin) for origin in args.allow_origin)
    except ValueError as err:
        raise SceneError(f"--allow-origin: {err}") from None
    try:
        port = app.free_port(args.port)
    except OSError as err:
        print(f"ngwear: --port: {err}", file=sys.stderr)
        return 2
    folder = Path(args.out or Path("out") / f"{scene.name}-explore")
    if args.no_token:
        print(f"ngwear: warning: --no-token: anyone who can reach port {port} (every user of this machine, anyone "
              f"a reverse proxy lets through) can drive the app and save into {folder}", file=sys.stderr)
    return app.serve(scene, port=port, folder=folder, token="" if args.no_token else secrets.token_hex(24),
                     kernel_timeout=args.kernel_timeout, max_kernels=args.max_kernels, origins=origins)


def dispatch(argv: list[str] | None = None) -> int:
    """Parse ``argv`` and run its command: its exit status (bad input: one line, 2)."""
    args = _parser().parse_args(argv)
    log_lines(args.quiet, args.verbose)
    if args.command == "stress":
        from ..studies.stress import main as stress_main
        return stress_main([a for a in args.args if a != "--"], prog="ngwear stress")
    try:
        commands = {"run": run, "verify": verify, "schema": schema, "sweep": sweep, "explore": explore,
                    "examples": examples}
        return commands[args.command](args)
    except FolderError as err:
        print(f"ngwear: {err.named(FLAGS.get(err.key, err.key))}", file=sys.stderr)
        return 2
    except (SceneError, StudyError) as err:
        print(f"ngwear: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        folder = getattr(args, "out", None) or getattr(args, "resume", None)
        name = err.filename2 or err.filename or folder          # a rename's target, rather than its temporary file
        print(f"ngwear: {written(args)}: cannot write {name} ({err.strerror or err})", file=sys.stderr)
        return 2
