"""Physics checks of the stress matrix's scenes with a known answer (lift-off → no pressure and no wear, …).

Each check takes the scene's row (:class:`~ngwear.studies.stress.StressRow`) and its result and returns
the texts of what failed (empty: passed).  The checks of :data:`ROW_CHECKS` need only the row (its
warnings and message) and also run for stopped and rejected scenes.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from ..model.keys import piecewise_linear
from ..runs.checks import TOL
from ..runs.validity import WORN


def _has_warning(row, word):
    return [] if any(word in w and "time.steps" in w for w in row.warnings) else [
        f"expected a '{word}' warning from explicit_stability, got {row.warnings}"]


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
    nu = np.asarray(r.scene.contact.direction)
    loads = r.scene.loads
    pushed = float(np.dot(loads.plate.force, nu))
    if loads.body_force is not None:
        import ngsolve as ngs
        pushed += float(np.dot(loads.body_force, nu)) * ngs.Integrate(ngs.CF(1.0), r.discretization.mesh)
    carried = pushed * np.array([piecewise_linear(loads.time_table, t) for t in r.times])
    off = np.abs(r.normal_force - carried).max() / max(abs(pushed), np.finfo(float).tiny)
    return [] if off <= 1e-9 else [f"the contact carries the plate force only to {off:.2e}"]


def _check_wear_overshoots(row, r):
    g = r.scene.contact.gap
    return [] if r.wear.max() > g * (1 + 1e-6) else [
        f"expected the non-monotone update to overshoot w > g (max w = {r.wear.max():.4g}, g = {g})"]


def _check_zero_where(name: str, field: str):
    """Points whose coefficient ``name`` (μ_i, κ_i) is 0 carry no friction force / no wear; the others do."""
    def check(row, r):
        zero = getattr(r, name) == 0
        if not zero.any() or zero.all():
            return [f"{name} should be 0 on a part of Γ_C only (0 at {zero.sum()} of {zero.size} points)"]
        nu = np.asarray(r.scene.contact.direction)
        value = {"wear": lambda: r.wear,
                 "friction": lambda: np.linalg.norm(r.forces - (r.forces @ nu)[..., None] * nu, axis=2)}[field]()
        fails = [] if value[:, zero].max() == 0 else [f"{field} {value[:, zero].max():.3g} where {name} = 0"]
        return fails + ([] if value[:, ~zero].max() > 0 else [f"no {field} where {name} > 0"])
    return check


def _check_rejected_names(field: str, remedy: str):
    def check(row, r):
        msg = row.message
        if msg.startswith(f"{field}:") and remedy in msg and len(msg.splitlines()) == 1:
            return []
        return [f"the rejection should be one line naming {field} and the remedy {remedy}: {msg}"]
    return check


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
    "cut_back": lambda row, r: [] if row.cutbacks > 0 else ["expected a load continuation (cut-back)"],
    # of the scheme: a layer worn through is the scene's physics (ngwear.runs.validity), said where it happens
    "no_warning": lambda row, r: [f"unexpected warning: {w}" for w in row.warnings if not w.startswith(WORN)],
    "oscillation_warning": lambda row, r: _has_warning(row, "oscillates"),
    "divergence_warning": lambda row, r: _has_warning(row, "diverges"),
    "rejected_names_solver": _check_rejected_names("solver.method", "'condensed'"),
    "rejected_names_steps": _check_rejected_names("time.steps", "wear.allow_unstable"),
    "rejected_names_friction": _check_rejected_names("contact.friction", ">= 0 at every contact point"),
    "no_friction_where_mu_zero": _check_zero_where("friction_coefficient", "friction"),
    "no_wear_where_kappa_zero": _check_zero_where("wear_coefficient", "wear"),
}
#: checks that need only the row (warnings, message): run for stopped and rejected scenes too
ROW_CHECKS = {"no_warning", "oscillation_warning", "divergence_warning", "rejected_names_solver",
              "rejected_names_steps", "rejected_names_friction"}
