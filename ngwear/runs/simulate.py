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

from ..model.scene import Scene
from ..numerics.discrete import Discretization
from ..numerics.solver import CondensedSystem, ConvergenceError, FullSystem, KrylovSystem, PlateRows, semismooth_newton
from ..numerics.wear import WearIntegrator, explicit_stability
from ..results.result import Result

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
    integrator = WearIntegrator(scene.wear.integrator, disc.law, k, n)
    result = Result.empty(scene, disc)
    warning = explicit_stability(scene, disc.largest_alpha())
    if warning:
        log.warning("%s", warning)
        result.warnings.append(warning)
    stepper = _Stepper(disc)
    x, lam = stepper.unknowns(), np.zeros(n)
    t_prev = None  # step 0 continues from the unloaded state u = 0
    bar = _progress(range(steps + 1), scene.name) if progress else range(steps + 1)
    for j in bar:
        t = j * k
        law = integrator.point_law()
        try:
            x, lam, record = stepper.solve(t, t_prev, law, x, lam, integrator)
        except ConvergenceError as err:
            result.fail(f"step {j} (t = {t:.4g}): {err}; {_remedy(scene, err.record)}", err.record)
            break
        s, delta = stepper.normal(x), stepper.plate(x)
        pressure = law.pressure(s - disc.d0)
        if not all(np.all(np.isfinite(a)) for a in (s, lam, pressure, delta)):
            result.fail(f"step {j} (t = {t:.4g}): non-finite solution", record)
            break
        w = integrator.wear_at(s - disc.d0)
        result.append(t, w, s, pressure, lam, disc.contact_forces(pressure, lam, t), delta, record)
        integrator.advance(w, pressure, disc.alpha(t), disc.alpha(t + k))
        t_prev = t
    result.wall_time = time.perf_counter() - start
    if result.status != "completed":
        log.warning("%s: %s", scene.name, result.status)
    return result


class _Stepper:
    """Solves one step; on a Newton failure it retries from a load continuation (cut-back).

    The cut-back does not change the scheme: it solves the same step's problem (wear law, v*) at
    the loads s_F = s_prev + θ (s_F(t) − s_prev), θ = 1/m … 1, each warm-starting the next, with
    m = 2, 4, 8; s_prev is the previous step's load factor, or 0 (the unloaded state) at step 0.
    """

    CUTBACKS = (2, 4, 8)

    def __init__(self, disc: Discretization):
        self.disc, self.scene = disc, disc.scene
        self._matrices: dict = {}
        self._factors: dict = {}

    @property
    def _full(self) -> bool:
        return self.scene.solver.method == "full"

    def unknowns(self) -> np.ndarray:
        """The unknowns at rest: s at the contact points (condensed) or the free DOFs (full), then δ."""
        disc = self.disc
        size = disc.full_basis.shape[1] if self._full else disc.points.n + disc.plate_modes_count
        return np.zeros(size)

    def normal(self, x):
        """The normal displacements s = ν·u at the contact points."""
        return self.disc.N @ (self.disc.full_basis @ x) if self._full else x[:self.disc.points.n]

    def plate(self, x):
        """δ, the plate's displacement (and tilts)."""
        return x[len(x) - self.disc.plate_modes_count:]

    def solve(self, t, t_prev, law, x, lam, integrator):
        target = self.disc.load_factor(t)
        try:
            return self._newton(t, target, law, x, lam, integrator)
        except ConvergenceError as first:
            start = 0.0 if t_prev is None else self.disc.load_factor(t_prev)
            if t_prev is None:
                x, lam = np.zeros_like(x), np.zeros_like(lam)
            for m in self.CUTBACKS:
                try:
                    xs, ls = x, lam
                    for theta in np.arange(1, m + 1) / m:
                        xs, ls, record = self._newton(t, start + theta * (target - start), law, xs, ls,
                                                      integrator)
                    log.info("t = %.4g: converged after cutting the load step into %d", t, m)
                    return xs, ls, record
                except ConvergenceError:
                    continue
            raise first

    def _newton(self, t, load_factor, law, x, lam, integrator):
        sc = self.scene.solver
        system = self._system(t, load_factor, law, integrator)
        return semismooth_newton(system, x, lam, sc.tolerance, sc.max_iterations)

    def _system(self, t, load_factor, law, integrator):
        disc = self.disc
        if self._full:
            return _full_system(disc, t, load_factor, integrator)
        n_star, mu = disc.n_star(t), self.scene.contact.friction
        if disc.matrix_free:
            return _krylov_system(disc, n_star, load_factor, law)
        key = n_star.tobytes()
        if key not in self._matrices:
            H = disc.normal_compliance
            A = H + mu * disc.friction_compliance(n_star) if mu > 0 and n_star.any() else H
            coupling = disc.plate
            directed = None if coupling is None else coupling.directed(disc.nu[None, :] + mu * n_star)
            self._matrices = {key: (A, directed)}
            self._factors = {}
        A, directed = self._matrices[key]
        plate = None if directed is None else PlateRows(disc.plate.normal, directed, disc.plate.stiffness,
                                                        load_factor * disc.plate_load)
        return CondensedSystem(disc.normal_compliance, A, disc.points.weights, load_factor * disc.s_load, disc.d0,
                               self.scene.contact.gap, law, self._factors, plate)


