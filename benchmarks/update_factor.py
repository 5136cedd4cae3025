"""What a geometry update's factorisation costs: K of the moved mesh with METIS's ordering or the first K's.

``geometries/brake_pad_life.toml`` at three sizes (the shipped mesh, ``mesh.maxh`` 0.002 and 0.00122: 202k DOFs),
one real update (the friction face worn by half the smallest element's height, :class:`~ngwear.numerics.recession.
Recession`), its K factorised by PARDISO without the Schur complement (the matrix-free contact solve), interleaved,
medians of ``--reps``, in one process:

* ``metis``: METIS orders the moved K afresh (and hands its ordering back: what a run's first factorisation does);
* ``given``: the first K's ordering given (``iparm[4] = 1``: what each update does).

The moved K's pattern may differ from the first's by a few entries (a right angle's zero coupling that a move
makes nonzero), so METIS's ordering of it may differ too: the table gives both factors' nonzeros, the largest
residual of a solve with the given ordering, and whether a factorisation given METIS's own ordering is METIS's to
the bit (so that a run resumed with the ordering its checkpoint keeps factorises as the run did).

    .venv/bin/python benchmarks/update_factor.py [--quick] [--reps 3]
"""
from __future__ import annotations

import common as C
import ngsolve as ngs
import numpy as np

from ngwear.numerics.pardiso import Pardiso
from ngwear.numerics.recession import Recession, contact_height


def row(maxh: float | None, reps: int) -> dict:
    scene, disc = C.life_pad(maxh)
    free = disc.body.free
    first = Pardiso(disc.elastic.stiffness[free][:, free])
    recession = Recession(ngs.Mesh(disc.mesh.ngmesh.Copy()), disc.points, disc.condensation.nu,
                          (scene.loads.plate.boundary,))
    wear = np.full(disc.points.n, scene.wear.update * min(contact_height(disc.mesh), scene.contact.gap))
    coords, _ = recession.trial(wear)
    recession.accept(coords, wear)
    moved = disc.moved(recession.mesh, recession.extension.regions).elastic.stiffness[free][:, free]
    b = np.random.default_rng(0).standard_normal(moved.shape[0])
    times, out = C.interleaved({"metis": lambda: Pardiso(moved), "given": lambda: Pardiso(moved, ordering=first.ordering)},
                               reps)
    metis, given = out["metis"], out["given"]
    x = given.solve(b)
    return {"maxh": scene.mesh.maxh, "dofs": disc.fes.ndof, "metis_nnz": metis.factor_nonzeros,
            "given_nnz": given.factor_nonzeros, "metis_s": C.median(times["metis"]),
            "given_s": C.median(times["given"]), "saved": 1 - C.median(times["given"]) / C.median(times["metis"]),
            "residual": float(np.abs(moved @ x - b).max() / np.abs(b).max()),
            "same": bool(np.array_equal(Pardiso(moved, ordering=metis.ordering).solve(b), metis.solve(b)))}


def main() -> None:
    args = C.parser(__doc__.splitlines()[0]).parse_args()
    with C.blas_limit(args.blas_threads):
        rows = [row(maxh, args.reps) for maxh in (C.LIFE_SIZES[:1] if args.quick else C.LIFE_SIZES)]
    columns = [("maxh", "mesh.maxh", ".5g"), ("dofs", "DOFs", "d"), ("metis_nnz", "nnz(L), METIS", "d"),
               ("given_nnz", "nnz(L), given", "d"), ("metis_s", "METIS [s]", ".3f"),
               ("given_s", "ordering given [s]", ".3f"), ("saved", "saved", ".0%"),
               ("residual", "residual, given", ".1e"), ("same", "METIS's handed back = METIS's", None)]
    C.finish("update_factor", "a geometry update's factorisation: METIS against the first K's ordering",
             C.machine_lines(args), rows, columns, quick=args.quick)


if __name__ == "__main__":
    main()
