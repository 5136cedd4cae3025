"""Progress of long work: a bar where someone watches it, log lines where no one does.

In a terminal or a Jupyter kernel :func:`bar` is a tqdm bar, redrawn in place.  Elsewhere (CI, a batch
scheduler, output piped into a file) a bar's carriage returns are noise in the log, so :func:`bar` gives
:class:`Lines` instead: the same calls, written through the logger ``ngwear.progress`` at INFO, one line per
stage (each new description) and one at every tenth of a counted total.  ``ngwear`` shows these lines unless
``--quiet``; a Python program sees them once it configures logging (``logging.basicConfig(level=logging.INFO)``).
"""
from __future__ import annotations

import logging
import sys
import time

log = logging.getLogger("ngwear.progress")


def watched() -> bool:
    """Whether someone watches a bar: stderr is a terminal, or the code runs in a Jupyter kernel."""
    if sys.stderr is not None and sys.stderr.isatty():
        return True
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    return shell is not None and "IPKernelApp" in shell.config


def bar(**kw):
    """A tqdm bar (``tqdm.auto``) with the keywords ``kw`` where someone watches it, else :class:`Lines`."""
    if watched():
        from tqdm.auto import tqdm
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
        self.start = time.monotonic()
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
        unit = "" if self.unit == "it" else f" {self.unit}s"
        return f"{self.desc}: {self.n:.4g} of {self.total:.4g}{unit} [{time.monotonic() - self.start:.1f} s]"

    def _say(self, text: str) -> None:
        if not self.disable:
            log.info("%s", text)