def _remedy(scene: Scene, record) -> str:
    """What to try after a Newton failure, from the failure's history."""
    last = record.residuals[-1] if record.residuals else np.inf
    if np.isfinite(last) and last < 1e3 * scene.solver.tolerance:
        return f"the merit stalled at round-off: raise solver.tolerance above {last:.1e}"
    tips = [f"more time.steps (now {scene.time.steps})",
            f"solver.max_iterations > {scene.solver.max_iterations}"]
    if scene.contact.friction > 0:
        tips.append(f"a smaller contact.friction (μ = {scene.contact.friction:g} may exceed the smallness "
                    f"bound (H_S): see `ngwear verify`)")
    return "try " + ", ".join(tips)


def _krylov_system(disc: Discretization, n_star, load_factor: float, law) -> KrylovSystem:
    """The condensed system applied matrix-free (large contact surfaces, see :class:`Discretization`)."""
    directions = disc.nu[None, :] + disc.scene.contact.friction * n_star
    plate = None if disc.plate is None else PlateRows(disc.plate.normal, disc.plate.directed(directions),
                                                      disc.plate.stiffness, load_factor * disc.plate_load)
    respond = lambda directed, normal: disc.normal_response(normal, directed, directions)  # noqa: E731
    return KrylovSystem(respond, disc.compliance_estimate, disc.points.weights, load_factor * disc.s_load, disc.d0,
                        disc.scene.contact.gap, law, disc.scene.solver.tolerance, plate)


def _full_system(disc: Discretization, t: float, load_factor: float, integrator: WearIntegrator) -> FullSystem:
    """The reference system: NGSolve form with w, μ, n* of this step (explicit wear: w = a, see the scene's rules)."""
    cf = disc.full_form
    disc.set_nodal(cf.w, integrator.a)
    cf.mu.Set(disc.scene.contact.friction)
    for gf, component in zip(cf.n_star, disc.n_star(t).T):
        disc.set_nodal(gf, component)
    load = disc.full_basis.T @ disc.load
    load[len(load) - disc.plate_modes_count:] += disc.plate_force
    floating = disc.plate_modes_count and not disc.scene.geometry.dirichlet
    return FullSystem(cf, disc.full_basis, load_factor * load, disc.N, disc.points.weights, disc.d0,
                      disc.scene.contact.gap, disc.stiffness, integrator.point_law(), disc.plate_modes_count,
                      disc.rigid_translation if floating else None)


def _progress(iterable, name):
    from tqdm.auto import tqdm
    return tqdm(iterable, desc=name, unit="step", leave=False)
