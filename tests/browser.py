"""Helpers of the browser tests and benchmark: servers on free ports, Debian's Chromium driven by Playwright.

Playwright cannot download its own browser here; it drives ``/usr/bin/chromium`` (``scripts/bootstrap.sh``
installs it).  Screenshots go to ``out/browser-artifacts/<test>/`` (kept as test artifacts).
"""
from __future__ import annotations

import base64
import io
import os
import re
import signal
import socket
import subprocess
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parents[1]
ARTIFACTS = ROOT / "out" / "browser-artifacts"
CHROMIUM = Path(os.environ.get("NGWEAR_CHROMIUM", "/usr/bin/chromium"))
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync"]
LOCAL = ("http://127.0.0.1", "ws://127.0.0.1", "blob:", "data:", "about:")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextmanager
def server(argv: list[str], port: int, log: Path, env: dict | None = None, timeout: float = 90, ready: str = ""):
    """Run ``argv`` (in its own process group) until it listens on ``port`` and has logged ``ready``.

    SIGINT stops it at the end (as Ctrl-C would).
    """
    with log.open("w") as out:
        process = subprocess.Popen(argv, stdout=out, stderr=subprocess.STDOUT, start_new_session=True,
                                   env=env, cwd=ROOT)
        try:
            deadline = time.monotonic() + timeout
            while not (_listening(port) and ready in log.read_text()):
                if process.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"{argv[:4]} did not listen on port {port}:\n{log.read_text()}")
                time.sleep(0.2)
            yield process
        finally:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGINT)
                try:
                    process.wait(30)
                except subprocess.TimeoutExpired:
                    os.killpg(process.pid, signal.SIGKILL)
                    process.wait()


def app_url(log: Path) -> str:
    """The URL (with its token) that ``ngwear explore`` printed into ``log``."""
    return re.search(r"at (http://127\.0\.0\.1:\d+/\S*)", log.read_text()).group(1)


def _listening(port: int) -> bool:
    with socket.socket() as s:
        return s.connect_ex(("127.0.0.1", port)) == 0


@contextmanager
def chromium(*flags: str):
    """A Playwright Chromium browser (Debian's) with further command-line ``flags``, closed at the end."""
    from playwright.sync_api import sync_playwright

    if not CHROMIUM.is_file():
        raise RuntimeError(f"{CHROMIUM} is missing: run scripts/bootstrap.sh as root (apt-get install chromium)")
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), args=[*CHROMIUM_FLAGS, *flags], headless=True)
        try:
            yield browser
        finally:
            browser.close()


class Watch:
    """Console errors, uncaught page errors and requests that leave 127.0.0.1, recorded on a page."""

    def __init__(self, page):
        self.errors, self.external = [], []
        page.on("console", lambda m: self.errors.append(f"console.{m.type}: {m.text}") if m.type == "error" else None)
        page.on("pageerror", lambda e: self.errors.append(f"page error: {e}"))
        page.on("request", lambda r: None if r.url.startswith(LOCAL) else self.external.append(r.url))


class Shots:
    """Numbered full-page screenshots in ``out/browser-artifacts/<name>/``; ``on_failure`` adds one when a block fails."""

    def __init__(self, name: str):
        self.folder = ARTIFACTS / name
        self.folder.mkdir(parents=True, exist_ok=True)
        for old in self.folder.glob("*.png"):
            old.unlink()
        self.count = 0
        print(f"screenshots: {self.folder}")

    def __call__(self, page, label: str) -> Path:
        self.count += 1
        path = self.folder / f"{self.count:02d}-{label}.png"
        page.screenshot(path=str(path), full_page=True)
        return path

    @contextmanager
    def on_failure(self, page):
        try:
            yield
        except BaseException:
            print(f"failed: see {self(page, 'failure')}")
            raise


IMAGE_JS = """async (selector) => {
    const img = document.querySelector(selector);
    const bytes = new Uint8Array(await (await fetch(img.src)).arrayBuffer());
    let text = ""; for (const b of bytes) text += String.fromCharCode(b);
    return btoa(text);
}"""


def image(page, selector: str) -> np.ndarray:
    """The RGB pixels of the ``<img>`` at ``selector``, from its source (not a screenshot)."""
    data = base64.b64decode(page.evaluate(IMAGE_JS, selector))
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))


def src(page, selector: str) -> str:
    return page.evaluate("(s) => { const i = document.querySelector(s); return i ? i.src : ''; }", selector)


def wait_for_new_image(page, selector: str, old_src: str, timeout: float = 60_000) -> None:
    """Until the ``<img>`` at ``selector`` shows a source other than ``old_src`` and has loaded it."""
    page.wait_for_function(
        """([s, old]) => { const i = document.querySelector(s);
                          return i && i.src && i.src !== old && i.complete && i.naturalWidth > 0; }""",
        arg=[selector, old_src], timeout=timeout)


def is_real_picture(pixels: np.ndarray) -> str | None:
    """Why ``pixels`` is not a real picture of the explorer (black, blank, noise), or None if it is one.

    A real picture has a white background, flat regions (neighbours mostly equal) and many colours.
    """
    white = (pixels == 255).all(axis=2).mean()
    flat = (pixels[:, 1:] == pixels[:, :-1]).all(axis=2).mean()
    colours = len(np.unique(pixels.reshape(-1, 3), axis=0))
    if not 0.15 < white < 0.95:
        return f"white background covers {white:.0%} (black or blank?)"
    if flat < 0.5:
        return f"only {flat:.0%} of neighbouring pixels are equal (noise?)"
    if colours < 50:
        return f"only {colours} colours"
    return None


def kernels_of(pid: int) -> list[int]:
    """Process ids of the ipykernel processes started by process ``pid``."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            cmdline = (stat.parent / "cmdline").read_bytes()
        except OSError:
            continue
        if int(fields[1]) == pid and fields[0] != "Z" and b"ipykernel" in cmdline:
            out.append(int(stat.parent.name))
    return out


def alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def wait_until(condition, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:.0f} s waiting until {what}")
        time.sleep(0.25)
