"""Stability stress matrix: extreme scenes, each run and checked against the invariants.

Every scene of :data:`CATALOGUE` (read from ``stress_scenes.toml``) is a small variation of the paper
strip (``geometries/paper_strip.toml`` at ``mesh.maxh = 0.1``, 20 steps), of ``geometries/box3d.toml``
or of the shipped brake pad and pin-on-disc (coarse, 20 steps), pushed to an extreme: friction μ far
past the smallness bound, k·α·L from 0.01 to 100 with each wear integrator, g from 1 down to 1e-6,
compliance slope L from 1e-2 to 1e8 (the Signorini limit), power-law compliance, lift-off, load
reversal, foundation-speed reversal, badly shaped meshes, P2, 3D, plates and turning discs.  A run must end in one of

* ``converged``: every step done and every invariant held at every step (see :func:`invariants`);
* ``stopped``: ``result.completed`` is False and ``result.status`` names the step, the cause and a
  remedy — the completed steps kept must still satisfy the invariants;
* ``rejected``: the scene is refused up front with a :class:`~ngwear.scene.SceneError` naming the
  field and the remedy;

anything else (an exception with a traceback, NaN in a completed step, an invariant broken in a
step reported done) is a ``crashed`` / ``violated`` outcome, i.e. a bug.  Scenes with a known
physical answer also carry a ``check`` (lift-off → no pressure and no wear, …).

``python -m ngwear.studies.stress [--quick] [--out docs/stress_report.md] [--only NAME ...]`` runs the
matrix and writes the Markdown report.
"""
from __future__ import annotations

import argparse
import logging
import math
import sys
import time
import tomllib
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..model.examples import FOLDER as GEOMETRIES
from ..model.scene import Scene, SceneError, load_scene

REPORT = Path("docs") / "stress_report.md"
SCENES = Path(__file__).with_name("stress_scenes.toml")

#: every invariant violation below is dimensionless; an invariant is held when it is ≤ TOL
TOL = 1e-8

#: the base scenes: the paper strip kept small, and the 3D box as shipped
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
    :data:`CHECKS` that the run must pass.  ``bug`` describes a known ngwear bug the scene
    exposes: ``expect`` is then the *correct* outcome, which the scene does not reach yet.
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


# ------------------------------------------------------------------------------- invariants


def k_alpha_slope(scene: Scene, alpha: float | None = None) -> float:
    """k·α·L_p, L_p the largest slope of p on [0, g] (as explicit_stability).

    ``alpha``: the largest α = κ‖v*‖ over the contact points (``Discretization.largest_alpha``); without
    it, that of the foundation's translation (a scene that was never discretized).
    """
    from ..numerics.wear import largest_slope
    c = scene.contact
    if alpha is None:
        speeds = [abs(f) for _, f in scene.foundation.speed_table] or [1.0]
        alpha = c.wear * float(np.linalg.norm(scene.foundation.velocity)) * max(speeds)
    return scene.dt * alpha * largest_slope(c)


def wear_bounded_by_gap(scene: Scene, alpha: float | None = None) -> bool:
    """Whether the integrator guarantees w ≤ max_t (u_ν − d₀)₊ ≤ g (monotone update).

    Implicit: always; explicit: k α L_p ≤ 1; trapezoidal: k α L_p ≤ 2 (w_j ≤ max(a_j, z_j) and
    a_j ≤ max(w_{j−1}, z_{j−1}) then).  Beyond that the update overshoots and w may exceed g.
    """
    limit = {"implicit": math.inf, "explicit": 1.0, "trapezoidal": 2.0}[scene.wear.integrator]
    return k_alpha_slope(scene, alpha) <= limit


