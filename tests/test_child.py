"""The case process of a study's worker: a crash ends the call, not the caller; nothing is left behind."""
import ctypes
import os
import signal
import subprocess
import sys
import time

import psutil
import pytest
from conftest import ROOT

from ngwear.studies.child import Child, ChildError


@pytest.fixture
def child():
    child = Child()
    yield child
    child.close()


def test_calls_run_in_one_process_that_keeps_its_state(child):
    pid = child.call(os.getpid)
    assert pid != os.getpid() and child.call(os.getpid) == pid == child.pid
    assert child.call(os.write, 1, b"what C++ code prints\n") == 21, "fd 1 is not the reply channel"
    assert child.call(print, "what Python prints") is None and child.call(divmod, 7, 2) == (3, 1)
    with pytest.raises(ChildError, match=r"^ValueError: invalid literal for int\(\) with base 10: 'x'$"):
        child.call(int, "x")
    assert child.call(os.getpid) == pid, "an exception leaves the process alive"


@pytest.mark.parametrize("function, args, message", [
    (ctypes.string_at, (0,), "the process running it died of SIGSEGV (Segmentation fault)"),
    (os._exit, (3,), "the process running it exited with status 3"),
    (os.kill, ("self", signal.SIGKILL), "the process running it died of SIGKILL (Killed; out of memory?)"),
])
def test_a_death_is_one_line_and_the_next_call_gets_a_new_process(child, function, args, message):
    pid = child.call(os.getpid)
    args = tuple(pid if a == "self" else a for a in args)
    with pytest.raises(ChildError) as err:
        child.call(function, *args)
    assert str(err.value) == message and not psutil.pid_exists(pid)
    assert child.call(os.getpid) not in (pid, None)


def test_a_busy_child_ends_with_its_parent(tmp_path):
    script = ("import os, time\nfrom ngwear.studies.child import Child\nchild = Child()\n"
              "print(child.call(os.getpid), flush=True)\nchild.call(time.sleep, 600)\n")
    parent = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, cwd=ROOT,
                              env={**os.environ, "PYTHONPATH": str(ROOT)})
    try:
        pid = int(parent.stdout.readline())
        assert psutil.Process(pid).ppid() == parent.pid
    finally:
        parent.kill()
        parent.wait()
    deadline = time.monotonic() + 20
    while _alive(pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _alive(pid), "the orphaned child exited"


def _alive(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False
