"""Local refinement of Γ_C: a sphere-ended pin refined within a zone, against the whole cap refined.

A steel pin of diameter 2 mm (a = 1 mm) with a hemispherical end (R = 1 mm), maxh 0.5 mm, pressed by a plate with
1 kN onto a flat that is all but rigid (p = L r₊, L = 1e17 Pa/m: its compression is 1 % of Hertz's approach):
Hertz gives a contact radius a_H = (3PR/4E*)^⅓ = 0.15 mm and a peak p₀ = 3P/(2π a_H²).  Three meshes: no
refinement; ``mesh.contact_maxh`` 0.03 mm within ``mesh.contact_zone`` 0.3 mm of the tip (the default
``mesh.zone_center``); the same size on the whole cap (what ``contact_maxh`` alone does).  Each: contact points
(all, in the zone), DOFs, meshing (Netgen, no cache, with the zone's sampling), the set-up (assembly,
factorisation, contact compliance) and the step; the contact radius a = √(A/π) from the contact area A, the peak
traction p + λ, and how the zone's traction differs from the whole cap's at its points within 0.8 a of the axis
(the cap's interpolated there; rms and max, as a share of the peak) and from Hertz's p₀ √(1 − r²/a_H²) there
(rms, as a share of p₀: the discretisation error).  ``--quick``: 0.06 mm, not the whole cap.

    .venv/bin/python benchmarks/contact_zone.py [--quick] [--reps 1]
"""
from __future__ import annotations

import tempfile

import common as C
import numpy as np
from scipy.interpolate import LinearNDInterpolator

import ngwear
from ngwear.model.scene_mesh import build_mesh
from ngwear.numerics.discrete import Discretization

PIN = {"name": "sphere", "units": "SI",
       "geometry": {"kind": "pin", "size": [0.001, 0.004], "end": "sphere", "position": [0.03, 0.0], "dirichlet": []},
       "mesh": {"maxh": 0.0005}, "material": {"young": 2e11, "poisson": 0.3},
       "contact": {"stiffness": 1e17, "gap": 1.0, "friction": 0.0, "direction": [0, 0, -1]},
       "loads": {"plate": {"boundary": "back", "force": [0, 0, -1000.0]}}, "time": {"steps": 1},
       "output": {"every": 1.0}}
AXIS = np.array([0.03, 0.0])
ZONE = 3e-4


def hertz(scene) -> tuple[float, float]:
    """(a_H, p₀) of a sphere of radius R pressed with P on a rigid flat."""
    m = scene.material
    e_star = m.young / (1 - m.poisson**2)
    force, radius = -scene.loads.plate.force[2], scene.geometry.end_radius
    a = (3 * force * radius / (4 * e_star)) ** (1 / 3)
    return a, 3 * force / (2 * np.pi * a**2)


def traction_at(result, points):
    """The traction p + λ of the last step at ``points`` (x, y), interpolated linearly over the contact points' (x, y)."""
    return LinearNDInterpolator(result.contact_points[:, :2], result.pressure[-1] + result.reaction[-1])(points)


def case(scene, reps: int) -> tuple[dict, object]:
    meshing, setup, steps = [], [], []
    for _ in range(reps):
        start = C.perf()
        mesh = build_mesh(scene, use_cache=False)
        meshing.append(C.perf() - start)
    start = C.perf()
    disc = Discretization(scene, mesh)
    for _, build in disc.stages():
        build()
    setup.append(C.perf() - start)
    start = C.perf()
    result = ngwear.simulate(scene, discretization=disc, progress=False)
    steps.append(C.perf() - start)
    distance = np.linalg.norm(result.contact_points[:, :2] - AXIS, axis=1)
    traction = result.pressure[-1] + result.reaction[-1]
    row = {"points": disc.points.n, "in_zone": int((distance <= ZONE).sum()), "dofs": disc.fes.ndof,
           "mesh_s": C.median(meshing), "setup_s": C.median(setup), "run_s": C.median(steps),
           "contact_radius_mm": 1e3 * np.sqrt(result.contact_area[-1] / np.pi), "peak_GPa": 1e-9 * traction.max(),
           "force_N": result.normal_force[-1], "solve": "matrix-free" if disc.matrix_free else "dense"}
    return row, result


