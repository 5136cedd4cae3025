"""Convergence studies against a fine reference computed by the tool (paper Theorems 4–5).

Errors are measured in the paper's norms: the V-norm ‖v‖_V = ‖ε(v)‖_{L²(Ω)} of the displacement
and the L²(Γ_C) norm of the wear, both

* summed in time as in Theorem 4:  E = ( k Σ_{j=1..N} ‖u_j − u_j^{ref}‖_V² + ‖w_j − w_j^{ref}‖_W² )^{1/2},
* and at the final time.

Theorem 5 predicts E² ≲ k² + k h² + h for P1 (so E = O(h^{1/2} + k)); observed orders are the
least-squares slopes of log E against log h (or log k).  Coarse displacements are interpolated
onto the reference mesh (NGSolve ``Set``), wear profiles onto the reference contact points.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import ngsolve as ngs
import numpy as np

from ..model.scene import Scene
from ..numerics.discrete import Discretization
from ..results.result import Result
from ..runs.simulate import simulate


@dataclass(frozen=True)
class Errors:
    """Errors of one run against the reference (see the module docstring)."""

    V_sum: float
    W_sum: float
    V_final: float
    W_final: float


def _run(scene: Scene) -> tuple[Result, float]:
    start = time.perf_counter()
    result = simulate(scene, progress=False)
    if not result.completed:
        raise RuntimeError(f"{scene.name}: {result.status}")
    return result, time.perf_counter() - start


def _wear_on(result: Result, ref: Result, step: int) -> np.ndarray:
    """Wear of ``result`` at ``step`` at the reference contact points.

    Linear interpolation along Γ_C in 2D; in 3D the scalar finite element function with the wear's
    nodal values (:attr:`ContactPoints.Q`).
    """
    if result.contact_points.shape == ref.contact_points.shape and np.allclose(
            result.contact_points, ref.contact_points):
        return result.wear[step]
    nu = np.array(result.scene.contact.direction)
    if result.scene.dim == 3:
        disc = result.discretization
        wear = ngs.GridFunction(ngs.H1(disc.mesh, order=result.scene.mesh.order, definedon="body"))
        disc.set_nodal(wear, result.wear[step])
        return np.asarray(wear(disc.locate(ref.contact_points))).ravel()
    tangent = np.array([-nu[1], nu[0]])
    x, xr = result.contact_points @ tangent, ref.contact_points @ tangent
    order = np.argsort(x)
    return np.interp(xr, x[order], result.wear[step][order])


def errors(result: Result, ref: Result) -> Errors:
    """Errors of ``result`` against ``ref`` at the run's times t_j, the steps k_j = t_j − t_{j−1} as weights.

    The reference is taken at t_j itself when it has that time (a uniform run against a reference
    whose steps divide it), else linearly interpolated between its two steps around t_j (an adaptive
    run); the sums are Σ_j k_j ‖·‖² (Theorem 4's k Σ for uniform steps).
    """
    if not np.isclose(ref.times[-1], result.times[-1]):
        raise ValueError("verify: the reference must end at the run's final time")
    rdisc: Discretization = ref.discretization
    coarse, reference = ngs.GridFunction(rdisc.fes), ngs.GridFunction(rdisc.fes)
    e_V, e_W = [], []
    for j in range(1, result.steps + 1):
        (i, a), (i1, b) = _bracket(ref.times, result.times[j])
        coarse.Set(result.discretization.gridfunction(result.displacement(j)))
        reference.vec.FV().NumPy()[:] = a * ref.displacement(i) + (b * ref.displacement(i1) if b else 0.0)
        diff = ngs.Sym(ngs.Grad(coarse)) - ngs.Sym(ngs.Grad(reference))
        e_V.append(ngs.Integrate(ngs.InnerProduct(diff, diff), rdisc.mesh, definedon=rdisc.mesh.Materials("body")))
        dw = _wear_on(result, ref, j) - (a * ref.wear[i] + b * ref.wear[i1])
        e_W.append(dw @ (ref.weights * dw))
    k = np.diff(result.times)
    return Errors(float(np.sqrt(k @ e_V)), float(np.sqrt(k @ e_W)), float(np.sqrt(e_V[-1])), float(np.sqrt(e_W[-1])))


def _bracket(times: np.ndarray, t: float) -> tuple[tuple[int, float], tuple[int, float]]:
    """((i, a), (i + 1, b)) with a t_i + b t_{i+1} = t, a + b = 1; b = 0 when t is a step time."""
    i = int(np.searchsorted(times, t, side="right")) - 1
    if np.isclose(times[i], t, rtol=1e-12, atol=1e-14 * times[-1]) or i == len(times) - 1:
        return (i, 1.0), (i, 0.0)
    b = (t - times[i]) / (times[i + 1] - times[i])
    return (i, 1.0 - b), (i + 1, b)


def observed_order(sizes, errs) -> float:
    """Least-squares slope of log(err) against log(size)."""
    return float(np.polyfit(np.log(sizes), np.log(errs), 1)[0])


def h_study(scene: Scene, maxhs, ref_maxh: float) -> list[dict]:
    """Errors of the scene at mesh sizes ``maxhs`` against a run at ``ref_maxh`` (same time grid)."""
    ref, _ = _run(scene.replace(**{"mesh.maxh": ref_maxh}))
    rows = []
    for h in maxhs:
        result, seconds = _run(scene.replace(**{"mesh.maxh": h}))
        e = errors(result, ref)
        rows.append({"h": h, "dofs": int(result.discretization.body.free.sum()), "seconds": seconds, **e.__dict__})
    return rows


def k_study(scene: Scene, steps, ref_steps: int) -> list[dict]:
    """Errors of the scene with ``steps`` time steps against ``ref_steps`` steps (same mesh)."""
    ref, _ = _run(scene.replace(**{"time.steps": ref_steps, "output.every": scene.time.T}))
    rows = []
    for n in steps:
        result, seconds = _run(scene.replace(**{"time.steps": n, "output.every": scene.time.T}))
        rows.append({"k": scene.time.T / n, "steps": n, "seconds": seconds, **errors(result, ref).__dict__})
    return rows


def orders(rows: list[dict], size: str) -> dict[str, float]:
    """Observed orders of each error column of a study."""
    sizes = [r[size] for r in rows]
    return {name: observed_order(sizes, [r[name] for r in rows]) for name in Errors.__dataclass_fields__}


def table(rows: list[dict], first: str | None = None) -> str:
    """A Markdown table of study rows (column ``first`` leftmost)."""
    cols = ([first] if first else []) + [c for c in rows[0] if c != first]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        lines.append("| " + " | ".join(f"{r[c]:.4g}" if isinstance(r[c], float) else str(r[c]) for c in cols) + " |")
    return "\n".join(lines)


def markdown(rows: list[dict], size: str) -> str:
    """A Markdown table of a study with the observed orders in the last row."""
    cols = [size] + [c for c in rows[0] if c != size]
    lines = table(rows, size).splitlines()
    rates = orders(rows, size)
    lines.append("| order | " + " | ".join(f"{rates[c]:.2f}" if c in rates else "" for c in cols[1:]) + " |")
    return "\n".join(lines)


def overshoot(result: Result) -> float:
    """max_j,i (w − (u_ν − d₀))₊ / g: wear beyond the body's surface, impossible for the exact solution.

    The exact wear never passes the surface (p = 0 there), the explicit update does once
    k α L > 1 (amplification 1 − k α L < 0), the trapezoidal one once k α L > 2.
    """
    beyond = result.wear - (result.normal_displacement - result.d0[None, :])
    return float(np.maximum(beyond, 0).max(initial=0.0) / result.scene.contact.gap)


def stability_study(scene: Scene, steps, ref_steps: int = 640) -> list[dict]:
    """Final-time wear error and overshoot of each integrator at k α L = T α L / steps."""
    contact = scene.contact
    alpha_l = contact.wear * float(np.linalg.norm(scene.foundation.velocity)) * contact.stiffness
    ref, _ = _run(scene.replace(**{"time.steps": ref_steps, "wear.integrator": "trapezoidal",
                                   "output.every": scene.time.T}))
    rows = []
    for n in steps:
        row = {"steps": n, "k_alpha_L": scene.time.T * alpha_l / n}
        for integrator in ("explicit", "implicit", "trapezoidal"):
            result, _ = _run(scene.replace(**{"time.steps": n, "wear.integrator": integrator,
                                              "output.every": scene.time.T}))
            dw = result.wear[-1] - ref.wear[-1]
            row[f"{integrator}_W_final"] = float(np.sqrt(dw @ (ref.weights * dw)))
            row[f"{integrator}_overshoot"] = overshoot(result)
        rows.append(row)
    return rows