def invariants(result) -> dict[str, float]:
    """Dimensionless violations of the invariants over the completed steps (≤ TOL means held).

    * ``gap``: (u_ν − d₀ − g)₊ / max(1, g);
    * ``wear_sign``: (−w)₊ / max(1, g);   ``wear_monotone``: (w_j − w_{j+1})₊ / max(1, g);
    * ``reaction_sign``: (−λ)₊ / P;   ``complementarity``: |λ (u_ν − d₀ − g)| / (P max(1, g));
      P = max(1, |λ|, p) is the traction scale;
    * ``pressure_law``: |p − p(u_ν − d₀ − w)| / max(1, p);
    * ``archard``: the nodal wear update of the scene's integrator,
      |w_{j+1} − w_j − k (θ_old α_j p_j + θ_new α_{j+1} p_{j+1})| / max(1, g);
    * ``wear_le_g``: (w − g)₊ / max(1, g), only where :func:`wear_bounded_by_gap` guarantees it;
    * ``finite``: 0, or inf when any recorded value is NaN or infinite.
    """
    from ..model.laws import compliance_from
    from ..numerics.wear import INTEGRATORS

    sc = result.scene
    g = sc.contact.gap
    arrays = (result.wear, result.normal_displacement, result.pressure, result.reaction)
    if len(result.times) == 0:
        return {"finite": 0.0}
    if not all(np.isfinite(a).all() for a in arrays):
        return {"finite": math.inf}
    w, s, p, lam = arrays
    z = s - result.d0[None, :]
    gs = max(1.0, g)
    P = max(1.0, float(np.abs(lam).max()), float(p.max()))
    law = compliance_from(sc.contact)
    out = {
        "finite": 0.0,
        "gap": float(np.maximum(z - g, 0).max()) / gs,
        "wear_sign": float(np.maximum(-w, 0).max()) / gs,
        "wear_monotone": float(np.maximum(-np.diff(w, axis=0), 0).max(initial=0.0)) / gs,
        "reaction_sign": float(np.maximum(-lam, 0).max()) / P,
        "complementarity": float(np.abs(lam * (z - g)).max()) / (P * gs),
        "pressure_law": _pressure_law_violation(law, s, result.d0[None, :], w, p),
    }
    disc = result.discretization
    if wear_bounded_by_gap(sc, disc.largest_alpha() if disc is not None else None):
        out["wear_le_g"] = float(np.maximum(w - g, 0).max()) / gs
    if disc is not None and len(result.times) > 1:
        th_old, th_new = INTEGRATORS[sc.wear.integrator]
        alpha = np.array([disc.alpha(t) for t in result.times])
        rate = alpha * p
        update = np.diff(result.times)[:, None] * (th_old * rate[:-1] + th_new * rate[1:])
        out["archard"] = float(np.abs(np.diff(w, axis=0) - update).max()) / gs
    return out


def _pressure_law_violation(law, s, d0, w, p) -> float:
    """|p − p(s − d₀ − w)| / max(1, p) beyond the round-off of evaluating the argument.

    s − d₀ − w can only be formed to ≈ eps (|s| + |d₀| + |w|), which p amplifies by its slope; a
    stiff law (L = 1e12) turns that into a visible but legitimate difference.
    """
    r = s - d0 - w
    slack = 8 * np.finfo(float).eps * (np.abs(s) + np.abs(d0) + np.abs(w))
    allowance = slack * law.derivative(np.maximum(r, 0) + slack) + 8 * np.finfo(float).eps * np.abs(p)
    excess = np.maximum(np.abs(p - law(r)) - allowance, 0)
    return float(excess.max() / max(1.0, float(p.max())))


def worst(violations: dict[str, float]) -> tuple[str, float]:
    name = max(violations, key=violations.get)
    return name, violations[name]


def smallness_ratio(result) -> float | None:
    """c₀² L_p μ / m_F of the paper's (H_S) on the run's mesh (> 1: past the bound), if available."""
    if result is None or result.discretization is None or result.scene.contact.friction == 0:
        return None
    try:
        from .theory import smallness
        check = smallness(result.discretization)
        return check.product / check.monotonicity
    except Exception:  # noqa: BLE001 — informative only; theory.py is optional here
        return None


# ------------------------------------------------------------------------------- physics checks
# Each check takes (row, result) and returns a list of failure texts (empty: passed).


def _has_warning(row, word):
    return [] if any(word in w and "time.steps" in w for w in row["warnings"]) else [
        f"expected a '{word}' warning from explicit_stability, got {row['warnings']}"]


def _check_liftoff(row, r):
    fails = []
    if r.pressure.max() != 0 or r.reaction.max() != 0:
        fails.append(f"pressure {r.pressure.max():.3g} / reaction {r.reaction.max():.3g} should be 0")
    if r.wear.max() != 0:
        fails.append(f"wear {r.wear.max():.3g} should be 0")
    z = r.normal_displacement - r.d0
    if z.max() > 1e-12 or not (z.min() < 0):
        fails.append(f"Γ_C should move away from the foundation (u_ν − d₀ in [{z.min():.3g}, {z.max():.3g}])")
    return fails