def main():
    p = C.parser(__doc__.splitlines()[0])
    p.set_defaults(reps=1)
    args = p.parse_args()
    h = 6e-5 if args.quick else 3e-5
    base = ngwear.Scene.from_dict(PIN)
    a_h, p0 = hertz(base)
    cases = {"no refinement": {}, f"zone {ZONE * 1e3:g} mm": {"mesh.contact_maxh": h, "mesh.contact_zone": ZONE}}
    if not args.quick:
        cases["whole cap"] = {"mesh.contact_maxh": h}
    header = C.machine_lines(args) + [
        f"steel pin a = 1 mm, hemispherical end R = 1 mm, maxh 0.5 mm, contact_maxh {h * 1e3:g} mm; P = 1 kN on a "
        f"flat, L = 1e17 Pa/m: Hertz a = {a_h * 1e3:.4f} mm, p0 = {p0 * 1e-9:.3f} GPa; meshing without the cache, "
        f"median of {args.reps}; Δ vs cap: p + λ at a case's points within 0.8 a of the axis against the whole "
        f"cap's (interpolated), / its peak"]
    rows, results = [], {}
    with tempfile.TemporaryDirectory() as cache:
        C.os.environ["NGWEAR_CACHE"] = cache
        for name, changes in cases.items():
            row, results[name] = case(base.replace(**changes), args.reps)
            rows.append({"case": name, **row})
            print(f"  {name}: {row['points']} points ({row['in_zone']} in the zone), mesh {row['mesh_s']:.1f} s, "
                  f"set-up {row['setup_s']:.1f} s, step {row['run_s']:.1f} s", flush=True)
    if "whole cap" in results:              # at each case's points within 0.8 a_H of the axis, the cap's interpolated
        cap = results["whole cap"]
        peak = (cap.pressure[-1] + cap.reaction[-1]).max()
        for row, name in zip(rows, cases):
            xy = results[name].contact_points[:, :2]
            inner = np.linalg.norm(xy - AXIS, axis=1) < 0.8 * a_h
            difference = (results[name].pressure[-1] + results[name].reaction[-1])[inner] - traction_at(cap, xy[inner])
            row["rms_vs_cap"] = np.sqrt(np.mean(difference**2)) / peak if inner.any() else np.nan
            row["max_vs_cap"] = np.abs(difference).max() / peak if inner.any() else np.nan
    for row, result in zip(rows, results.values()):     # the discretisation error: against Hertz at the same points
        xy = result.contact_points[:, :2]
        r = np.linalg.norm(xy - AXIS, axis=1)
        inner = r < 0.8 * a_h
        exact = p0 * np.sqrt(1 - (r[inner] / a_h) ** 2)
        row["rms_vs_hertz"] = np.sqrt(np.mean(((result.pressure[-1] + result.reaction[-1])[inner] - exact) ** 2)) / p0
    columns = [("case", "case", None), ("points", "contact points", None), ("in_zone", "in the zone", None),
               ("dofs", "DOFs", None), ("solve", "contact solve", None), ("mesh_s", "mesh [s]", ".1f"),
               ("setup_s", "set-up [s]", ".1f"), ("run_s", "step [s]", ".2f"),
               ("contact_radius_mm", "a [mm]", ".4f"), ("peak_GPa", "peak p+λ [GPa]", ".3f"),
               ("force_N", "force [N]", ".1f"), ("rms_vs_hertz", "rms Δ vs Hertz", ".4f"),
               ("rms_vs_cap", "rms Δ vs cap", ".4f"), ("max_vs_cap", "max Δ vs cap", ".4f")]
    C.finish("contact_zone", "a sphere-ended pin: local against whole-cap refinement", header, rows, columns,
             quick=args.quick)


if __name__ == "__main__":
    main()
