"""Progress of long work: a bar where someone watches it, log lines where no one does.

In a terminal or a Jupyter kernel :func:`bar` is a tqdm bar, redrawn in place.  Elsewhere (CI, a batch
scheduler, output piped into a file) a bar's carriage returns are noise in the log, so :func:`bar` gives
:class:`Lines` instead: the same calls, written through the logger ``ngwear.progress`` at INFO, one line per
stage (each new description) and one at every tenth of a counted total.  ``ngwear`` shows these lines unless
``--quiet``; a Python program sees them once it configures logging (``logging.basicConfig(level=logging.INFO)``).
Both count in whole numbers with thousands separators and say how long the rest will take, from the rate so far::

    paper_strip:  70%|███████   | 42,000 of 60,000 steps [00:12<00:05, 3500.00 step/s]     (a terminal)
    ngwear: paper_strip: 42,000 of 60,000 steps [12.0 s, about 5.1 s left]                 (a log)
"""
from __future__ import annotations

import logging
import sys
import time

from ..model.programme import Schedule

log = logging.getLogger("ngwear.progress")


def watched() -> bool:
    """Whether someone watches a bar: stderr is a terminal, or the code runs in a Jupyter kernel."""
    if sys.stderr is not None and sys.stderr.isatty():
        return True
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    return shell is not None and "IPKernelApp" in shell.config


COUNTED = "{l_bar}{bar}| {n:,} of {total:,} {unit}s [{elapsed}<{remaining}, {rate_fmt}]"
"""The format of a tqdm bar that counts (steps, cases): whole numbers with separators, the time left."""


def bar(**kw):
    """A tqdm bar (``tqdm.auto``) with the keywords ``kw`` where someone watches it, else :class:`Lines`.

    A bar with a ``total`` and a ``unit`` counts in :data:`COUNTED`'s format unless ``kw`` gives a ``bar_format``.
    """
    if watched():
        from tqdm.auto import tqdm
        if kw.get("total") is not None and "unit" in kw:
            kw.setdefault("bar_format", COUNTED)
        return tqdm(**kw)
    return Lines(**kw)


class Lines:
    """tqdm's calls (``update``, ``set_description_str``, ``write``, ``close``) as log lines.

    Parameters
    ----------
    total : float, optional
        What the count goes up to (None: stages only, no count).
    desc : str
        What is counted, e.g. the scene's name.
    unit : str
        The counted unit (``step``, ``case``); tqdm's default ``it`` is not written.
    initial : float
        The count to start from (a resumed run).
    disable : bool
        Write nothing.
    """

    def __init__(self, total=None, desc: str = "", unit: str = "it", initial=0, disable: bool = False, **_):
        self.total, self.desc, self.unit, self.n, self.disable = total, desc, unit, initial, disable
        self.start, self.initial = time.monotonic(), initial
        self.tenth = self._tenth()
        if total is not None:
            self._say(self._count())

    def update(self, n=1) -> None:
        self.n += n
        if self._tenth() > self.tenth:
            self.tenth = self._tenth()
            self._say(self._count())

    def set_description_str(self, desc: str) -> None:
        """A new stage: one line."""
        self.desc = desc
        self._say(desc)

    def write(self, text: str, file=None) -> None:
        self._say(text)

    def close(self) -> None:
        """Nothing to clear (a bar erases itself)."""

    def _tenth(self) -> int:
        return int(10 * self.n / self.total + 1e-9) if self.total else 0

    def _count(self) -> str:
        """``desc: n of total units [elapsed, about … left]``; the time left from the rate since the start."""
        unit = "" if self.unit == "it" else f" {self.unit}s"
        elapsed, done = time.monotonic() - self.start, self.n - self.initial
        left = f", about {duration(elapsed * (self.total - self.n) / done)} left" if 0 < done and self.n < self.total \
            else ""
        return f"{self.desc}: {number(self.n)} of {number(self.total)}{unit} [{duration(elapsed)}{left}]"

    def _say(self, text: str) -> None:
        if not self.disable:
            log.info("%s", text)


def number(value) -> str:
    """A count as a whole number with thousands separators (``42,000``); a fraction (a time) to 4 digits."""
    return f"{int(value):,}" if float(value).is_integer() else f"{value:.4g}"


def duration(seconds: float) -> str:
    """Seconds as a reader takes them in: ``5.1 s``, ``3.2 min``, ``1.5 h``."""
    if seconds < 120:
        return f"{seconds:.1f} s"
    return f"{seconds / 60:.1f} min" if seconds < 7200 else f"{seconds / 3600:.1f} h"


class RunProgress:
    """A run's bar, from where the run starts: its steps (uniform), its time (adaptive) or its stops (a programme)."""

    def __init__(self, scene, result):
        self.scene, time = scene, scene.time
        if scene.programme is not None:
            self.shown = self._stops(result)
            self.bar = bar(total=scene.programme.count, initial=self.shown, desc=scene.name, unit="stop", leave=False)
        elif not time.adaptive:
            self.bar = bar(total=time.steps, initial=max(result.steps, 0), desc=scene.name, unit="step", leave=False)
        else:
            self.bar = bar(total=time.T, initial=result.times[-1] if len(result.times) else 0.0, desc=scene.name,
                           leave=False, bar_format="{l_bar}{bar}| t = {n:.4g} of {total:.4g} [{elapsed}<{remaining}]")

    def _stops(self, result) -> int:
        """The stops done: the simulated ones whose end is recorded, and the jumped ones."""
        return len(Schedule.of(self.scene.programme).ends(len(result.times))) + len(result.jumped)

    def update(self, result) -> None:
        """After a recorded step: one step, its time, or the stops it ended."""
        if self.scene.programme is not None:
            done = self._stops(result)
            if done > self.shown:
                self.bar.update(done - self.shown)
                self.shown = done
        else:
            self.bar.update(1 if not self.scene.time.adaptive else result.times[-1] - result.times[-2])

    def close(self) -> None:
        self.bar.close()
