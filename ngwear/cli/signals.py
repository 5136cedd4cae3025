"""The signals of a command: SIGINT and SIGTERM handled within a block (standard library only: loads at once)."""
from __future__ import annotations

import signal
import threading
from contextlib import contextmanager


@contextmanager
def on_signals(handler):
    """``handler(number)`` on SIGINT and SIGTERM within the block (the handlers before it after).

    Also where SIGINT was ignored: a process started in the background by a script inherits that.  Called from
    another thread than the main one (which alone may set handlers), it leaves them as they are.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = {sig: signal.signal(sig, lambda number, _frame: handler(number)) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler_before in before.items():
            signal.signal(sig, handler_before)
