"""A study's case process, a part file's reader, a mesher: a crash or a stop ends the call, not the caller; none is left."""
import ctypes
import os
import signal
import subprocess
import sys
import threading
import time

import psutil
import pytest
from conftest import ROOT

import ngwear
from ngwear.child import Child, ChildError, ChildStopped
from ngwear.model import part_files


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
    with pytest.raises(ChildError, match=r"^ValueError: invalid literal for int\(\) with base 10: 'x'$") as err:
        child.call(int, "x")
    assert isinstance(err.value.__cause__, ValueError) and err.value.signal is None
    assert child.call(os.getpid) == pid, "an exception leaves the process alive"
    assert child.call(os.kill, pid, signal.SIGINT) is None and child.call(os.getpid) == pid, "SIGINT is ignored"


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
    assert err.value.signal == {ctypes.string_at: "SIGSEGV", os._exit: None, os.kill: "SIGKILL"}[function]
    assert child.call(os.getpid) not in (pid, None)


def test_a_set_stop_kills_the_child_at_once(child):
    pid, stop = child.call(os.getpid), threading.Event()
    threading.Timer(0.3, stop.set).start()
    start = time.monotonic()
    with pytest.raises(ChildStopped):
        child.call(time.sleep, 600, stop=stop)
    assert time.monotonic() - start < 3 and not _alive(pid) and child.pid is None


def test_an_interrupt_of_the_caller_kills_the_child(child):
    pid = child.call(os.getpid)
    threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT)).start()
    with pytest.raises(KeyboardInterrupt):
        child.call(time.sleep, 600)
    assert not _alive(pid) and child.pid is None


def test_a_child_imports_the_modules_its_calls_name_and_ngwear_api_on_use(child):
    loaded = "sorted(m for m in __import__('sys').modules if m.startswith(('ngwear', 'ngsolve')))"
    assert child.call(part_files._listed, ["pad"]) == ("body", "pad")
    assert child.call(eval, loaded) == ["ngwear", "ngwear.child", "ngwear.model", "ngwear.model.part_files"]
    assert child.call(eval, "__import__('ngwear').__version__") == ngwear.__version__
    assert "ngsolve" not in child.call(eval, loaded)
    assert child.call(eval, "__import__('ngwear').simulate.__name__") == "simulate"
    assert {"ngwear.runs.simulate", "ngsolve"} <= set(child.call(eval, loaded))


def test_what_a_child_prints_goes_to_stderr_or_nowhere_when_quiet():
    script = ("import os\nfrom ngwear.child import Child, run\nChild().call(print, 'loud')\n"
              "run(os.write, 1, b'quiet', quiet=True)\nrun(os.write, 2, b'quiet', quiet=True)\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert (done.returncode, done.stdout, done.stderr) == (0, "", "loud\n")


def test_a_busy_child_ends_with_its_parent(tmp_path):
    script = ("import os, time\nfrom ngwear.child import Child\nchild = Child()\n"
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
