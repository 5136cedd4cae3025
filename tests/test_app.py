"""`ngwear explore` in a real browser: Debian's Chromium driven by Playwright against the Voilà app on 127.0.0.1.

The page shows the paper scene; keyboard slider moves give new pictures whose slider values are the
result's scene; the time slider scrubs; the saved scene re-run by `ngwear run` gives the saved
result's numbers; nothing is fetched from the internet and the console shows no error; the kernel
of a closed page ends, and Ctrl-C stops the server and its kernels.  Screenshots:
``out/browser-artifacts/test_app/``.
"""
import subprocess
import sys
import time
import tomllib

import numpy as np
import pytest
from browser import (
    Shots,
    Watch,
    alive,
    app_url,
    chromium,
    free_port,
    image,
    is_real_picture,
    kernels_of,
    server,
    src,
    wait_for_new_image,
    wait_until,
)
from conftest import PAPER
from PIL import Image

import ngwear
from ngwear.views.sliders import sliders_for

pytestmark = pytest.mark.browser
PICTURE, PLOTS = "img.ngwear-picture", "img.ngwear-plots"


def readouts(page, names) -> dict:
    return {n: float(page.inner_text(f".ngwear-slider-{n} .widget-readout")) for n in names}


def matches(shown: dict, scene) -> bool:
    """Slider readouts (3 significant digits) are the scene's values."""
    values = {s.name: s.value(scene) for s in sliders_for(scene)}
    return shown.keys() == values.keys() and all(
        abs(shown[n] - v) <= 0.006 * abs(v) + 1e-12 for n, v in values.items())


def press(page, slider: str, key: str) -> np.ndarray:
    """Press ``key`` on a slider's handle; the new picture once it is shown and the page is ready."""
    old = src(page, PICTURE)
    page.focus(f".ngwear-{slider} .noUi-handle")
    page.keyboard.press(key)
    wait_for_new_image(page, PICTURE, old)
    page.wait_for_function("() => document.querySelector('.ngwear-progress').textContent.includes('ready')")
    return image(page, PICTURE)


def click(page, button: str) -> str:
    """Click a save button; the path it reports."""
    old = page.inner_text(".ngwear-message")
    page.click(f"button.ngwear-{button}")
    page.wait_for_function("""(old) => { const text = document.querySelector('.ngwear-message').textContent;
                                         return text.includes('saved') && text !== old; }""", arg=old)
    return page.inner_text(".ngwear-message").split(": ", 1)[1].strip()


def test_explore_app_in_chromium(tmp_path):
    port, shots = free_port(), Shots("test_app")
    argv = [sys.executable, "-m", "ngwear.cli", "explore", str(PAPER), "--port", str(port),
            "--out", str(tmp_path / "saved"), "--kernel-timeout", "3"]
    with server(argv, port, tmp_path / "server.log", ready="?token=") as app, chromium() as browser:
        url = app_url(tmp_path / "server.log")
        page = browser.new_page(viewport={"width": 1280, "height": 1100})
        watch = Watch(page)
        with shots.on_failure(page):
            time.sleep(5)  # the preheated kernel idles past --kernel-timeout: it must not be culled once handed out
            page.goto(url)
            page.wait_for_function(f"() => {{ const i = document.querySelector('{PICTURE}');"
                                   " return i && i.complete && i.naturalWidth > 0; }", timeout=90_000)
            shots(page, "opened")
            first = image(page, PICTURE)
            assert is_real_picture(first) is None, is_real_picture(first)
            names = [s.name for s in sliders_for(ngwear.load_scene(PAPER))]
            assert matches(readouts(page, names), ngwear.load_scene(PAPER))
            status = page.query_selector(".ngwear-status")
            assert "max wear" in status.inner_text() and page.evaluate(
                "(e) => e.scrollWidth <= e.clientWidth && e.getBoundingClientRect().right <= window.innerWidth",
                status), "the status line is cut off"

            moved = press(page, "slider-load", "ArrowRight")
            moved = press(page, "slider-load", "ArrowRight")
            shots(page, "load-moved")
            assert is_real_picture(moved) is None and np.abs(moved.astype(int) - first).mean() > 0.5
            assert readouts(page, ["load"])["load"] == pytest.approx(0.11)

            scrubbed = press(page, "time", "Home")
            assert page.inner_text(".ngwear-time .widget-readout").strip() == "0"
            scrubbed_on = press(page, "time", "ArrowRight")
            shots(page, "scrubbed")
            assert np.abs(scrubbed.astype(int) - moved).mean() > 0.5 and not np.array_equal(scrubbed, scrubbed_on)

            saved = click(page, "save_scene")
            scene = ngwear.load_scene(saved)
            assert matches(readouts(page, names), scene) and scene.loads.traction["top"][1] == pytest.approx(-0.11)
            assert tomllib.loads(open(saved).read())["contact"]["wear"] == 1.5
            picture_file = click(page, "save_picture")
            assert np.array_equal(np.asarray(Image.open(picture_file).convert("RGB")),
                                  image(page, PICTURE))
            result_dir = click(page, "save_result")
            run = subprocess.run([sys.executable, "-m", "ngwear.cli", "run", saved, "--out", str(tmp_path / "run"),
                                  "--quiet"], capture_output=True, text=True)
            assert run.returncode == 0, run.stderr
            ours, theirs = np.load(f"{result_dir}/result.npz"), np.load(tmp_path / "run" / "result.npz")
            for name in ("wear", "normal_displacement", "pressure", "reaction"):
                assert np.allclose(ours[name], theirs[name], rtol=1e-9, atol=1e-13), name
            assert ours["wear"].max() > 0.1

            plots = image(page, PLOTS)
            page.click("button.ngwear-pin")
            page.wait_for_function("() => document.querySelector('.ngwear-status').textContent.includes('A/B')")
            press(page, "slider-speed", "ArrowRight")
            page.wait_for_function("() => document.querySelector('.ngwear-status').textContent"
                                   ".includes('B differs from A in speed 1 → 1.05')")
            shots(page, "a-b")
            assert np.abs(image(page, PLOTS).astype(int) - plots).mean() > 0.5

            assert not watch.errors, watch.errors
            assert not watch.external, f"requests leaving 127.0.0.1: {watch.external}"

        kernels = kernels_of(app.pid)
        assert len(kernels) == 2, "the page's kernel and one preheated for the next page"
        page.close()
        wait_until(lambda: len(kernels_of(app.pid)) == 1, 60, "the closed page's kernel has ended")

    assert app.returncode == 0 and "stopped" in (tmp_path / "server.log").read_text()
    assert not any(alive(pid) for pid in kernels), "Ctrl-C leaves no kernel running"