def _check_load_reversal(row, r):
    after = r.times >= 0.6 - 1e-12
    fails = []
    if not (r.pressure[~after].max() > 0):
        fails.append("pressure before the reversal should be positive")
    if r.pressure[after].max() != 0 or r.reaction[after].max() != 0:
        fails.append(f"pressure after the reversal {r.pressure[after].max():.3g} should be 0")
    first = int(np.argmax(after))
    if np.ptp(r.wear[first + 1:], axis=0).max(initial=0) > 0:
        fails.append("wear should be frozen one step after the lift-off")
    return fails


def _tangential_force(r):
    nu = np.array(r.scene.contact.direction)
    v = np.array(r.scene.foundation.velocity)
    tangent = v - (v @ nu) * nu
    tangent /= np.linalg.norm(tangent)
    return r.forces.sum(axis=1) @ tangent  # force on the foundation along +v*, per step


def _check_friction_flips(row, r):
    f = _tangential_force(r)
    before, after = r.times <= 0.4 + 1e-12, r.times >= 0.6 - 1e-12
    fails = []
    if not (f[before] < 0).all():
        fails.append(f"friction force along v* before the reversal should be < 0 "
                     f"(got max {f[before].max():.3g})")
    if not (f[after] > 0).all():
        fails.append(f"friction force along v* after the reversal should be > 0 "
                     f"(got min {f[after].min():.3g})")
    return fails


def _check_speed_stop(row, r):
    stopped = r.times >= 0.5 + 1e-12
    fails = []
    if np.abs(_tangential_force(r)[stopped]).max() > 0:
        fails.append("no friction force once v* = 0")
    j = int(np.argmax(stopped))
    if np.ptp(r.wear[j:], axis=0).max() > 0:
        fails.append("wear should be frozen once v* = 0")
    return fails


def _check_signorini(row, r):
    sc = r.scene
    z = r.normal_displacement - r.d0
    fails = []
    if z.max() > sc.contact.gap * (1 + TOL):
        fails.append(f"u_ν − d₀ = {z.max():.3g} > g")
    compression = (z - r.wear).max()
    if compression > 1e-6:
        fails.append(f"compression u_ν − d₀ − w = {compression:.3g} should be ≈ p/L ≈ 0")
    if r.pressure.max() <= 0:
        fails.append("the body should press on the layer")
    return fails


def _check_rigid_contact(row, r):
    return [] if r.reaction.max() > 0 else ["the body should reach the rigid foundation (λ > 0 somewhere)"]


def _check_no_rigid_contact(row, r):
    return [] if r.reaction.max() == 0 else [f"λ = {r.reaction.max():.3g} should be 0 (g = 1 is not reached)"]


def _check_plate_balance(row, r):
    """A body held by its plate alone: the contact carries the plate force (and the body force) at every step."""
    from ..model.laws import piecewise_linear
    nu = np.asarray(r.scene.contact.direction)
    loads = r.scene.loads
    pushed = float(np.dot(loads.plate.force, nu))
    if loads.body_force is not None:
        import ngsolve as ngs
        pushed += float(np.dot(loads.body_force, nu)) * ngs.Integrate(ngs.CF(1.0), r.discretization.mesh)
    carried = pushed * np.array([piecewise_linear(loads.time_table, t) for t in r.times])
    off = np.abs(r.normal_force - carried).max() / max(abs(pushed), 1e-300)
    return [] if off <= 1e-9 else [f"the contact carries the plate force only to {off:.2e}"]


def _check_wear_overshoots(row, r):
    g = r.scene.contact.gap
    return [] if r.wear.max() > g * (1 + 1e-6) else [
        f"expected the non-monotone update to overshoot w > g (max w = {r.wear.max():.4g}, g = {g})"]


def _check_rejected(row, r):
    msg = row["message"]
    if msg.startswith("solver.method:") and "'condensed'" in msg:
        return []
    return [f"the rejection should name solver.method and the remedy 'condensed': {msg}"]


