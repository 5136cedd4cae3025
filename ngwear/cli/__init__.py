"""Script mode: ``ngwear run SCENE [--out DIR] [--set KEY=VALUE ...] [--no-pictures]``.

SCENE is a scene TOML file or the name of a shipped scene (``ngwear run paper_strip``); ``ngwear examples``
lists the shipped scenes and ``ngwear examples --copy DIR`` copies them to start from.  Also ``ngwear explore``
(the explorer as a web app), ``ngwear verify``, ``ngwear stress``, ``ngwear schema`` (the scene files' JSON
Schema) and ``ngwear sweep STUDY.toml [--out DIR] [--scheduler ADDRESS] [--workers N]`` (a parameter study on
Dask, see :mod:`ngwear.studies.sweep`).  Every command takes ``--quiet`` (warnings and errors only) and
``--verbose`` (also the solver's notes and the log of the libraries, Dask's included); by default a run shows a
progress bar in a terminal and one line per stage elsewhere.

Bad input exits with status 2 and one line naming the field (also an output folder in use by another
run, or a damaged file of one); a run that stops part-way writes the steps it completed and exits with
status 1, as does a run stopped by a full disk (one line saying what its checkpoint keeps).
"""
from __future__ import annotations

import os
import signal
import sys

from .signals import on_signals


def main(argv: list[str] | None = None) -> int:
    """The ``ngwear`` command: its exit status (0 done, 1 a run stopped part-way, 2 bad input, 128 + a signal).

    SIGINT and SIGTERM end it at once with 128 + the signal and one line, from the first instant: the libraries
    (NGSolve, NumPy, …) load inside, after the handler is set.  A run and a study stop at their next step or case
    instead, keeping what they computed (:mod:`ngwear.cli.run`).
    """
    received, loading = [], [True]

    def interrupted(number):    # outside the work that stops itself (a run, a study): at once
        if loading:             # nothing written yet, and an exception would become an extension module's
            print("ngwear: interrupted", file=sys.stderr, flush=True)          # ImportError
            os._exit(128 + number)
        received.append(number)
        raise KeyboardInterrupt

    try:
        with on_signals(interrupted):
            from .commands import dispatch
            loading.clear()
            return dispatch(argv)
    except KeyboardInterrupt:
        print("ngwear: interrupted", file=sys.stderr)
        return 128 + (received[-1] if received else signal.SIGINT)
