"""Netgen's memory and time per element, and ngwear's estimate of the element count.

Each case meshes a part in a fresh process (no cache) and reports the estimate of
:func:`ngwear.model.netgen_meshing.estimate` beside the elements Netgen made, the meshing time and the peak memory above
the process's memory before meshing (``VmHWM``, reset before it: Linux), per element: the numbers behind the
default of ``mesh.max_elements`` (docs/guide/scenes.md).  Cases are ``scene:key=value,...`` (``strip`` is the
paper's strip, ``box`` box3d, ``pad`` the brake pad).

    .venv/bin/python benchmarks/mesh_size.py            # every case
    .venv/bin/python benchmarks/mesh_size.py --quick
"""
from __future__ import annotations

import json
import subprocess
import sys

from common import finish, machine_lines, parser

CASES = ["strip:mesh.maxh=0.02", "strip:mesh.maxh=0.01", "strip:mesh.maxh=0.005",
         "strip:mesh.maxh=0.1,mesh.contact_maxh=0.002", "box:mesh.maxh=0.06", "box:mesh.maxh=0.04",
         "box:mesh.maxh=0.025", "box:mesh.maxh=0.1,mesh.contact_maxh=0.02", "pad:mesh.contact_maxh=0.002"]
QUICK = ["strip:mesh.maxh=0.02", "box:mesh.maxh=0.06"]
SCENES = {"strip": "paper_strip", "box": "box3d", "pad": "brake_pad"}

CHILD = """
import json, sys, time
import ngwear
from ngwear.model.kinds import KINDS
from ngwear.model.netgen_meshing import _mesh, estimate
name, sets = sys.argv[1], json.loads(sys.argv[2])
scene = ngwear.load_scene(name).replace(**sets)
g, m = scene.geometry, scene.mesh
shape = KINDS[g.kind].build(g, m)
count = estimate(shape, g.dim, m.maxh, m.grading)[0]
def status(key):
    return next(int(line.split()[1]) for line in open("/proc/self/status") if line.startswith(key))
open("/proc/self/clear_refs", "w").write("5")       # the peak (VmHWM) from here on
before = status("VmRSS:")
start = time.perf_counter()
mesh = _mesh(shape, g.dim, m.maxh, m.grading)
seconds = time.perf_counter() - start
peak = status("VmHWM:") - before
elements = mesh.ne if g.dim == 3 else len(mesh.Elements2D())
print(json.dumps({"dim": g.dim, "estimate": count, "elements": elements, "seconds": seconds, "peak_mb": peak / 1024}))
"""


def measure(case: str) -> dict:
    scene, _, settings = case.partition(":")
    sets = {k: float(v) for k, v in (item.split("=") for item in settings.split(",") if item)}
    done = subprocess.run([sys.executable, "-c", CHILD, SCENES[scene], json.dumps(sets)], capture_output=True,
                          text=True, check=True)
    row = json.loads(done.stdout.strip().splitlines()[-1])
    return {"case": case, **row, "ratio": row["estimate"] / row["elements"],
            "kb_per_element": 1024 * row["peak_mb"] / row["elements"]}


def main() -> None:
    args = parser(__doc__.splitlines()[0]).parse_args()
    rows = [measure(case) for case in (QUICK if args.quick else CASES)]
    columns = [("case", "case", None), ("dim", "dim", None), ("estimate", "estimate", ".0f"),
               ("elements", "elements", None), ("ratio", "estimate/elements", ".2f"), ("seconds", "mesh s", ".1f"),
               ("peak_mb", "peak MB", ".0f"), ("kb_per_element", "KB/element", ".2f")]
    finish("mesh_size", "Netgen: memory and time per element, and ngwear's estimate", machine_lines(args), rows,
           columns, quick=args.quick)


if __name__ == "__main__":
    main()
