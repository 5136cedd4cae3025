"""The heat equation's time scheme and mass matrix, measured on the half-space under a uniform flux.

A column 0.02 × 1 (P1 temperature, the strip's Netgen mesh at maxh h; k = ρ = c = 1) takes the flux q = 1 on Γ_C
(y = 0) until T = 0.02, when the heat has gone 4√(κT) = 0.57 deep, the back (y = 1) still cold to 1e-7: the closed
form of the half-space holds, surface rise ΔT = 2q√(t/π)/√(kρc), profile (2q/k)√(κt) ierfc(y / (2√(κt))).

Schemes on N uniform steps: ngwear's two (:class:`ngwear.numerics.heat.Heat`): ``heat.scheme = "bounded"``
(backward Euler, its low-order step with the lumped capacity and the upwinded conduction, flux-corrected within the
bound), that low-order step alone, and ``"consistent"`` (backward Euler with the consistent capacity M and conduction
K, the default); with M and K also BDF2 (its first step backward Euler) and Crank–Nicolson.
For each: the surface error at T, the largest surface error over the steps after the first tenth of [0, T], the
profile's largest nodal error at T (all relative to ΔT(T)) and the undershoot min(T − T₀) / ΔT(T) (a scheme
without a discrete maximum principle cools a node below its start).  Then the space error: the surface error, the
profile's largest nodal and its L² error (√(eᵀMe / 1ᵀM1)) at T over h (BDF2 at N = 4000, whose time error is below
the space error), with observed orders.

    .venv/bin/python benchmarks/heat_schemes.py [--quick]
"""
from __future__ import annotations

import common as C
import ngsolve as ngs
import numpy as np
import scipy.sparse.linalg as spla
from scipy.special import erfc

from ngwear.model.scene import Scene
from ngwear.model.scene_mesh import build_mesh
from ngwear.numerics.forms import displacement_space
from ngwear.numerics.heat import Heat
from ngwear.numerics.points import contact_points
from ngwear.numerics.stiffness import assembled

FINAL, FLUX = 0.02, 1.0


def column(maxh: float, scheme: str = "bounded") -> tuple[Heat, np.ndarray]:
    """The half-space column's heat (k = ρ = c = 1, η = 1, adiabatic) and its nodes' depths y.

    The heat gains ``consistent`` (M, K): the consistent capacity and the conduction before upwinding.
    """
    scene = Scene.from_dict({"geometry": {"kind": "strip", "size": [0.02, 1.0]}, "mesh": {"maxh": maxh},
                             "material": {"conductivity": 1.0, "density": 1.0, "heat_capacity": 1.0},
                             "heat": {"model": "conduction", "partition": 1.0, "scheme": scheme}})
    mesh = build_mesh(scene)
    heat = Heat(scene, mesh, contact_points(displacement_space(mesh, scene), 2, 1))
    u, v = heat.space.TnT()
    heat.consistent = (assembled(ngs.BilinearForm(u * v * ngs.dx, symmetric=True)),
                       assembled(ngs.BilinearForm(ngs.grad(u) * ngs.grad(v) * ngs.dx, symmetric=True)))
    return heat, np.array(mesh.ngmesh.Coordinates())[:, 1]


def surface_exact(t):
    return 2 * FLUX * np.sqrt(np.asarray(t) / np.pi)


def profile_exact(y, t):
    x = y / (2 * np.sqrt(t))
    return 2 * FLUX * np.sqrt(t) * (np.exp(-x * x) / np.sqrt(np.pi) - x * erfc(x))


