"""`ngwear explore` without a browser: bad input is one line naming the field, the served page, signals."""
import json
import signal
import socket
import subprocess
import sys
import time
from importlib.util import find_spec

import pytest
from browser import alive
from conftest import PAPER, ROOT
from test_cli import assert_one_line_error, ngwear

import ngwear as ng
from ngwear.views import app

#: `ngwear explore` serves with Voilà, the optional extra ngwear[app]; the page itself needs only the core packages
needs_voila = pytest.mark.skipif(find_spec("voila") is None, reason="needs the app extra: pip install 'ngwear[app]'")
WITHOUT_VOILA = "import sys; sys.modules['voila'] = None; from ngwear.cli import main; sys.exit(main())"


@needs_voila
@pytest.mark.parametrize("args, field", [
    (["missing.toml"], "scene file"),
    ([PAPER, "--set", "contact.gap=-1"], "contact.gap"),
    ([PAPER, "--kernel-timeout", "0"], "--kernel-timeout"),
    ([PAPER, "--max-kernels", "0"], "--max-kernels"),
    ([PAPER, "--port", "99999"], "--port"),
    ([PAPER, "--allow-origin", "ngwear.example.org"], "--allow-origin"),
    ([PAPER, "--allow-origin", "https://ngwear.example.org/app"], "--allow-origin"),
])
def test_bad_input_is_one_line_naming_the_field(tmp_path, args, field):
    assert_one_line_error(ngwear("explore", *args, cwd=tmp_path), field)


@needs_voila
def test_a_busy_port_is_refused(tmp_path):
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        assert_one_line_error(ngwear("explore", PAPER, "--port", port, cwd=tmp_path), "--port")
        assert app.free_port(None) != port


def test_without_the_app_extra_explore_says_what_to_install(tmp_path):
    """Voilà hidden (as when ngwear[app] is not installed): one line naming the extra, status 2."""
    proc = subprocess.run([sys.executable, "-c", WITHOUT_VOILA, "explore", str(PAPER)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert_one_line_error(proc, "explore")
    assert "needs the optional packages of ngwear[app]" in proc.stderr
    assert "pip install 'ngwear[app]'" in proc.stderr


def test_the_served_notebook_calls_the_page_with_the_scene(tmp_path):
    scene = ng.load_scene(PAPER).replace(**{"mesh.maxh": 0.2, "time.steps": 20})
    notebook = app.notebook(scene, tmp_path / "saves", tmp_path / "ready")
    (cell,) = notebook["cells"]
    assert notebook["metadata"]["kernelspec"]["name"] == app.KERNEL and json.dumps(notebook)
    namespace = {}
    exec(compile(cell["source"].replace("page(", "box = page(", 1), "page", "exec"), namespace)
    assert (tmp_path / "ready").exists(), "the page tells the server it is ready"
    classes = {c for w in namespace["box"].children for c in getattr(w, "_dom_classes", ())}
    assert {"ngwear-picture", "ngwear-plots", "ngwear-time"} <= classes


def test_a_scene_whose_run_stops_gives_a_page_saying_so(tmp_path):
    scene = ng.load_scene(PAPER).replace(**{"mesh.maxh": 0.2, "time.steps": 20, "contact.stiffness": 1e8,
                                            "contact.wear": 5.0, "wear.allow_unstable": True})
    shown = app.page(scene.to_dict(), str(tmp_path), str(tmp_path / "ready"))
    assert "the scene's run stopped at step" in shown.value and (tmp_path / "ready").exists()


def test_origins_are_written_as_browsers_send_them():
    assert app.check_origin("https://NGwear.example.org") == "https://ngwear.example.org"
    assert app.check_origin("http://localhost:8080/") == "http://localhost:8080"
    for bad in ("ngwear.example.org", "ftp://x.org", "https://x.org/app", "https://user@x.org", "https://"):
        with pytest.raises(ValueError, match="is not an origin"):
            app.check_origin(bad)


BLOCKED = """
import subprocess, sys, time
from tornado.ioloop import IOLoop
from ngwear.views.app_server import stop_on_signals

child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
print(child.pid, flush=True)
stop_on_signals(1.0, cleanup=lambda: print("cleaned up", flush=True))
if sys.argv[1] == "blocked":
    IOLoop.current().add_callback(time.sleep, 600)  # a handler that never returns
IOLoop.current().start()
child.kill()
print("loop stopped", flush=True)
"""


@needs_voila
@pytest.mark.parametrize("loop", ["free", "blocked"])
def test_sigterm_stops_the_server_even_if_its_loop_is_blocked(loop):
    process = subprocess.Popen([sys.executable, "-c", BLOCKED, loop], cwd=ROOT, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    child = int(process.stdout.readline())
    time.sleep(0.5)  # the loop runs (or is blocked)
    process.send_signal(signal.SIGTERM)
    out, err = process.communicate(timeout=30)
    assert "SIGTERM: stopping" in out and not alive(child)
    if loop == "free":
        assert process.returncode == 0 and "loop stopped" in out and err == ""
    else:
        assert process.returncode == 1 and "cleaned up" in out and "loop stopped" not in out
        assert err.strip() == "ngwear explore: not stopped after 1 s: killing its kernels"
