"""Stability stress matrix: extreme scenes, each run and checked against the invariants.

Every scene of :data:`CATALOGUE` (read from ``stress_scenes.toml``) is a small variation of the paper
strip (``geometries/paper_strip.toml`` at ``mesh.maxh = 0.1``, 20 steps), of ``geometries/box3d.toml``
or of the shipped brake pad and pin-on-disc (coarse, 20 steps), pushed to an extreme: friction μ far
past the smallness bound, k·α·L from 0.01 to 100 with each wear integrator, g from 1 down to 1e-6,
compliance slope L from 1e-2 to 1e8 (the Signorini limit), power-law compliance, lift-off, load
reversal, foundation-speed reversal, badly shaped meshes, P2, 3D, plates and turning discs.  A run must end in one of

* ``converged``: every step done and every invariant held at every step
  (:mod:`ngwear.runs.checks`, which the time loop itself checks);
* ``stopped``: ``result.completed`` is False and ``result.status`` names the step, the cause and a
  remedy — the completed steps kept must still satisfy the invariants;
* ``rejected``: the scene is refused up front with a :class:`~ngwear.scene.SceneError` naming the
  field and the remedy;

anything else (an exception with a traceback, NaN in a completed step, an invariant broken in a
step reported done) is a ``crashed`` / ``violated`` outcome, i.e. a bug.  Scenes with a known
physical answer also carry a ``check`` (:mod:`ngwear.studies.stress_checks`).

``python -m ngwear.studies.stress [--quick] [--out docs/stress_report.md] [--only NAME ...]`` runs the
matrix and writes the Markdown report (:mod:`ngwear.studies.stress_report`).
"""
from __future__ import annotations

import logging
import math
import sys
import time
import tomllib
import traceback
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..model.examples import FOLDER as GEOMETRIES
from ..model.scene import Scene, SceneError, load_scene
from ..runs.checks import allowances, invariants, k_alpha_slope, worst
from .stress_checks import CHECKS, ROW_CHECKS
from .stress_report import REPORT, write_report

SCENES = Path(__file__).with_name("stress_scenes.toml")

#: the base scenes: the paper strip kept small, the 3D box as shipped, the pad and the pin coarse and short
BASES: dict[str, tuple[str, dict[str, Any]]] = {
    "strip": ("paper_strip.toml", {"mesh.maxh": 0.1, "time.steps": 20, "output.every": 1.0}),
    "box": ("box3d.toml", {"output.every": 1.0}),
    "pad": ("brake_pad.toml", {"mesh.maxh": 0.012, "time.steps": 20, "output.every": 150.0}),
    "pin": ("pin_on_disc.toml", {"mesh.maxh": 0.003, "mesh.contact_maxh": 0.0006, "time.steps": 20,
                                 "output.every": 60.0}),
}


@dataclass(frozen=True)
class StressScene:
    """One entry of the matrix: overrides of a base scene and what we expect of it.

    ``expect`` is the pinned outcome (``converged``, ``stopped``, ``rejected``) or None when
    either acceptable one would do; ``reason`` says why.  ``checks`` name physics checks of
    :data:`~ngwear.studies.stress_checks.CHECKS` that the run must pass.  ``bug`` describes a known
    ngwear bug the scene exposes: ``expect`` is then the *correct* outcome, which it does not reach yet.
    """

    name: str
    group: str
    overrides: dict[str, Any]
    expect: str | None = "converged"
    reason: str = ""
    checks: tuple[str, ...] = ()
    base: str = "strip"
    quick: bool = False
    bug: str = ""

    def scene(self) -> Scene:
        path, defaults = BASES[self.base]
        return load_scene(GEOMETRIES / path).replace(**{**defaults, **self.overrides, "name": self.name})


