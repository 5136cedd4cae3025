"""For the tests: a Dask worker plugin whose worker's case processes die on chosen cases.

Registered on a cluster, :class:`Deaths` replaces on each worker what the worker asks its case
process to run (``ngwear.studies.sweep.simulate_case``) by :func:`simulate_or_die`, which kills its own
process when the scene's ``contact.friction`` is one of the chosen values — by a real segmentation fault
(reading address 0), by SIGKILL (as the kernel's OOM killer does) or by ``os._exit(3)`` — and otherwise
runs the case.  The case processes import this module: ``tests`` must be on their PYTHONPATH.
"""
import ctypes
import functools
import os
import signal

from distributed import WorkerPlugin

DEATHS = {
    "segfault": lambda: ctypes.string_at(0),
    "kill": lambda: os.kill(os.getpid(), signal.SIGKILL),
    "exit": lambda: os._exit(3),
}


def simulate_or_die(deaths: dict, scene, *args):
    from ngwear.studies.sweep import simulate_case

    if scene.contact.friction in deaths:
        DEATHS[deaths[scene.contact.friction]]()
    return simulate_case(scene, *args)


class Deaths(WorkerPlugin):
    """``deaths``: contact.friction → how its case process dies (a key of :data:`DEATHS`)."""

    def __init__(self, deaths: dict):
        self.deaths = deaths

    def setup(self, worker):
        from ngwear.studies import sweep

        sweep.simulate_case = functools.partial(simulate_or_die, self.deaths)
