"""The time loop: scheme P^hk of the paper (eqs. 14–15) and its implicit / second-order variants.

For j = 0..N (t_j = j k):  solve the contact problem for u_j with the wear law of step j
(:mod:`ngwear.wear`), then record s_j = ν·u_j, p_j, λ_j, w_j at the contact points and advance the
wear.  Bulk displacement fields are recovered (one back-substitution each) only for the steps
that are written or looked at.
"""
from __future__ import annotations

import logging
import time

import numpy as np

from .discrete import Discretization
from .result import Result
from .scene import Scene
from .solver import CondensedSystem, ConvergenceError, FullSystem, semismooth_newton
from .wear import WearIntegrator, explicit_stability

log = logging.getLogger(__name__)


def simulate(scene: Scene, *, discretization: Discretization | None = None,
             progress: bool = True) -> Result:
    """Run the scene's time loop; a run that fails part-way returns the steps it completed.

    Pass the ``discretization`` of an earlier run to reuse its mesh, factorisation and contact
    compliance wherever the scene change allows (see :meth:`Discretization.with_scene`).
    """
    start = time.perf_counter()
    if discretization is None:
        disc = Discretization(scene)
    else:
        disc = discretization if discretization.scene == scene else discretization.with_scene(scene)
    k, steps = scene.dt, scene.time.steps
    n = disc.points.n
    g, mu = scene.contact.gap, scene.contact.friction
    integrator = WearIntegrator(scene.wear.integrator, disc.law, k, n)
    result = Result.empty(scene, disc)
    warning = explicit_stability(scene)
    if warning:
        log.warning("%s", warning)
        result.warnings.append(warning)
    x = np.zeros(n) if scene.solver.method == "condensed" else np.zeros(int(disc.free.sum()))
    lam = np.zeros(n)
    step_range = range(steps + 1)
    bar = _progress(step_range, scene.name) if progress else step_range
    matrices = {}
    for j in bar:
        t = j * k
        law = integrator.point_law()
        if scene.solver.method == "condensed":
            n_star = disc.n_star(t)
            key = tuple(n_star)
            if key not in matrices:
                H = disc.normal_compliance
                A = H + disc.friction_compliance(n_star) * mu if mu > 0 and n_star.any() else H
                matrices = {key: A}
            system = CondensedSystem(disc.normal_compliance, matrices[key], disc.points.weights,
                                     disc.load_factor(t) * disc.s_load, disc.d0, g, law)
        else:
            system = _full_system(disc, t, integrator)
        try:
            x, lam, record = semismooth_newton(system, x, lam, scene.solver.tolerance,
                                               scene.solver.max_iterations)
        except ConvergenceError as err:
            result.fail(f"step {j} (t = {t:.4g}): {err}", err.record)
            break
        s = x if scene.solver.method == "condensed" else disc.N[:, disc.free] @ x
        z = s - disc.d0
        pressure = law.pressure(z)
        if not (np.all(np.isfinite(s)) and np.all(np.isfinite(lam))):
            result.fail(f"step {j} (t = {t:.4g}): non-finite solution", record)
            break
        w = integrator.wear_at(z)
        result.append(t, w, s, pressure, lam, disc.contact_forces(pressure, lam, t), record)
        integrator.advance(w, pressure, disc.alpha(t), disc.alpha(t + k))
    result.wall_time = time.perf_counter() - start
    if result.status != "completed":
        log.warning("%s: %s", scene.name, result.status)
    return result


def _full_system(disc: Discretization, t: float, integrator: WearIntegrator) -> FullSystem:
    """The reference system: NGSolve form with w, μ, n* of this step."""
    if integrator.c != 0:
        raise NotImplementedError("solver.method = 'full' supports wear.integrator = 'explicit' only")
    cf = disc.full_form
    cf.w.vec.FV().NumPy()[:] = disc.points.Q @ integrator.a
    cf.mu.Set(disc.scene.contact.friction)
    for p, v in zip(cf.n_star, disc.n_star(t)):
        p.Set(float(v))
    return FullSystem(cf, disc.load_factor(t) * disc.load, disc.free, disc.N, disc.points.weights,
                      disc.d0, disc.scene.contact.gap, disc.stiffness.diagonal())


def _progress(iterable, name):
    from tqdm.auto import tqdm
    return tqdm(iterable, desc=name, unit="step", leave=False)