def _catalogue() -> tuple[StressScene, ...]:
    """The scenes of ``stress_scenes.toml`` (data, not logic: see its header)."""
    data = tomllib.loads(SCENES.read_text(encoding="utf-8"))
    return tuple(StressScene(e["name"], e["group"], e["overrides"],
                             None if e.get("expect") == "either" else e.get("expect", "converged"),
                             e.get("reason", ""), tuple(e.get("checks", ())), e.get("base", "strip"),
                             e.get("quick", False), e.get("bug", "")) for e in data["scene"])


CATALOGUE = _catalogue()


@dataclass
class StressRow:
    """What one scene of the matrix did: the report's row (``result``: the run, when asked for)."""

    spec: StressScene
    outcome: str = ""
    message: str = ""
    steps: int = 0
    of: int | None = None
    newton_total: int = 0
    newton_max: int = 0
    cutbacks: int = 0
    max_wear: float = math.nan
    max_penetration: float = math.nan
    gap: float = math.nan
    kaL: float = math.nan
    hs_ratio: float | None = None
    worst: tuple[str, float] = ("", math.nan)
    violations: dict[str, float] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    check_failures: list[str] = field(default_factory=list)
    contact_points: int = 0
    wall_time: float = 0.0
    traceback: str = ""
    result: Any = None

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def params(self) -> str:
        return _params(self.spec.overrides, self.spec.base)

    @property
    def acceptable(self) -> bool:
        """Outcome (a) converged with the invariants, (b) stopped clearly, or refused up front."""
        return self.outcome in ("converged", "stopped", "rejected")

    @property
    def as_expected(self) -> bool:
        """Acceptable, the pinned outcome if any, and every physics check passed."""
        return self.acceptable and self.spec.expect in (None, self.outcome) and not self.check_failures


def clear_stop_message(status: str) -> list[str]:
    """What a stop message lacks: it must name the step (and time) and suggest a remedy."""
    missing = []
    if not status.startswith("step ") or "(t = " not in status:
        missing.append("the step and time")
    if not any(word in status for word in ("try ", "use ", "set ", "increase ", "reduce ")):
        missing.append("a remedy")
    return missing


def smallness_ratio(result) -> float | None:
    """c₀² L_p μ / m_F of the paper's (H_S) on the run's mesh (> 1: past the bound), if available."""
    if result is None or result.discretization is None or not result.discretization.contact.coefficients.friction.any():
        return None
    from .theory import smallness
    check = smallness(result.discretization)
    return check.product / check.monotonicity


def run_scene(spec: StressScene, *, keep_result: bool = False) -> StressRow:
    """Run one scene and classify it (with its ``result`` if asked)."""
    from ..runs.simulate import simulate

    row = StressRow(spec)
    logger = logging.getLogger("ngwear")
    old_level, old_propagate = logger.level, logger.propagate
    logger.setLevel(logging.INFO)
    logger.propagate = False  # keep the console quiet: the row records warnings and messages
    result, caught = None, []
    start = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            scene = spec.scene()
            row.of, row.gap, row.kaL = scene.time.steps, scene.contact.gap, k_alpha_slope(scene)
            result = simulate(scene, progress=False)
            row.kaL = k_alpha_slope(scene, result.discretization.contact.largest_rate())
    except SceneError as err:
        row.outcome, row.message = "rejected", str(err)
    except Exception as err:  # noqa: BLE001 — a crash is exactly what the matrix looks for
        row.outcome, row.message, row.traceback = "crashed", f"{type(err).__name__}: {err}", traceback.format_exc()
    finally:
        row.wall_time = time.perf_counter() - start
        logger.setLevel(old_level)
        logger.propagate = old_propagate
    row.warnings = list(dict.fromkeys(
        (list(result.warnings) if result is not None else [])
        + [f"{w.category.__name__}: {w.message}" for w in caught or []]))
    if result is not None:
        _classify(row, result)
    complete = result is not None and result.completed
    for name in spec.checks:
        if complete or name in ROW_CHECKS:
            row.check_failures += CHECKS[name](row, result)
    row.hs_ratio = smallness_ratio(result)
    if keep_result:
        row.result = result
    return row