CHECKS: dict[str, Callable] = {
    "liftoff": _check_liftoff,
    "load_reversal": _check_load_reversal,
    "friction_flips": _check_friction_flips,
    "speed_stop": _check_speed_stop,
    "signorini": _check_signorini,
    "rigid_contact": _check_rigid_contact,
    "no_rigid_contact": _check_no_rigid_contact,
    "wear_overshoots": _check_wear_overshoots,
    "plate_balance": _check_plate_balance,
    "no_warning": lambda row, r: [f"unexpected warning: {w}" for w in row["warnings"]],
    "oscillation_warning": lambda row, r: _has_warning(row, "oscillates"),
    "divergence_warning": lambda row, r: _has_warning(row, "diverges"),
    "rejected_names_solver": _check_rejected,
}
#: checks that need only the row (warnings, message): run for stopped and rejected scenes too
ROW_CHECKS = {"no_warning", "oscillation_warning", "divergence_warning", "rejected_names_solver"}


# ------------------------------------------------------------------------------- running


def clear_stop_message(status: str) -> list[str]:
    """What a stop message lacks: it must name the step (and time) and suggest a remedy."""
    missing = []
    if not status.startswith("step ") or "(t = " not in status:
        missing.append("the step and time")
    if not any(word in status for word in ("try ", "use ", "set ", "increase ", "reduce ")):
        missing.append("a remedy")
    return missing


class _LogCapture(logging.Handler):
    def __init__(self):
        super().__init__(logging.INFO)
        self.records: list[logging.LogRecord] = []

    def emit(self, record):
        self.records.append(record)


def run_scene(spec: StressScene, *, keep_result: bool = False) -> dict[str, Any]:
    """Run one scene and classify it; returns the report row (with ``result`` if asked)."""
    from ..runs.simulate import simulate

    row: dict[str, Any] = {
        "name": spec.name, "group": spec.group, "params": _params(spec.overrides, spec.base),
        "expect": spec.expect, "reason": spec.reason, "checks": spec.checks, "bug": spec.bug,
        "outcome": None, "message": "", "steps": 0, "of": None, "newton_total": 0, "newton_max": 0,
        "cutbacks": 0, "max_wear": math.nan, "max_penetration": math.nan, "gap": math.nan, "kaL": math.nan,
        "hs_ratio": None, "worst": ("", math.nan), "violations": {}, "warnings": [], "check_failures": [],
        "contact_points": 0, "wall_time": 0.0}
    capture = _LogCapture()
    logger = logging.getLogger("ngwear")
    old_level, old_propagate = logger.level, logger.propagate
    logger.addHandler(capture)
    logger.setLevel(logging.INFO)
    logger.propagate = False  # the row records the messages; keep the console quiet
    result, caught = None, []
    start = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            scene = spec.scene()
            row["of"], row["gap"], row["kaL"] = scene.time.steps, scene.contact.gap, k_alpha_slope(scene)
            result = simulate(scene, progress=False)
            row["kaL"] = k_alpha_slope(scene, result.discretization.largest_alpha())
    except SceneError as err:
        row["outcome"], row["message"] = "rejected", str(err)
    except Exception as err:  # noqa: BLE001 — a crash is exactly what the matrix looks for
        row["outcome"] = "crashed"
        row["message"] = f"{type(err).__name__}: {err}"
        row["traceback"] = traceback.format_exc()
    finally:
        row["wall_time"] = time.perf_counter() - start
        logger.removeHandler(capture)
        logger.setLevel(old_level)
        logger.propagate = old_propagate
    row["warnings"] = list(dict.fromkeys(
        (list(result.warnings) if result is not None else [])
        + [f"{w.category.__name__}: {w.message}" for w in caught or []]))
    row["cutbacks"] = sum("cutting the step" in r.getMessage() for r in capture.records)
    if result is not None:
        _classify(row, result)
    complete = result is not None and result.completed
    for name in spec.checks:
        if complete or name in ROW_CHECKS:
            row["check_failures"] += CHECKS[name](row, result)
    row["hs_ratio"] = smallness_ratio(result)
    if keep_result:
        row["result"] = result
    return row


