"""Convergence studies against a fine reference computed by the tool (paper Theorems 4–5), and the stability study.

Errors are measured in the paper's norms: the V-norm ‖v‖_V = ‖ε(v)‖_{L²(Ω)} of the displacement
and the L²(Γ_C) norm of the wear, both

* summed in time as in Theorem 4:  E = ( k Σ_{j=1..N} ‖u_j − u_j^{ref}‖_V² + ‖w_j − w_j^{ref}‖_W² )^{1/2},
* and at the final time.

Theorem 5 predicts E² ≲ k² + k h² + h for P1 (so E = O(h^{1/2} + k)); observed orders are the
least-squares slopes of log E against log h (or log k).  On another mesh than the reference's, ε(u) is
evaluated at the reference's quadrature points and the wear, as the finite element function on Γ_C it is,
at the reference's contact points (:mod:`ngwear.numerics.transfer`: robust where curved faces put points
of one mesh outside the other).  The h-study refines every size of the scene (``mesh.maxh`` and
``mesh.contact_maxh``) by the same factor and checks that the meshes do get finer.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from ..model.scene import Scene, SceneError
from ..numerics.discrete import Discretization
from ..numerics.transfer import ContactTrace, Locator, StrainQuadrature
from ..results.result import Result
from ..runs.checks import overshoot
from ..runs.simulate import simulate

SIZES = ("mesh.maxh", "mesh.contact_maxh")
"""The scene keys that set a mesh size: the h-study scales each one that is set."""


@dataclass(frozen=True)
class Errors:
    """Errors of one run against the reference (see the module docstring)."""

    V_sum: float
    W_sum: float
    V_final: float
    W_final: float


class StoppedRun(RuntimeError):
    """A run of a study did not complete (its status says why)."""


def _run(scene: Scene, like: Result | None = None) -> tuple[Result, float]:
    """The completed run of ``scene`` and its seconds; ``like``: a run on the same mesh whose factorisation it reuses."""
    start = time.perf_counter()
    result = simulate(scene, discretization=None if like is None else like.discretization, progress=False)
    if not result.completed:
        raise StoppedRun(f"{scene.name}: {result.status}")
    return result, time.perf_counter() - start


def refined(scene: Scene, factor: float) -> Scene:
    """The scene with every mesh size (:data:`SIZES`, where set) multiplied by ``factor``."""
    if scene.mesh.maxh is None:
        raise SceneError("mesh.maxh: a mesh file (geometry.kind = 'mesh') has one resolution; no h-study")
    sizes = {"mesh.maxh": scene.mesh.maxh, "mesh.contact_maxh": scene.mesh.contact_maxh}
    return scene.replace(**{key: value * factor for key, value in sizes.items() if value is not None})


class Reference:
    """A reference run with what comparing other runs against it needs (quadrature, Γ_C of each mesh)."""

    def __init__(self, result: Result):
        self.result, disc = result, result.discretization
        order, dim = result.scene.mesh.order, result.scene.dim     # |ε|² exactly, points inside the elements:
        self.quadrature = StrainQuadrature(disc.fes, 3 if (order, dim) == (1, 2) else 2 * order)
        self._meshes: dict[int, tuple] = {}

    def _on(self, disc: Discretization):
        """(mesh points of the quadrature on ``disc``'s mesh, ``disc``'s Γ_C trace), once per mesh."""
        key = id(disc.mesh)
        if key not in self._meshes:
            locator = Locator(disc.mesh)
            self._meshes = {key: (disc.mesh, self.quadrature.on(disc.mesh),
                                  ContactTrace(disc.mesh, disc.points, disc.scene.mesh.order, locator.reach))}
        return self._meshes[key][1:]

    def errors(self, result: Result) -> Errors:
        """Errors of ``result`` at its times t_j, the steps k_j = t_j − t_{j−1} as weights.

        The reference is taken at t_j itself when it has that time (a uniform run against a reference
        whose steps divide it), else linearly interpolated between its two steps around t_j (an adaptive
        run); the sums are Σ_j k_j ‖·‖² (Theorem 4's k Σ for uniform steps).
        """
        ref = self.result
        if not np.isclose(ref.times[-1], result.times[-1]):
            raise ValueError("verify: the reference must end at the run's final time")
        disc = result.discretization
        at, trace = self._on(disc)
        same = result.contact_points.shape == ref.contact_points.shape and np.allclose(result.contact_points,
                                                                                        ref.contact_points)
        e_V, e_W = [], []
        for j in range(1, result.steps + 1):
            (i, a), (i1, b) = _bracket(ref.times, result.times[j])
            u_ref = a * ref.displacement(i) + (b * ref.displacement(i1) if b else 0.0)
            e_V.append(self.quadrature.error2(disc.gridfunction(result.displacement(j)), at, u_ref))
            wear = result.wear[j] if same else trace(result.wear[j], ref.contact_points)
            dw = wear - (a * ref.wear[i] + b * ref.wear[i1])
            e_W.append(dw @ (ref.weights * dw))
        k = np.diff(result.times)
        return Errors(float(np.sqrt(k @ e_V)), float(np.sqrt(k @ e_W)), float(np.sqrt(e_V[-1])),
                      float(np.sqrt(e_W[-1])))


def errors(result: Result, ref: Result) -> Errors:
    """Errors of ``result`` against the reference run ``ref`` (see :meth:`Reference.errors`)."""
    return Reference(ref).errors(result)


def _bracket(times: np.ndarray, t: float) -> tuple[tuple[int, float], tuple[int, float]]:
    """((i, a), (i + 1, b)) with a t_i + b t_{i+1} = t, a + b = 1; b = 0 when t is a step time."""
    i = int(np.searchsorted(times, t, side="right")) - 1
    if np.isclose(times[i], t, rtol=1e-12, atol=1e-14 * times[-1]) or i == len(times) - 1:
        return (i, 1.0), (i, 0.0)
    b = (t - times[i]) / (times[i + 1] - times[i])
    return (i, 1.0 - b), (i + 1, b)


def observed_order(sizes, errs) -> float:
    """Least-squares slope of log(err) against log(size); NaN when an error vanishes (nothing to converge)."""
    errs = np.asarray(errs, dtype=float)
    if not (errs > 0).all():
        return float("nan")
    return float(np.polyfit(np.log(sizes), np.log(errs), 1)[0])


def h_study(scene: Scene, maxhs, ref_maxh: float) -> list[dict]:
    """Errors at mesh sizes ``maxhs`` against a run at ``ref_maxh`` (same time grid).

    Each size is a ``mesh.maxh``; the scene's other sizes (``mesh.contact_maxh``) scale with it.  Raises
    SceneError when refining does not refine (the DOFs must grow from each mesh to the next and the reference).
    """
    h0 = scene.mesh.maxh
    if h0 is None:
        refined(scene, 1.0)
    order = sorted(maxhs, reverse=True)
    reference = Reference(_run(refined(scene, ref_maxh / h0))[0])
    rows = []
    for h in order:
        result, seconds = _run(refined(scene, h / h0))
        rows.append({"h": h, "dofs": int(result.discretization.body.free.sum()), "seconds": seconds,
                     **reference.errors(result).__dict__})
    dofs = [r["dofs"] for r in rows] + [int(reference.result.discretization.body.free.sum())]
    if any(b <= a for a, b in zip(dofs, dofs[1:])):
        raise SceneError(f"mesh.maxh: refining {', '.join(f'{h:g}' for h in order)} → {ref_maxh:g} gives "
                         f"{dofs} free DOFs: the meshes do not get finer")
    return rows


def k_study(scene: Scene, steps, ref_steps: int) -> list[dict]:
    """Errors of the scene with ``steps`` time steps against ``ref_steps`` steps (same mesh, factorised once)."""
    final = {"output.every": scene.time.T}
    reference = Reference(_run(scene.replace(**{"time.steps": ref_steps, **final}))[0])
    rows = []
    for n in steps:
        result, seconds = _run(scene.replace(**{"time.steps": n, **final}), like=reference.result)
        rows.append({"k": scene.time.T / n, "steps": n, "seconds": seconds, **reference.errors(result).__dict__})
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
    cell = lambda c: "" if c not in rates else ("—" if np.isnan(rates[c]) else f"{rates[c]:.2f}")  # noqa: E731
    lines.append("| order | " + " | ".join(cell(c) for c in cols[1:]) + " |")
    return "\n".join(lines)


def alpha_slope(scene: Scene) -> float:
    """α L_p: the largest wear rate κ‖v*‖ over the contact points and the speed table, times the largest slope of p."""
    return Discretization(scene).contact.largest_rate()


def stability_steps(scene: Scene, targets=(0.5, 1.0, 1.5, 2.5, 5.0)) -> list[int]:
    """Step counts N with k α L = T α L / N nearest to the ``targets`` (those N ≥ 1 reaches, distinct)."""
    rate = scene.time.T * alpha_slope(scene)
    if rate == 0:
        return []
    return sorted({max(1, round(rate / r)) for r in targets}, reverse=True)


def stability_study(scene: Scene, steps, ref_steps: int = 640) -> list[dict]:
    """Final-time wear error and overshoot (:func:`ngwear.runs.checks.overshoot`) of each integrator.

    k α L = T α L / steps with the scene's real α (the largest κ‖v*‖ over the contact points and the speed
    table) and L (the largest slope of p on [0, g]); the explicit update is run where it diverges too
    (``wear.allow_unstable``).  W_final = ‖w(T) − w_ref(T)‖_{L²(Γ_C)} against ``ref_steps`` trapezoidal steps.  Every
    run reuses the reference's mesh and factorisation.
    """
    rate = alpha_slope(scene)
    final = {"output.every": scene.time.T, "wear.allow_unstable": True}
    ref, _ = _run(scene.replace(**{"time.steps": ref_steps, "wear.integrator": "trapezoidal", **final}))
    rows = []
    loop = logging.getLogger(simulate.__module__)
    level = loop.level
    loop.setLevel(logging.ERROR)            # the unstable steps are asked for: their warnings say nothing new here
    try:
        for n in steps:
            row = {"steps": n, "k_alpha_L": scene.time.T * rate / n}
            for integrator in ("explicit", "implicit", "trapezoidal"):
                result, _ = _run(scene.replace(**{"time.steps": n, "wear.integrator": integrator, **final}), like=ref)
                dw = result.wear[-1] - ref.wear[-1]
                row[f"{integrator}_W_final"] = float(np.sqrt(dw @ (ref.weights * dw)))
                row[f"{integrator}_overshoot"] = overshoot(result)
            rows.append(row)
    finally:
        loop.setLevel(level)
    return rows
