"""`ngwear explore` without a browser: bad input is one line naming the field, and the served page itself."""
import json
import socket

import pytest
from conftest import PAPER
from test_cli import assert_one_line_error, ngwear

import ngwear as ng
from ngwear.views import app


@pytest.mark.parametrize("args, field", [
    (["missing.toml"], "scene file"),
    ([PAPER, "--set", "contact.gap=-1"], "contact.gap"),
    ([PAPER, "--kernel-timeout", "0"], "--kernel-timeout"),
])
def test_bad_input_is_one_line_naming_the_field(tmp_path, args, field):
    assert_one_line_error(ngwear("explore", *args, cwd=tmp_path), field)


def test_a_busy_port_is_refused(tmp_path):
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        assert_one_line_error(ngwear("explore", PAPER, "--port", port, cwd=tmp_path), "--port")
        assert app.free_port(None) != port


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
                                            "contact.wear": 5.0})
    shown = app.page(scene.to_dict(), str(tmp_path), str(tmp_path / "ready"))
    assert "the scene's run stopped at step" in shown.value and (tmp_path / "ready").exists()
