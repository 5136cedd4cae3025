"""`notebooks/explore.ipynb` in JupyterLab with its default settings, in Debian's Chromium (Playwright).

JupyterLab 4.6 sends widget messages to kernel subshells (``commsOverSubshells: "perCommTarget"``),
so the explorer's callbacks run on a thread other than the one that ran the notebook's cells; the
pictures must stay real pictures (not black, not noise) and follow every slider move and scrub.
JupyterLab runs in a temporary copy of ``notebooks/`` (beside ``geometries/``) with its own
config, data, settings and workspace folders, so neither the user's settings nor the repository's
notebook are touched.  Screenshots: ``out/browser-artifacts/test_jupyterlab/``.
"""
import json
import os
import shutil
import sys

import numpy as np
import pytest
from browser import Shots, Watch, chromium, free_port, image, is_real_picture, server, src, wait_for_new_image
from conftest import ROOT
from jupyter_client import BlockingKernelClient

pytestmark = pytest.mark.browser
PICTURE = "img.ngwear-picture"


def lab(tmp_path, port):
    shutil.copytree(ROOT / "notebooks", tmp_path / "notebooks", ignore=shutil.ignore_patterns(".ipynb_checkpoints"))
    (tmp_path / "geometries").symlink_to(ROOT / "geometries")
    dirs = {name: tmp_path / "jupyter" / name for name in ("config", "data", "runtime", "settings", "workspaces")}
    env = dict(os.environ, JUPYTER_CONFIG_DIR=str(dirs["config"]), JUPYTER_DATA_DIR=str(dirs["data"]),
               JUPYTER_RUNTIME_DIR=str(dirs["runtime"]), JUPYTERLAB_SETTINGS_DIR=str(dirs["settings"]),
               JUPYTERLAB_WORKSPACES_DIR=str(dirs["workspaces"]), NGWEAR_NOTEBOOK_QUICK="1")
    env.pop("JUPYTER_PATH", None)
    argv = [sys.executable, "-m", "jupyterlab", "--no-browser", "--ServerApp.ip=127.0.0.1", f"--ServerApp.port={port}",
            "--ServerApp.port_retries=0", "--IdentityProvider.token=", "--ServerApp.allow_root=True",
            f"--ServerApp.root_dir={tmp_path}"]
    return argv, env, dirs["runtime"]


def kernel(runtime) -> BlockingKernelClient:
    """A client of the notebook's kernel (its connection file is in the runtime folder)."""
    files = sorted(runtime.glob("kernel-*.json"))
    assert len(files) == 1, files
    client = BlockingKernelClient()
    client.load_connection_info(json.loads(files[0].read_text()))
    client.start_channels()
    client.wait_for_ready(timeout=30)
    return client


def evaluate(client, expression: str):
    """The value of a JSON-able ``expression`` in the kernel (run on its main shell)."""
    reply = client.execute_interactive(f"import json as _json\nprint(_json.dumps({expression}))", timeout=30,
                                       output_hook=lambda msg: printed.append(msg), store_history=False)
    assert reply["content"]["status"] == "ok", reply
    text = "".join(m["content"].get("text", "") for m in printed if m["msg_type"] == "stream")
    printed.clear()
    return json.loads(text)


printed = []


def test_explorer_notebook_in_jupyterlab(tmp_path):
    port, shots = free_port(), Shots("test_jupyterlab")
    argv, env, runtime = lab(tmp_path, port)
    with server(argv, port, tmp_path / "lab.log", env=env), chromium() as browser:
        page = browser.new_page(viewport={"width": 1400, "height": 1200})
        watch = Watch(page)
        with shots.on_failure(page):
            page.goto(f"http://127.0.0.1:{port}/lab/tree/notebooks/explore.ipynb")
            page.wait_for_selector(".jp-Notebook .jp-Cell", timeout=90_000)
            page.wait_for_function(  # the kernel is connected and idle (the cell toolbar says idle earlier)
                "() => document.querySelector('#jp-main-statusbar').textContent.includes('(ipykernel) | Idle')",
                timeout=90_000)
            page.get_by_role("menuitem", name="Run", exact=True).click()
            page.get_by_role("menuitem", name="Run All Cells", exact=True).click()
            page.wait_for_function("() => document.body.textContent.includes('new factorisation: False')", timeout=120_000)
            page.wait_for_function(f"() => {{ const i = document.querySelector('{PICTURE}');"
                                   " return i && i.complete && i.naturalWidth > 0; }", timeout=60_000)
            page.locator(PICTURE).scroll_into_view_if_needed()
            shots(page, "run-all")
            assert page.inner_text(".ngwear-slider-speed .widget-readout").strip() == "2.00", "explorer.set moved it"

            client = kernel(runtime)
            pictures = [image(page, PICTURE)]
            for slider, key in (("slider-load", "ArrowRight"), ("slider-wear", "ArrowLeft"), ("slider-friction", "End"),
                                ("time", "Home"), ("time", "ArrowRight"), ("time", "End"), ("slider-load", "ArrowRight")):
                old = src(page, PICTURE)
                page.focus(f".ngwear-{slider} .noUi-handle")
                page.keyboard.press(key)
                wait_for_new_image(page, PICTURE, old)
                page.wait_for_function("() => document.querySelector('.ngwear-progress').textContent.includes('ready')")
                pictures.append(image(page, PICTURE))
                assert is_real_picture(pictures[-1]) is None, f"after {key} on {slider}: {is_real_picture(pictures[-1])}"
                assert np.abs(pictures[-1].astype(int) - pictures[-2]).mean() > 0.2, f"{key} on {slider} changed nothing"
            shots(page, "moved-and-scrubbed")

            state = evaluate(client, "{'values': explorer.values, 'step': explorer.step, "
                                     "'completed': explorer.result.completed, "
                                     "'threads': [t.name for t in __import__('threading').enumerate()]}")
            shown = {name: float(page.inner_text(f".ngwear-slider-{name} .widget-readout"))
                     for name in ("load", "speed", "wear", "friction", "gap", "steps")}
            assert shown == pytest.approx(state["values"], rel=6e-3) and state["completed"]
            assert state["values"]["friction"] == 2.0 and state["step"] == state["values"]["steps"]
            assert any(name.startswith("subshell-") for name in state["threads"]), \
                f"widget messages ran on the main shell, not a subshell: {state['threads']}"
            kernel_picture = np.array(evaluate(client, "explorer.picture().tolist()"), dtype=np.uint8)
            assert np.array_equal(kernel_picture, pictures[-1]), "the page shows the kernel's picture"
            client.stop_channels()
            assert not watch.errors, watch.errors
            assert not watch.external, f"requests leaving 127.0.0.1: {watch.external}"