def _classify(row: dict[str, Any], result) -> None:
    row["steps"] = result.steps
    row["contact_points"] = len(result.weights)
    its = [rec.iterations for rec in result.newton]
    row["newton_total"], row["newton_max"] = int(sum(its)), int(max(its, default=0))
    if len(result.times):
        row["max_wear"] = float(result.wear.max())
        row["max_penetration"] = float((result.normal_displacement - result.d0[None, :]).max())
    row["violations"] = invariants(result)
    row["worst"] = worst(row["violations"])
    held = row["worst"][1] <= TOL
    if result.completed:
        row["outcome"] = "converged" if held else "violated"
        if not held:
            name, value = row["worst"]
            row["message"] = f"invariant {name} violated by {value:.3g} in a completed run"
        return
    row["message"] = result.status
    missing = clear_stop_message(result.status)
    if not held:
        row["outcome"] = "violated"
        row["message"] += f" [kept steps violate {row['worst'][0]} by {row['worst'][1]:.3g}]"
    elif missing:
        row["outcome"] = "unclear stop"
        row["message"] += f" [the message lacks {' and '.join(missing)}]"
    else:
        row["outcome"] = "stopped"


def acceptable(row: dict[str, Any]) -> bool:
    """Outcome (a) converged with the invariants, (b) stopped clearly, or refused up front."""
    return row["outcome"] in ("converged", "stopped", "rejected")


def as_expected(row: dict[str, Any]) -> bool:
    """Acceptable, the pinned outcome if any, and every physics check passed."""
    return acceptable(row) and (row["expect"] is None or row["outcome"] == row["expect"]) \
        and not row["check_failures"]


def catalogue(quick: bool = False, only: list[str] | None = None) -> list[StressScene]:
    """The scenes to run: all, the quick ones, or those named in ``only``."""
    if only:
        unknown = set(only) - {s.name for s in CATALOGUE}
        if unknown:
            raise KeyError(f"unknown stress scene(s): {', '.join(sorted(unknown))}")
        return [s for s in CATALOGUE if s.name in only]
    return [s for s in CATALOGUE if s.quick or not quick]


def run_matrix(quick: bool = False, only: list[str] | None = None, progress: bool = False) -> list[dict]:
    """Run the catalogue (``quick``: the scenes marked quick) and return one row per scene."""
    rows = []
    for spec in catalogue(quick, only):
        row = run_scene(spec)
        if progress:
            print(f"{row['name']:<40} {row['outcome']:<10} {row['wall_time']:6.2f} s", file=sys.stderr)
        rows.append(row)
    return rows


# ------------------------------------------------------------------------------- report


def _params(overrides: dict[str, Any], base: str) -> str:
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


def _num(x: float) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if x == 0:
        return "0"
    return f"{x:.3g}"


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _status(r: dict[str, Any]) -> str:
    """The outcome cell: outcome, the pinned one if different, and a known-bug marker."""
    text = r["outcome"]
    if r["expect"] not in (None, r["outcome"]):
        text += f" (expected {r['expect']})"
    if r["bug"]:
        text += " **known bug**"
    return text


