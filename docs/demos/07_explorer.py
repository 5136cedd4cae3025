r"""
The explorer: sliders, a picture, A/B comparisons
=================================================

The explorer keeps a scene, its discretization and its last run.  Moving a slider changes one scene key (or
scales the load or the speed), runs the scene again — reusing the mesh and the factorisation whenever the key
allows: friction :math:`\mu`, wear :math:`\kappa`, layer :math:`g`, speed and load change nothing that is
factorised — and redraws.  The same object drives the web app (``ngwear explore``), the notebook
(``notebooks/explore.ipynb``) and scripts.  Here: the paper's scene at a coarser resolution, more friction, a
pinned run A against a faster foundation B, and the app's page as Chromium shows it.
"""

# %%
from pathlib import Path

import ngwear
from ngwear.model.examples import scene_file

out = Path("out") / "explorer"
scene = ngwear.load_scene(scene_file("paper_strip"))
explorer = ngwear.Explorer(scene, maxh=0.1, steps=50)
print("sliders:", ", ".join(f"{name} = {value:g}" for name, value in explorer.values.items()))
explorer.set(friction=0.5)
print(explorer.summary())
explorer.save_picture(out / "picture.png")

# %%
# The time slider scrubs through the run (no new solve); *pin as A* keeps the run on show, and the plots then
# compare every later run B with it: the dashed lines are A, the lowest panel the difference of the wear
# :math:`w_B - w_A` along :math:`\Gamma_C`.
explorer.scrub(25)
explorer.pin()
explorer.set(speed=1.5)
explorer.scrub(-1)
print(explorer.summary())
from PIL import Image

Image.fromarray(explorer.plots()).save(out / "a_b.png")

# %%
# The run on show is an ordinary result: the same numbers as :func:`ngwear.simulate` of the same scene.
direct = ngwear.simulate(explorer.scene, progress=False)
print(f"worn area {explorer.result.wear_volume[-1]:.12g} in the explorer, {direct.wear_volume[-1]:.12g} run directly")

# %%
# The app: ``ngwear explore`` serves these widgets as a web page on 127.0.0.1 (one kernel per page, from Voilà),
# behind a token it prints in its URL.  This screenshot is taken while the documentation is built, with the same
# Chromium and Playwright as the browser tests (``tests/test_app.py``): the page of the paper's scene once its
# first picture is shown.
import signal
import socket
import subprocess
import sys

from playwright.sync_api import sync_playwright

with socket.socket() as probe:
    probe.bind(("127.0.0.1", 0))
    port = probe.getsockname()[1]
app = subprocess.Popen([sys.executable, "-m", "ngwear.cli", "explore", str(scene_file("paper_strip")), "--port",
                        str(port), "--out", str(out / "saved")], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                       text=True)
try:
    for line in app.stdout:                 # the URL, with the page's token, is printed once the first kernel is ready
        if "http://127.0.0.1" in line:
            url = next(word for word in line.split() if word.startswith("http://127.0.0.1"))
            break
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=[
            "--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update"])
        page = browser.new_page(viewport={"width": 1100, "height": 900})
        page.goto(url)
        page.wait_for_function("() => { const i = document.querySelector('img.ngwear-picture');"
                               " return i && i.complete && i.naturalWidth > 0; }", timeout=120_000)
        page.screenshot(path=str(out / "app.png"), full_page=True)
        browser.close()
finally:
    app.send_signal(signal.SIGINT)                           # Ctrl-C: the server stops its kernels
    app.wait(60)
