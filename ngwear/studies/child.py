"""A child process that runs calls, so that a crash ends the call and not its caller.

A case that segfaults inside NGSolve, calls ``os._exit`` or is killed for its memory takes its process
with it.  Run in a :class:`Child`, it takes only the child: the call raises :class:`ChildError` with one
line naming the signal or the exit status, and the next call starts a new child.  A child runs one call
at a time and keeps its module state between calls (a study's cached discretizations).

The child runs :func:`main` in a new Python interpreter.  It reads calls ``(function, args)``, pickled (functions
by reference: importable in the child), from its stdin and writes each outcome, length-prefixed, to a
copy of its stdout; file descriptor 1 itself goes to stderr, so what C++ code prints cannot corrupt the
replies.  It ignores SIGINT (its parent decides when it ends) and exits when its stdin closes or its
parent dies.
"""
from __future__ import annotations

import atexit
import os
import pickle
import signal
import struct
import subprocess
import sys
import threading
import time
from typing import Any, BinaryIO, Callable

HEADER = struct.Struct("<Q")


class ChildError(RuntimeError):
    """A call failed in the child (``Type: message`` of its exception) or the child died during it."""


class Child:
    """A Python child process running calls one at a time; started on the first call, again after a death."""

    def __init__(self) -> None:
        self._process: subprocess.Popen | None = None
        atexit.register(self.close)

    def call(self, function: Callable, *args: Any) -> Any:
        """``function(*args)`` in the child: its result, or :class:`ChildError` with one line."""
        if self._process is None or self._process.poll() is not None:
            self._process = subprocess.Popen([sys.executable, "-c", f"from {__name__} import main; main()"],
                                             stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        process = self._process
        request = pickle.dumps((function, args))
        try:
            _send(process.stdin, request)
            status, value = pickle.loads(_receive(process.stdout))
        except (OSError, EOFError):
            raise ChildError(_death(process.wait())) from None
        if status == "error":
            raise ChildError(value)
        return value

    @property
    def pid(self) -> int | None:
        """The child's process id (None before the first call)."""
        return self._process.pid if self._process is not None else None

    def close(self) -> None:
        """End the child (it is started again by the next call)."""
        if self._process is not None and self._process.poll() is None:
            self._process.kill()
            self._process.wait()


def _death(code: int) -> str:
    """One line for a child that died with return code ``code`` (−N: killed by signal N)."""
    if code >= 0:
        return f"the process running it exited with status {code}"
    number = -code
    try:
        name = signal.Signals(number).name
    except ValueError:
        name = f"signal {number}"
    hint = "; out of memory?" if number == signal.SIGKILL else ""
    return f"the process running it died of {name} ({signal.strsignal(number)}{hint})"


def _send(stream: BinaryIO, data: bytes) -> None:
    stream.write(HEADER.pack(len(data)) + data)
    stream.flush()


def _receive(stream: BinaryIO) -> bytes:
    header = stream.read(HEADER.size)
    if len(header) < HEADER.size:
        raise EOFError
    size = HEADER.unpack(header)[0]
    data = stream.read(size)
    if len(data) < size:
        raise EOFError
    return data


def _line(err: BaseException) -> str:
    lines = str(err).strip().splitlines()
    return f"{type(err).__name__}: {lines[0] if lines else ''}".strip()


def _exit_with(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(1.0)
    os._exit(1)


def main() -> None:
    """The child's loop: read a call, run it, write its outcome; until stdin closes."""
    replies = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_exit_with, args=(os.getppid(),), daemon=True).start()
    requests = sys.stdin.buffer
    while True:
        try:
            request = _receive(requests)
        except EOFError:
            return
        try:
            function, args = pickle.loads(request)
            reply = pickle.dumps(("ok", function(*args)))
        except Exception as err:  # the call's own failure, as one line (an exception may not unpickle)
            reply = pickle.dumps(("error", _line(err)))
        _send(replies, reply)