def _classify(row: StressRow, result) -> None:
    row.steps = result.steps
    row.contact_points = len(result.weights)
    its = [rec.iterations for rec in result.newton]
    row.newton_total, row.newton_max = int(sum(its)), int(max(its, default=0))
    row.cutbacks = sum(rec.cutbacks for rec in result.newton)
    if len(result.times):
        row.max_wear = float(result.wear.max())
        row.max_penetration = float((result.normal_displacement - result.d0[None, :]).max())
    row.violations = invariants(result)
    row.worst = worst(result, row.violations)
    allowed = allowances(result.scene)
    broken = {k: v for k, v in row.violations.items() if v > allowed[k]}
    if result.completed:
        row.outcome = "violated" if broken else "converged"
        if broken:
            row.message = f"invariant {row.worst[0]} violated by {row.worst[1]:.3g} in a completed run"
        return
    row.message = result.status
    missing = clear_stop_message(result.status)
    if broken:
        row.outcome = "violated"
        row.message += f" [kept steps violate {row.worst[0]} by {row.worst[1]:.3g}]"
    elif missing:
        row.outcome = "unclear stop"
        row.message += f" [the message lacks {' and '.join(missing)}]"
    else:
        row.outcome = "stopped"


def catalogue(quick: bool = False, only: list[str] | None = None) -> list[StressScene]:
    """The scenes to run: all, the quick ones, or those named in ``only``."""
    if only:
        unknown = set(only) - {s.name for s in CATALOGUE}
        if unknown:
            raise KeyError(f"unknown stress scene(s): {', '.join(sorted(unknown))}")
        return [s for s in CATALOGUE if s.name in only]
    return [s for s in CATALOGUE if s.quick or not quick]


def run_matrix(quick: bool = False, only: list[str] | None = None, progress: bool = False) -> list[StressRow]:
    """Run the catalogue (``quick``: the scenes marked quick) and return one row per scene."""
    rows = []
    for spec in catalogue(quick, only):
        row = run_scene(spec)
        if progress:
            print(f"{row.name:<40} {row.outcome:<10} {row.wall_time:6.2f} s", file=sys.stderr)
        rows.append(row)
    return rows


def _params(overrides: dict[str, Any], base: str) -> str:
    """The overrides as the report's parameters cell."""
    def fmt(v):
        if isinstance(v, float):
            return f"{v:g}"
        if isinstance(v, dict):
            return "{" + ", ".join(f"{k}: {fmt(x)}" for k, x in v.items()) + "}"
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(fmt(x) for x in v) + "]"
        return str(v)
    text = ", ".join(f"{k.split('.')[-1] if k.startswith(('contact.', 'wear.')) else k} = {fmt(v)}"
                     for k, v in overrides.items())
    return text or f"({BASES[base][0]} as is)"


def main(argv: list[str] | None = None, prog: str = "python -m ngwear.studies.stress") -> int:
    """``python -m ngwear.studies.stress`` (``ngwear stress``): run the matrix and write the report.

    Exit status 1 when a scene is not as expected (other than the known bugs), else 0.
    """
    from ..cli.shell import OneLineParser

    parser = OneLineParser(prog=prog, description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="only the scenes marked quick")
    parser.add_argument("--out", default=str(REPORT), help=f"report path (default {REPORT})")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="run these scenes only")
    args = parser.parse_args(argv)
    rows = run_matrix(args.quick, args.only, progress=True)
    path = write_report(rows, args.out)
    bad = [r.name for r in rows if not r.as_expected and not r.spec.bug]
    bugs = [r.name for r in rows if r.spec.bug]
    print(f"written {path}: {len(rows)} scenes, {sum(r.wall_time for r in rows):.1f} s"
          + (f"; known bugs: {', '.join(bugs)}" if bugs else "")
          + (f"; NOT as expected: {', '.join(bad)}" if bad else "; the rest as expected"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
