"""Child processes that run calls, so that a crash ends the call and not its caller.

A call that segfaults inside Netgen or NGSolve, calls ``os._exit`` or is killed for its memory takes its process
with it.  Run in a :class:`Child`, it takes only the child: the call raises :class:`ChildError` with one line
naming the signal or the exit status, and the next call starts a new child.  A child runs one call at a time and
keeps its module state between calls (a study's cached discretizations); :func:`run` makes one call in a child
of its own (a part file read, a large mesh made).  A set ``stop`` kills the child within :data:`POLL` seconds
(:class:`ChildStopped`), as does an exception raised in the caller during the call (a KeyboardInterrupt).

The child runs this file as a script.  It imports ngwear's modules from this file's folder (the files its parent
runs) as its calls name them, and ngwear's API (``__init__.py``, which imports every layer) only when an attribute
of the package itself is used: a child reading a part file imports Netgen, not NGSolve.  It reads calls
``(function, args)``, pickled (functions by reference: importable in the child), from its stdin and writes each
outcome, length-prefixed, to a copy of its stdout; file descriptor 1 itself goes to stderr, so what C++ code prints
cannot corrupt the replies.  A quiet child's stderr goes to ``/dev/null`` (what Netgen and OpenCASCADE print when
they read or mesh).  It ignores SIGINT (its parent decides when it ends) and exits when its stdin closes or its
parent dies.
"""
from __future__ import annotations

import atexit
import contextlib
import importlib.util
import os
import pickle
import select
import signal
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any, BinaryIO, Callable

HEADER = struct.Struct("<Q")
POLL = 0.05
"""Seconds between two looks at a call's ``stop`` event."""


class ChildError(RuntimeError):
    """A call failed in the child or the child died during it; the message is one line.

    The message is ``Type: message`` of the call's exception, which is also the ``__cause__`` where it pickles.
    ``signal`` is the name of the signal that killed the child (``SIGSEGV``), None when it raised or exited.
    """

    def __init__(self, line: str, signal: str | None = None) -> None:
        super().__init__(line)
        self.signal = signal


class ChildStopped(RuntimeError):
    """A call ended by its ``stop`` event: its child was killed."""


class Child:
    """A Python child process running calls one at a time; started on the first call, again after a death.

    ``quiet``: what the child prints goes to ``/dev/null``, not to this process's stderr.
    """

    def __init__(self, quiet: bool = False) -> None:
        self.quiet = quiet
        self._process: subprocess.Popen | None = None

    def call(self, function: Callable, *args: Any, stop: threading.Event | None = None) -> Any:
        """``function(*args)`` in the child: its result, :class:`ChildError` with one line, or :class:`ChildStopped`."""
        request = pickle.dumps((function, args))
        if self._process is None or self._process.poll() is not None:
            self.close()
            self._process = subprocess.Popen([sys.executable, "-P", __file__], stdin=subprocess.PIPE,
                                             stdout=subprocess.PIPE, stderr=subprocess.DEVNULL if self.quiet else None)
            atexit.register(self.close)
        process = self._process
        try:
            _send(process.stdin, request)
            while stop is not None and not select.select([process.stdout], [], [], POLL)[0]:
                if stop.is_set():
                    raise ChildStopped
            status, value = pickle.loads(_receive(process.stdout))
        except (OSError, EOFError):
            raise ChildError(*_death(process.wait())) from None
        except BaseException:       # stopped or interrupted: the child would run on, out of step with its replies
            self.close()
            raise
        if status == "error":
            line, cause = value
            raise ChildError(line) from cause
        return value

    @property
    def pid(self) -> int | None:
        """The child's process id (None before the first call)."""
        return self._process.pid if self._process is not None else None

    def close(self) -> None:
        """End the child (the next call starts a new one)."""
        atexit.unregister(self.close)
        process, self._process = self._process, None
        if process is not None:
            process.kill()
            process.wait()
            process.stdout.close()
            with contextlib.suppress(BrokenPipeError):     # a request the child did not read
                process.stdin.close()


def run(function: Callable, *args: Any, stop: threading.Event | None = None, quiet: bool = False) -> Any:
    """``function(*args)`` in a child of its own, ended after the call (see :meth:`Child.call`)."""
    child = Child(quiet)
    try:
        return child.call(function, *args, stop=stop)
    finally:
        child.close()


def _death(code: int) -> tuple[str, str | None]:
    """One line for a child that died with return code ``code`` (−N: killed by signal N), and the signal's name."""
    if code >= 0:
        return f"the process running it exited with status {code}", None
    number = -code
    try:
        name = signal.Signals(number).name
    except ValueError:
        name = f"signal {number}"
    hint = "; out of memory?" if number == signal.SIGKILL else ""
    return f"the process running it died of {name} ({signal.strsignal(number)}{hint})", name


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


def _portable(err: BaseException) -> BaseException | None:
    """``err`` where it survives pickling, else None (one whose ``__init__`` takes other arguments than its message)."""
    try:
        return pickle.loads(pickle.dumps(err))
    except Exception:  # whatever pickling raises: the line says it all
        return None


def _exit_with(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(1.0)
    os._exit(1)


def _without_api() -> None:
    """Import ngwear from this file's folder (its parent's ngwear), running its ``__init__`` only when used."""
    folder = Path(__file__).parent
    spec = importlib.util.spec_from_file_location(folder.name, folder / "__init__.py",
                                                  submodule_search_locations=[str(folder)])
    package = importlib.util.module_from_spec(spec)

    def load(name: str) -> Any:
        del package.__getattr__
        spec.loader.exec_module(package)
        return getattr(package, name)

    package.__getattr__ = load
    sys.modules[spec.name] = package


def _serve() -> None:
    """The child's loop: read a call, run it, write its outcome; until stdin closes."""
    replies = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_exit_with, args=(os.getppid(),), daemon=True).start()
    _without_api()
    requests = sys.stdin.buffer
    while True:
        try:
            request = _receive(requests)
        except EOFError:
            return
        try:
            function, args = pickle.loads(request)
            reply = pickle.dumps(("ok", function(*args)))
        except Exception as err:  # the call's own failure, as one line (and itself, where it pickles)
            reply = pickle.dumps(("error", (_line(err), _portable(err))))
        _send(replies, reply)


if __name__ == "__main__":
    _serve()
