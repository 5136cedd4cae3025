"""What a geometry update's stiffness costs: the gradient blocks of the moved region summed in NumPy or by NGSolve.

``geometries/brake_pad_life.toml`` at three sizes (the shipped mesh, ``mesh.maxh`` 0.002 and 0.00122: 202k DOFs).
Each measurement is K as a geometry update builds it (:meth:`GradientBlocks.stiffness` with the backing plate's
blocks kept, the friction material's built anew), interleaved, medians of ``--reps``, in one process:

* ``numpy``: P1 on straight simplices, the blocks summed from the element arrays (``simplex_blocks``) with the
  region's index map of an earlier update (``simplex_pattern``, kept across updates);
* ``numpy, map anew``: the same with the index map made again (a run's first K);
* ``ngsolve``: the same blocks assembled by NGSolve's symbolic forms (the path of P2 and curved meshes).

All give the same K: the table gives NumPy's largest difference from NGSolve's relative to K's largest entry.

    .venv/bin/python benchmarks/stiffness_blocks.py [--quick] [--reps 3]
"""
from __future__ import annotations

import common as C

from ngwear.numerics.stiffness import GradientBlocks


def row(maxh: float | None, reps: int) -> dict:
    scene, disc = C.life_pad(maxh)
    laws = {region: law.tangent_at_zero() for region, law in disc.elastic.laws.items()}
    moved = "body"                                          # the pad's friction material: it carries Γ_C
    kept = {r: GradientBlocks(disc.fes).of(r) for r in disc.mesh.GetMaterials() if r != moved}
    earlier = GradientBlocks(disc.fes).patterns                 # an earlier update's index maps
    GradientBlocks(disc.fes, patterns=earlier).of(moved)

    def build(vertex_p1: bool, patterns: dict | None = None):
        def stiffness():
            blocks = GradientBlocks(disc.fes, kept, patterns)    # the moved region's blocks built anew each time
            blocks.vertex_p1 = vertex_p1
            return blocks.stiffness(laws)
        return stiffness

    times, out = C.interleaved({"numpy": build(True, earlier), "numpy, map anew": build(True),
                                "ngsolve": build(False)}, reps)
    scale = abs(out["ngsolve"]).max()
    assert abs(out["numpy"] - out["numpy, map anew"]).max() == 0
    return {"maxh": scene.mesh.maxh, "dofs": disc.fes.ndof, "moved": moved,
            "numpy_s": C.median(times["numpy"]), "anew_s": C.median(times["numpy, map anew"]),
            "ngsolve_s": C.median(times["ngsolve"]), "speed_up": C.median(times["ngsolve"]) / C.median(times["numpy"]),
            "difference": abs(out["numpy"] - out["ngsolve"]).max() / scale}


def main() -> None:
    args = C.parser(__doc__.splitlines()[0]).parse_args()
    with C.blas_limit(args.blas_threads):
        rows = [row(maxh, args.reps) for maxh in (C.LIFE_SIZES[:1] if args.quick else C.LIFE_SIZES)]
    columns = [("maxh", "mesh.maxh", ".5g"), ("dofs", "DOFs", "d"), ("moved", "moved region", None),
               ("numpy_s", "numpy [s]", ".3f"), ("anew_s", "numpy, map anew [s]", ".3f"),
               ("ngsolve_s", "NGSolve [s]", ".3f"), ("speed_up", "speed-up", ".1f"),
               ("difference", "max |ΔK| / max |K|", ".1e")]
    C.finish("stiffness_blocks", "a geometry update's K: blocks in NumPy against NGSolve", C.machine_lines(args), rows,
             columns, quick=args.quick)


if __name__ == "__main__":
    main()