def write_report(rows: list[dict], path=REPORT) -> Path:
    """Write the Markdown report of ``rows`` (from :func:`run_matrix`) to ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    total = sum(r["wall_time"] for r in rows)
    counts: dict[str, int] = {}
    for r in rows:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    bugs = [r for r in rows if r["bug"]]
    bad = [r for r in rows if not as_expected(r) and not r["bug"]]
    lines = [
        "# Stability stress matrix",
        "",
        "Generated by `ngwear/studies/stress.py`; do not edit by hand. Regenerate with",
        "",
        "```bash",
        "python -m ngwear.studies.stress            # every scene → docs/stress_report.md",
        "python -m ngwear.studies.stress --quick    # the scenes marked quick",
        "```",
        "",
        "and test with `pytest -n 2 tests/test_stress.py` (one test per scene).",
        "",
        "Bases: `geometries/paper_strip.toml` at maxh = 0.1 with 20 steps (k·α·L = 0.75, μ = 1, "
        "g = 0.2, L = 10, explicit wear) and `geometries/box3d.toml` as shipped (40 steps); the "
        "parameters column lists the overrides. k·α·L uses the largest slope of p on [0, g] and the "
        "largest foundation speed (as the explicit-stability warning does); *H_S* is "
        "c₀² L_p μ / m_F of the paper's smallness hypothesis on the scene's mesh (> 1: past the bound).",
        "",
        "Outcomes: **converged** = every step done and every invariant held at every step; "
        "**stopped** = the run ended early with a message naming the step, the cause and a remedy, "
        "the kept steps satisfying the invariants; **rejected** = refused up front with a "
        "`SceneError` naming the field. Anything else (crashed, violated, unclear stop) is a bug.",
        "",
        f"Invariants (dimensionless, held when ≤ {TOL:g}): gap (u_ν − d₀ − g)₊/max(1,g); w ≥ 0 and "
        "non-decreasing; λ ≥ 0; complementarity |λ(u_ν − d₀ − g)|; pressure = p(u_ν − d₀ − w); "
        "the nodal Archard update of the integrator; w ≤ g where the integrator is monotone "
        "(implicit; explicit with k·α·L ≤ 1; trapezoidal with k·α·L ≤ 2); no NaN. The *worst* "
        "column is the largest of them.",
        "",
        f"**{len(rows)} scenes**: {', '.join(f'{n} {k}' for k, n in sorted(counts.items()))}; "
        f"{sum(as_expected(r) for r in rows)} as expected, {len(bugs)} known bug(s), "
        f"{len(bad)} unexpected. Total run time {total:.1f} s (sequential, one process, meshing included "
        "where the mesh was not cached yet).",
        "",
        "| scene | parameters | k·α·L | H_S | outcome | last step / N | Newton total / max | cut-backs "
        "| max w (/ g) | max u_ν − d₀ | g | worst invariant | checks | wall [s] |",
        "|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---|---|---:|",
    ]
    for r in rows:
        wname, wval = r["worst"]
        checks = ", ".join(r["checks"])
        if r["check_failures"]:
            checks += " FAILED"
        elif checks:
            checks += " ok"
        g, w = r["gap"], r["max_wear"]
        wear = "–" if math.isnan(w) else _num(w) + ("" if w == 0 else f" ({w / g:.3g} g)")
        last = "none" if r["steps"] < 0 else str(r["steps"])
        lines.append("| " + " | ".join(_cell(c) for c in (
            r["name"], r["params"], _num(r["kaL"]), _num(r["hs_ratio"]), _status(r),
            f"{last} / {r['of'] if r['of'] is not None else '–'}",
            f"{r['newton_total']} / {r['newton_max']}", str(r["cutbacks"]),
            wear, _num(r["max_penetration"]), _num(g),
            f"{wname} {_num(wval)}" if wname else "–", checks, f"{r['wall_time']:.2f}")) + " |")
    if bugs:
        lines += ["", "## Known bugs exposed", ""]
        for r in bugs:
            lines.append(f"* **{r['name']}** ({_status(r)}): {r['bug']}.")
            if r["message"]:
                lines.append(f"  * message: `{r['message']}`")
    if bad:
        lines += ["", "## Not as expected", ""]
        for r in bad:
            lines.append(f"* **{r['name']}**: {r['outcome']} (expected {r['expect']}) {r['message']} "
                         + "; ".join(r["check_failures"]))
            if r.get("traceback"):
                lines += ["", "```", r["traceback"].rstrip(), "```", ""]
    notes = [r for r in rows if r["message"] or r["warnings"] or r["reason"]]
    if notes:
        lines += ["", "## Reasons, messages and warnings", ""]
        for r in notes:
            lines.append(f"* **{r['name']}**" + (f": {r['reason']}" if r["reason"] else ""))
            if r["message"] and not r["bug"]:
                lines.append(f"  * {r['outcome']}: `{r['message']}`")
            for w in r["warnings"]:
                lines.append(f"  * warning: `{w}`")
            for f in r["check_failures"]:
                lines.append(f"  * check failed: {f}")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def main(argv: list[str] | None = None) -> int:
    """``python -m ngwear.studies.stress``: run the matrix and write the report.

    Exit status 1 when a scene is not as expected (other than the known bugs), else 0.
    """
    parser = argparse.ArgumentParser(prog="python -m ngwear.studies.stress", description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="only the scenes marked quick")
    parser.add_argument("--out", default=str(REPORT), help=f"report path (default {REPORT})")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="run these scenes only")
    args = parser.parse_args(argv)
    rows = run_matrix(args.quick, args.only, progress=True)
    path = write_report(rows, args.out)
    bad = [r["name"] for r in rows if not as_expected(r) and not r["bug"]]
    bugs = [r["name"] for r in rows if r["bug"]]
    print(f"written {path}: {len(rows)} scenes, {sum(r['wall_time'] for r in rows):.1f} s"
          + (f"; known bugs: {', '.join(bugs)}" if bugs else "")
          + (f"; NOT as expected: {', '.join(bad)}" if bad else "; the rest as expected"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