def march(heat: Heat, scheme: str, steps: int) -> tuple[list[float], np.ndarray]:
    """Surface temperatures after each step and the final nodal temperatures of ``scheme`` on ``steps`` steps."""
    dt, (M, A) = FINAL / steps, heat.consistent
    load = heat.evaluation.T @ (heat.weights * FLUX)
    if scheme.startswith("bounded"):
        heat.temperature, surface = np.zeros(M.shape[0]), []
        for _ in range(steps):
            heat.advance(dt, np.full(len(heat.weights), FLUX))
            surface.append(float(heat.surface_temperature() @ heat.weights / heat.weights.sum()))
        return surface, heat.temperature.copy()
    if scheme == "low order":
        M, A = heat.mass, heat.stiffness
    matrices = {"consistent (backward Euler)": M + dt * A, "low order": M + dt * A, "BDF2": 1.5 * M + dt * A,
                "Crank–Nicolson": M + 0.5 * dt * A}
    solve, first = spla.factorized(matrices[scheme].tocsc()), spla.factorized((M + dt * A).tocsc())
    T, before, surface = np.zeros(M.shape[0]), None, []
    for n in range(steps):
        if scheme == "BDF2" and before is not None:
            T, before = solve(M @ (2 * T - 0.5 * before) + dt * load), T
        elif scheme == "Crank–Nicolson":
            T = solve(M @ T - 0.5 * dt * (A @ T) + dt * load)
        else:
            T, before = (solve if scheme != "BDF2" else first)(M @ T + dt * load), T
        surface.append(float(heat.evaluation @ T @ heat.weights / heat.weights.sum()))
    return surface, T


SCHEMES = ("bounded (flux-corrected)", "low order", "consistent (backward Euler)", "BDF2", "Crank–Nicolson")


def main():
    args = C.parser(__doc__.splitlines()[0]).parse_args()
    header = C.machine_lines(args)
    rows = []
    heat, y = column(0.005)
    scale = float(surface_exact(FINAL))
    for steps in ((10, 40) if args.quick else (5, 10, 20, 40, 80, 160, 1280, 4000)):
        times = FINAL / steps * np.arange(1, steps + 1)
        for scheme in SCHEMES:
            surface, T = march(heat, scheme, steps)
            late = times >= 0.1 * FINAL
            errors = np.abs(np.array(surface) / surface_exact(times) - 1)
            rows.append({"study": "time", "scheme": scheme, "h": 0.005, "steps": steps,
                         "surface_error": abs(surface[-1] / scale - 1), "worst_after_T/10": errors[late].max(),
                         "profile_error": np.abs(T - profile_exact(y, FINAL)).max() / scale,
                         "undershoot": min(T.min(), 0.0) / scale})
    for maxh in ((0.04, 0.02) if args.quick else (0.08, 0.04, 0.02, 0.01, 0.005)):
        heat, y = column(maxh)
        surface, T = march(heat, "BDF2", 4000)
        error = T - profile_exact(y, FINAL)
        rows.append({"study": "space", "scheme": "BDF2", "h": maxh, "steps": 4000,
                     "surface_error": abs(surface[-1] / scale - 1), "profile_error": np.abs(error).max() / scale,
                     "profile_l2": np.sqrt(error @ heat.consistent[0] @ error / heat.capacity.sum()) / scale})
    for study, key, by in (("time", "steps", "scheme"), ("space", "h", "scheme")):
        for name in {r[by] for r in rows if r["study"] == study}:
            series = [r for r in rows if r["study"] == study and r[by] == name]
            for a, b in zip(series, series[1:]):
                for error in ("surface_error", "profile_error", "profile_l2"):
                    if error not in a:
                        continue
                    b[f"{error}_order"] = np.log(a[error] / b[error]) / abs(np.log(b[key] / a[key]))
    columns = [("study", "study", None), ("scheme", "scheme", None), ("h", "h", None), ("steps", "N", None),
               ("surface_error", "surface err", ".2e"), ("surface_error_order", "order", ".2f"),
               ("worst_after_T/10", "worst t>T/10", ".2e"), ("profile_error", "profile err", ".2e"),
               ("profile_error_order", "order", ".2f"), ("profile_l2", "profile L2", ".2e"),
               ("profile_l2_order", "order", ".2f"), ("undershoot", "undershoot", ".1e")]
    C.finish("heat_schemes", "half-space under a uniform flux: errors relative to ΔT(T)", header, rows, columns,
             quick=args.quick)


if __name__ == "__main__":
    main()
