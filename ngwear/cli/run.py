"""``ngwear run``: a scene run from the terminal, its files, its pictures and its summary.

A run that stops part-way writes the steps it completed and exits with status 1, as does a run stopped by a full disk
(one line saying what its checkpoint keeps); an interrupt exits with 128 + the signal, after writing the steps done.
"""
from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path

from scipy.sparse.linalg import ArpackNoConvergence

from ..model.netgen_meshing import Stopped
from ..model.scene import parse_override
from ..results.checkpoint import saved_scene
from ..results.folder import NoSpace, hold, no_space
from ..results.material_summary import describe
from ..results.summary import LAST_STEP
from ..results.units import suffix
from ..results.units import unit as unit_of
from ..runs.checks import WORN_OUT
from ..runs.simulate import Stages, simulate
from ..studies.theory import uniqueness as lanczos_uniqueness
from .shell import STAGES, scene_of
from .signals import on_signals


def run(args) -> int:
    scene, settings = scene_of(args, required=args.resume is None)
    out = Path(args.out or args.resume or Path("out") / scene.name)      # --out with --resume: go on there
    with hold(out, written(args), create=args.resume is None or args.out is not None):   # for the whole run
        return _run(args, scene, settings, out)


def written(args) -> str:
    """The flag of the folder a command writes into: --out, or --resume when it goes on in the resumed folder."""
    return "--resume" if getattr(args, "resume", None) and not getattr(args, "out", None) else "--out"


def _run(args, scene, settings, out: Path) -> int:
    if args.resume is not None and scene is None:
        scene = saved_scene(args.resume)
        scene = scene.replace(**dict(parse_override(item) for item in settings)) if settings else scene
    stop, received = threading.Event(), []

    def interrupt(number):      # stop at the next step boundary; a second signal changes nothing
        received.append(number)
        stop.set()

    result = None
    try:
        with on_signals(interrupt):
            result = simulate(scene, progress=not args.quiet, checkpoint=out, resume=args.resume, stop=stop)
            STAGES.info("%s: writing result.npz and %d VTU frames", result.scene.name, len(result.stored_steps))
            result.save(out)
            check = None if args.no_check else uniqueness(result, stop, progress=not args.quiet)
            write(result, out, pictures=not args.no_pictures and not stop.is_set(), check=check)
    except Stopped as err:
        print(f"ngwear: interrupted during the set-up ({err}); nothing was computed", file=sys.stderr)
        return 128 + received[0]
    except NoSpace as err:
        print(f"ngwear: {written(args)}: {err}" + (f": ngwear run --resume {out}" if err.resumable else ""),
              file=sys.stderr)
        return 1
    except OSError as err:
        if result is None or not no_space(err):
            raise
        print(f"ngwear: {written(args)}: no space left on device in {out} for the results; the checkpoint keeps all "
              f"{result.steps + 1} steps: free space, then write them with: ngwear run --resume {out}",
              file=sys.stderr)
        return 1
    if result.completed and received:
        print("ngwear: interrupted after the run: it is complete and written" + ("" if args.no_pictures else
              " (the pictures drawn before the signal)"), file=sys.stderr)
        return 128 + received[0]
    if result.status == "interrupted":
        t = result.times[-1] if len(result.times) else 0.0
        print(f"ngwear: interrupted after step {result.steps} (t = {t:.4g}); resume with: ngwear run --resume {out}",
              file=sys.stderr)
        return 128 + (received[0] if received else signal.SIGINT)
    if result.status == WORN_OUT:
        print(f"ngwear: worn out: {result.warnings[-1]}", file=sys.stderr)
        return 0
    if not result.completed:
        print(f"ngwear: run stopped early: {result.status}", file=sys.stderr)
        return 1
    return 0


def uniqueness(result, stop, progress: bool) -> tuple[str, str] | None:
    """(label, text) of the summary's (H_S) line for a completed run with friction; None when there is nothing to say.

    Information, not a warning: (H_S) is sufficient for uniqueness, and a completed run has met the invariants at
    every step whatever it says.  Never after an interrupt; a signal during the check aborts it.  It reuses the
    run's factorisation (:func:`ngwear.studies.theory.uniqueness`), shown as a stage on the progress bar.
    """
    disc = result.discretization
    if not result.completed or stop.is_set() or disc is None or not disc.contact.coefficients.friction.any():
        return None
    stages = Stages(result.scene.name, progress)
    try:
        check = stages.run(f"uniqueness (H_S): Lanczos on the compliance of {disc.points.n} contact points",
                           lambda: lanczos_uniqueness(disc, stop.is_set))
    except KeyboardInterrupt:
        return "uniqueness", "(H_S) not evaluated: interrupted"
    except ArpackNoConvergence as err:
        return "uniqueness", f"(H_S) not evaluated: Lanczos did not converge ({str(err).splitlines()[0]})"
    finally:
        stages.close()
    return "uniqueness", check.message() + ("" if check.holds else "; the run's own checks hold")


def write(result, out: Path, pictures: bool, check: tuple[str, str] | None = None) -> None:
    """Write the result's pictures into ``out`` (saved there before) and print the summary."""
    written = []
    if pictures and result.steps >= 0:
        from ..views.pictures import write_pictures  # pyvista and VTK: loaded for the pictures alone
        STAGES.info("%s: drawing the pictures", result.scene.name)
        written = write_pictures(result, out)
    summary = result.summary()
    unit, materials = summary.pop("units", {}), summary.pop("materials")
    provenance, blocks = summary.pop("provenance", None), summary.pop("blocks", [])
    warnings = summary.pop("warnings")
    width = max(map(len, summary))
    for key, value in summary.items():
        if key == LAST_STEP[0] and "end_time" in summary:   # the whole run's numbers first, then the last step's
            print(f"{'last step':<{width}}  t = {summary['end_time']:.4g}" + (f" {unit['end_time']}" if unit else ""))
        text = "never" if key in ("gap_reached_at", "stops_to_limit") and value is None else (
            f"{value + 0.0:.4g}" if isinstance(value, float) else f"{value}")       # + 0.0: never −0
        print(f"{key:<{width}}  {text} {unit[key]}" if key in unit and value is not None else f"{key:<{width}}  {text}")
    volume, degrees = suffix(result.scene, "volume"), suffix(result.scene, "temperature")
    for b in blocks:                                # a programme's wear per block
        per_mj = "" if b["volume_per_megajoule"] is None else f", {b['volume_per_megajoule']:.4g}{volume} per MJ"
        hot = "" if "peak_face_temperature" not in b else (
            f", face up to {b['peak_face_temperature']:.4g}{degrees}, track up to {b['peak_track_temperature']:.4g}"
            f"{degrees}")
        print(f"{'block ' + str(b['block']):<{width}}  {b['stops']} stops, {b['volume_per_stop']:.4g}{volume} worn "
              f"per stop{per_mj}{hot}")
    for region, entry in materials.items():         # m_F, L_F of each law beside (H_S)
        print(f"{'material':<{width}}  {region}: {describe(entry, unit_of(result.scene, 'pressure'))}")
    if check is not None:
        print(f"{check[0]:<{width}}  {check[1]}")
    for warning in warnings:
        print(f"{'warning':<{width}}  {warning}")
    if provenance:
        print(f"{'provenance':<{width}}  ngwear {provenance['ngwear']}, NGSolve {provenance['ngsolve']}, Python "
              f"{provenance['python']}, scene {provenance['scene_sha256'][:12]}")
    frames = len(result.stored_steps)
    print(f"{'written':<{width}}  {out}/ (result.npz, history.csv, fields.pvd with {frames} frames, {len(written)} "
          "PNG)")
