"""What ``ngwear verify`` runs for a scene, and its report: h- and k-refinement, stability of the wear update, (H_S).

The plan follows the scene (:func:`plan`): every mesh size is refined by the same factor (``mesh.maxh`` and
``mesh.contact_maxh``), from the scene's own sizes (``quick``: 2D from them, 3D parts from twice them, so
that the reference is the scene's mesh); the time grids keep k·α·L ≤ 1 (α the largest wear rate over the
contact points, L the largest slope of p on [0, g]) so that the k-study measures accuracy, not overshoot;
the stability study takes the step counts of k·α·L = 0.5, 1, 1.5, 2.5, 5 that N ≥ 1 reaches.  A scene
without wear (κ = 0, or no sliding) has nothing that depends on k: its k- and stability studies are left
out, and said so; so is the h-study of a mesh file (one resolution).  A programme's scene is verified on its first
stop (:func:`first_stop`): the same part, loads and coefficients over one stop of the first block, its speed and load
ramps as time tables, so that the studies may choose its time steps.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..model.coefficients import bound
from ..model.scene import Scene
from ..numerics.discrete import Discretization
from . import verify
from .theory import smallness, uniqueness

INTEGRATORS = ("explicit", "implicit", "trapezoidal")


@dataclass(frozen=True)
class Plan:
    """The sizes and step counts of one verification (see the module docstring)."""

    maxhs: tuple[float, ...]
    ref_maxh: float | None
    h_steps: int
    k_maxh: float | None
    k_steps: tuple[int, ...]
    k_ref: int
    stability_steps: tuple[int, ...]
    stability_ref: int


def first_stop(scene: Scene) -> Scene:
    """A programme's first stop as a scene of its own: T = d, the stop's s_v and s_F as the time tables (else itself)."""
    if scene.programme is None:
        return scene
    stop, steps = scene.programme.blocks[0], scene.programme.steps_per_stop
    data = scene.to_dict()
    del data["programme"]
    d = stop.duration
    data["time"] = {**data.get("time", {}), "T": d, "steps": steps}
    data["foundation"]["speed_table"] = [[0.0, stop.speed[0]], [d, stop.speed[1]]]
    data["loads"]["time_table"] = [[0.0, stop.load[0]], [d, stop.load[1]]]
    data["output"] = {**data.get("output", {}), "every": d}
    data["output"].pop("times", None)
    return Scene.from_dict(data)


def plan(scene: Scene, quick: bool) -> Plan:
    """The plan of ``ngwear verify`` for ``scene`` (``quick``: three meshes, three step sizes, short references).

    2D: maxh = 4, 2, 1 (quick) or 8, 4, 2, 1 times the scene's against a half (a quarter); 3D parts, whose
    shipped meshes are coarse (a few hundred to a few thousand DOFs): 1, 0.7, 0.5 (and 0.35) times the scene's
    against 0.35 (0.25).  The k-study runs on twice the scene's maxh (2D) or on the scene's (3D).
    """
    h0 = scene.mesh.maxh
    if scene.dim == 2:
        factors, ref, k_factor = ((4, 2, 1), 0.5, 2) if quick else ((8, 4, 2, 1), 0.25, 2)
    else:
        factors, ref, k_factor = ((1, 0.7, 0.5), 0.35, 1) if quick else ((1, 0.7, 0.5, 0.35), 0.25, 1)
    k_maxh = k_factor * h0 if h0 else None
    k_scene = verify.refined(scene, k_factor) if h0 else scene
    rate = scene.time.T * verify.alpha_slope(k_scene)
    wears = rate > 0
    base = max(10, math.ceil(rate))                     # k α L ≤ 1 at the coarsest step
    k_steps = tuple(base * m for m in ((1, 2, 4) if quick else (1, 2, 4, 8)))
    return Plan(maxhs=tuple(f * h0 for f in factors) if h0 else (), ref_maxh=ref * h0 if h0 else None,
                h_steps=max(10 if quick else 20, math.ceil(rate)) if wears else scene.time.steps, k_maxh=k_maxh,
                k_steps=k_steps if wears else (), k_ref=8 * k_steps[-1],
                stability_steps=tuple(verify.stability_steps(k_scene)) if wears else (),
                stability_ref=(160 if quick else 640) if wears else 0)


@dataclass
class Report:
    """The studies of one scene: rows of each, and the (H_S) lines."""

    scene: Scene
    plan: Plan
    h_rows: list[dict] = field(default_factory=list)
    k_rows: dict[str, list[dict]] = field(default_factory=dict)
    stability: list[dict] = field(default_factory=list)
    smallness: list[str] = field(default_factory=list)
    on_first_stop: bool = False

    def orders(self) -> dict:
        """Observed orders: ``{"h": {column: order}, "k": {integrator: {column: order}}}`` (NaN: nothing to fit)."""
        return {"h": verify.orders(self.h_rows, "h") if self.h_rows else {},
                "k": {name: verify.orders(rows, "k") for name, rows in self.k_rows.items()}}

    def to_dict(self) -> dict:
        """Everything of the report as plain data (``convergence.json``)."""
        return {"scene": self.scene.name, "on_first_stop": self.on_first_stop, "plan": self.plan.__dict__,
                "smallness": self.smallness,
                "h": self.h_rows, "k": self.k_rows, "stability": self.stability, "orders": self.orders()}

    def markdown(self) -> str:
        s, p = self.scene, self.plan
        sections = [f"# Convergence of {s.name}\n", *(f"{line}\n" for line in self.smallness)]
        if self.on_first_stop:
            sections.insert(1, f"On the programme's first stop: T = {s.time.T:g} (its duration), its speed and load "
                               "factors as foundation.speed_table and loads.time_table.\n")
        if self.h_rows:
            sizes = "mesh.maxh" + (" and mesh.contact_maxh" if s.mesh.contact_maxh is not None else "")
            sections += [f"## h-refinement (P{s.mesh.order}, {p.h_steps} steps; {sizes} refined together, "
                         f"reference maxh = {p.ref_maxh:g})\n", verify.markdown(self.h_rows, "h"),
                         "\n![h](convergence_h.png)"]
        else:
            sections.append("## h-refinement: none (a mesh file has one resolution)\n")
        if not self.k_rows:
            sections.append("\n## k-refinement and stability: none (no wear: κ = 0 or nothing slides; the "
                            "quasistatic solution does not depend on the time step)\n")
            return "\n".join(sections) + "\n"
        mesh = f"maxh = {p.k_maxh:g}, " if p.k_maxh else ""
        for integrator, rows in self.k_rows.items():
            sections += [f"\n## k-refinement, {integrator} wear ({mesh}reference {p.k_ref} steps)\n",
                         verify.markdown(rows, "k")]
        sections += ["\n![k](convergence_k.png)",
                     "\n## Stability of the wear integrators\n",
                     "k_alpha_L = k·α·L with α the largest wear rate κ‖v*‖ over the contact points and the speed "
                     "table and L the largest slope of p on [0, g]. *W_final*: ‖w(T) − w_ref(T)‖ in L²(Γ_C) against "
                     f"{p.stability_ref} trapezoidal steps. *overshoot*: max_j (w_j − max_(m≤j) (u_ν − d₀)₊) / g, "
                     "the wear beyond the largest penetration reached so far (the exact wear never passes it: w' > 0 "
                     "only while u_ν − d₀ > w; after lift-off w > u_ν − d₀ is physical and not counted). Exact "
                     "solution: 0. Theory for p = L r₊: explicit overshoots once k·α·L > 1 (diverges beyond 2: "
                     "run here with wear.allow_unstable), trapezoidal once k·α·L > 2, implicit never.\n",
                     verify.table(self.stability)]
        return "\n".join(sections) + "\n"


def run(scene: Scene, quick: bool = False, *, paper_form: bool = True) -> Report:
    """Run the plan's studies for ``scene`` (``paper_form``: also the paper's c₀, a second factorisation).

    A programme's scene: on its first stop (:func:`first_stop`), said in the report.
    """
    stop = scene.programme is not None
    scene = first_stop(scene)
    p = plan(scene, quick)
    report = Report(scene, p, on_first_stop=stop)
    base = scene.replace(**{"time.steps": p.h_steps, "output.every": scene.time.T})
    if bound(scene.contact.friction) != 0:        # a field (None) may have friction
        disc = Discretization(scene)
        report.smallness.append(uniqueness(disc).message())
        if paper_form:
            report.smallness.append(smallness(disc).message())
    if p.maxhs:
        report.h_rows = verify.h_study(base, p.maxhs, p.ref_maxh)
    if p.k_steps:
        k_base = verify.refined(base, p.k_maxh / scene.mesh.maxh) if p.k_maxh else base
        for integrator in INTEGRATORS:
            report.k_rows[integrator] = verify.k_study(k_base.replace(**{"wear.integrator": integrator}),
                                                       p.k_steps, p.k_ref)
        report.stability = verify.stability_study(k_base, p.stability_steps, p.stability_ref)
    return report
