"""A sphere wearing flat far beyond its layer: the contact radius against Argatov's a⁴ = a₀⁴ + 4κFsR/π.

The shipped pin on disc (``geometries/pin_on_disc.toml``: a spherical end R = 5 mm, 10 N, at 30 mm from the axis
of a disc turning at 10 rad/s) with a thin, stiff layer (g = 10 µm, L = 10¹² Pa/m), its tip refined (0.1 mm within
1.5 mm), ``wear.geometry = "surface"`` (``wear.update`` 0.5) for 150 s: 45 m of sliding, the tip worn 13 g.  The
contact radius a = √(A/π), A the area of the points with p + λ > 0 (each step's weights), against Argatov's law
from the measured a₀; it should agree within 5 % for s ≥ 4 s₀, a(s₀) = 2 a₀.  In ``"layer"`` mode the same scene
stops wearing at g.

    python benchmarks/life_argatov.py
"""
from __future__ import annotations

from common import ROOT, blas_limit, machine_lines, parser, print_table, write_csv

import ngwear
from ngwear.results.metrics import contact_radius
from ngwear.studies.closed_forms import worn_flat_radius


def main() -> None:
    args = parser(__doc__.splitlines()[0]).parse_args()
    scene = ngwear.load_scene(ROOT / "geometries" / "pin_on_disc.toml").replace(**{
        "contact.gap": 1e-5, "contact.stiffness": 1e12, "mesh.contact_maxh": 1e-4, "mesh.contact_zone": 1.5e-3,
        "time.T": 150.0, "time.steps": 300, "wear.integrator": "trapezoidal", "wear.geometry": "surface",
        "wear.update": 0.5, "output.every": 150.0})
    with blas_limit(args.blas_threads):
        result = ngwear.simulate(scene, progress=False)
        layer = ngwear.simulate(scene.replace(**{"wear.geometry": "layer", "time.T": 30.0, "time.steps": 60,
                                                 "output.every": 30.0}), progress=False)
    speed = scene.foundation.angular_velocity[2] * scene.geometry.position[0]
    force, radius, kappa = -scene.loads.plate.force[2], scene.geometry.end_radius, scene.contact.wear
    weights = result.row_weights
    radii = [contact_radius(weights[j], result.pressure[j], result.reaction[j]) for j in range(result.steps + 1)]
    rows = []
    for j in range(0, result.steps + 1, 20):
        distance = speed * result.times[j]
        argatov = worn_flat_radius(radii[0], kappa, force, distance, radius)
        rows.append({"s_m": distance, "a_mm": 1e3 * radii[j], "argatov_mm": 1e3 * argatov,
                     "error": radii[j] / argatov - 1, "max_total_wear_um": 1e6 * result.total_wear[j].max()})
    header = machine_lines(args) + [f"{result.status}, {result.geometry_updates} geometry updates, "
                                    f"{len(result.weights)} contact points, {result.wall_time:.0f} s; layer mode: "
                                    f"max wear {layer.wear.max() / scene.contact.gap:.4f} g"]
    print_table("a sphere wearing flat: contact radius against Argatov", header, rows,
                [("s_m", "sliding [m]", ".1f"), ("a_mm", "a [mm]", ".4f"), ("argatov_mm", "Argatov [mm]", ".4f"),
                 ("error", "error", "+.3f"), ("max_total_wear_um", "max total wear [µm]", ".1f")])
    write_csv("life_argatov", header, rows)


if __name__ == "__main__":
    main()
