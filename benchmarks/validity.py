"""What the run's validity checks cost per step: strains beyond the small-strain model, a worn layer.

The shipped brake pad (P1, maxh 0.006, 220 contact points) and finer (maxh 0.003, 0.002), 150 steps, on one
discretization: the time loop with the checks (:class:`ngwear.runs.validity.Validity`) and with them replaced by
a no-op, interleaved, ms per step (medians of ``--reps``); the checks alone per step (``Validity.__call__`` over the
run's recorded rows, median of 5 passes); casting the segments along −ν once (the set-up's share), against the
whole set-up (mesh from the cache, discretization, first step).

    .venv/bin/python benchmarks/validity.py [--quick] [--reps 5]
"""
from __future__ import annotations

from unittest import mock

import common as C

import ngwear
from ngwear.numerics.contact import Instant
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.strain import segments
from ngwear.runs import validity
from ngwear.runs.step import State

STEPS = 150


class Off:
    """The checks replaced by nothing (the loop without them)."""

    def __init__(self, result, disc):
        pass

    def __call__(self, *args):
        return None

    def report(self, result):
        pass


def main():
    args = C.parser(__doc__.splitlines()[0]).parse_args()
    rows = []
    for maxh in (0.006,) if args.quick else (0.006, 0.003, 0.002):
        scene = ngwear.load_scene("brake_pad").replace(**{"mesh.maxh": maxh, "time.steps": STEPS})
        mesh = C.mesh_for(scene)
        setup, disc = C.timed(lambda: Discretization(scene, mesh))
        first, _ = C.timed(lambda: ngwear.simulate(scene.replace(**{"time.steps": 1, "time.T": 1.0,
                                                                    "output.every": 1.0}),
                                                   discretization=disc, progress=False))
        cast, _ = C.timed(lambda: segments(scene, disc.mesh, disc.points.coords))

        def run(off: bool):
            if not off:
                return ngwear.simulate(scene, discretization=disc, progress=False)
            with mock.patch("ngwear.runs.loop.Validity", Off):
                return ngwear.simulate(scene, discretization=disc, progress=False)

        times, outs = C.interleaved({"on": lambda: run(False), "off": lambda: run(True)}, args.reps)
        result = outs["on"]
        check = validity.Validity(result, result.discretization)
        states = [State(None, None, None, result.wear[j], Instant(t, 1.0, 1.0), normal=result.normal_displacement[j],
                        plate=result.plate_displacement[j], steps=j) for j, t in enumerate(result.times)]

        def checks():
            for state in states:
                check(state)

        alone = C.median([C.timed(checks)[0] for _ in range(5)]) / (result.steps + 1)
        on, off = C.median(times["on"]) / STEPS, C.median(times["off"]) / STEPS
        rows.append({"maxh": maxh, "points": disc.points.n, "ms_step_on": 1e3 * on, "ms_step_off": 1e3 * off,
                     "difference_%": 100 * (on / off - 1), "checks_ms_step": 1e3 * alone,
                     "checks_%": 100 * alone / off, "segments_s": cast, "setup_s": setup + first,
                     "segments_%_setup": 100 * cast / (setup + first)})
        print(rows[-1], flush=True)
    C.finish("validity", "validity checks per step (brake pad, 150 steps)", C.machine_lines(args), rows,
             [("maxh", "maxh", "g"), ("points", "points", None), ("ms_step_on", "ms/step on", ".3f"),
              ("ms_step_off", "ms/step off", ".3f"), ("difference_%", "diff %", "+.1f"),
              ("checks_ms_step", "checks ms/step", ".4f"), ("checks_%", "checks %", ".2f"),
              ("segments_s", "segments s", ".3f"), ("setup_s", "set-up s", ".2f"),
              ("segments_%_setup", "segments % set-up", ".1f")], quick=args.quick)


if __name__ == "__main__":
    main()
