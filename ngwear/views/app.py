"""``ngwear explore``: the explorer as a web app, served by Voilà on 127.0.0.1.

Voilà (optional extra ``ngwear[app]``) shows a notebook's outputs as a page, without its code,
and gives every page its own kernel, so that the same ipywidgets explorer as in Jupyter runs as an
app.  ngwear serves a one-cell notebook calling :func:`page` with the scene, and configures:

* its own template (``app_data/voila/templates/ngwear``): Voilà's lab template without the icon
  fonts and mermaid.js it loads from CDNs, so that the page needs nothing from the internet;
* its own kernel spec, this Python, whatever kernels the user has installed;
* a random token, as Jupyter's: the page, its API and websockets need it (in the printed URL; the
  page then keeps it in a cookie), unless ``token=""``;
* jupyter_server's checks of ``Host`` (127.0.0.1, localhost, and the hosts of ``origins``) and
  ``Origin`` (the ``Host``, or one of ``origins``: a reverse proxy's public address);
* the server's guards (:mod:`ngwear.views.app_server`): at most ``max_kernels`` kernels, a short
  life for kernels no page connects to, the end of the kernels of closed pages once idle for
  ``kernel_timeout`` seconds (Voilà would keep them, ~500 MB each, until the server stops), only
  the v1 kernel websocket protocol, SIGINT and SIGTERM always answered;
* one kernel preheated: Voilà runs the page's notebook before a page asks for it (import, solve,
  first render with its shader compilation), so that a page shows its first picture without waiting
  for them (``benchmarks/explore_browser.py``); the URL is printed once the first one is ready;
* the page's *save into* confined to ``folder``.
"""
from __future__ import annotations

import json
import logging
import os
import re
import shutil
import socket
import sys
import tempfile
import time
from pathlib import Path
from urllib.parse import urlsplit

from ..model.scene import Scene

DATA = Path(__file__).with_name("app_data")
KERNEL = "ngwear-explore"
DEFAULT_PORT = 8866
STOP_GRACE = 15.0


def page(scene: dict, folder: str, ready: str):
    """The app's page, run in the page's kernel: the explorer of ``scene`` (a scene's dict), saving into ``folder``.

    The page's *save into* stays inside ``folder``.  Touches the file ``ready`` when done (the server
    announces its URL once the first kernel is ready).
    """
    import ipywidgets as W

    from .explore import Explorer, RunError

    try:
        return Explorer(Scene.from_dict(scene)).widget(folder, confined=True)
    except RunError as err:
        return W.HTML(f"<b>ngwear explore</b>: the scene's run stopped at {err}")
    finally:
        Path(ready).touch()


def notebook(scene: Scene, folder: Path, ready: Path) -> dict:
    """The served notebook: one code cell calling :func:`page`."""
    code = f"from ngwear.views.app import page\n\npage({scene.to_dict()!r}, {str(folder)!r}, {str(ready)!r})"
    return {"cells": [{"cell_type": "code", "execution_count": None, "id": "page", "metadata": {},
                       "outputs": [], "source": code}],
            "metadata": {"kernelspec": {"name": KERNEL, "display_name": "ngwear", "language": "python"},
                         "language_info": {"name": "python"}},
            "nbformat": 4, "nbformat_minor": 5}


def free_port(requested: int | None) -> int:
    """``requested`` if it is free on 127.0.0.1 (else ``OSError``), or the first free port from 8866 on."""
    candidates = [requested] if requested is not None else range(DEFAULT_PORT, DEFAULT_PORT + 50)
    for port in candidates:
        with socket.socket() as probe:
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as the server will
            try:
                probe.bind(("127.0.0.1", port))
            except OSError:
                continue
            return port
    raise OSError(f"port {requested} is in use" if requested is not None else
                  f"no free port in {DEFAULT_PORT}-{DEFAULT_PORT + 49}")


def check_origin(origin: str) -> str:
    """``origin`` (``scheme://host[:port]``, as a browser sends it), or ``ValueError`` saying what is wrong."""
    parts = urlsplit(origin)
    if parts.scheme not in ("http", "https") or not parts.hostname or parts.path not in ("", "/") or \
            parts.query or parts.fragment or parts.username:
        raise ValueError(f"{origin!r} is not an origin: scheme://host[:port], e.g. https://ngwear.example.org")
    return f"{parts.scheme}://{parts.netloc.lower()}"


def serve(scene: Scene, *, port: int, folder: Path, token: str, kernel_timeout: int = 60, max_kernels: int = 4,
          origins: tuple[str, ...] = ()) -> int:
    """Serve the explorer of ``scene`` on http://127.0.0.1:``port``/ until Ctrl-C; returns the exit status.

    Parameters
    ----------
    token : str
        What the page's URL, API and websockets need (``""``: nothing, anyone who reaches the port
        may use the app).
    kernel_timeout, max_kernels : int
        Seconds after which the kernel of a closed page ends; most kernels at once.
    origins : tuple of str
        Further origins (and their hosts) served besides 127.0.0.1 and localhost: the public
        address of a reverse proxy, e.g. ``("https://ngwear.example.org",)``.
    """
    from .app_server import Server, stop_on_signals

    with tempfile.TemporaryDirectory(prefix="ngwear-explore-") as tmp:
        work = Path(tmp)
        spec = work / "kernels" / KERNEL
        spec.mkdir(parents=True)
        (spec / "kernel.json").write_text(json.dumps({
            "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
            "display_name": "ngwear", "language": "python"}))
        path, ready = work / f"{scene.name}.ipynb", work / "ready"
        path.write_text(json.dumps(notebook(scene, folder.resolve(), ready)))
        os.environ["JUPYTER_PATH"] = os.pathsep.join(
            [str(work), str(DATA), *filter(None, [os.environ.get("JUPYTER_PATH")])])
        logging.getLogger("tornado.access").setLevel(logging.ERROR)
        app = Server(config=_config(port, token, kernel_timeout, max_kernels, origins))
        app.initialize([str(path)])
        if token:
            for handler in (*logging.getLogger().handlers, *app.log.handlers, logging.lastResort):
                handler.addFilter(_Scrub(token))
        stop_on_signals(STOP_GRACE, cleanup=lambda: shutil.rmtree(work, ignore_errors=True))
        print(f"ngwear explore: {scene.name}: preparing the first page's kernel …", flush=True)
        url = f"http://127.0.0.1:{port}/" + (f"?token={token}" if token else "")
        _announce_when(ready, f"ngwear explore: {scene.name} at {url}")
        app.start()
        print("ngwear explore: stopped", flush=True)
    return 0


class _Scrub(logging.Filter):
    """Writes ``secret`` as ``[secret]`` in log records (tornado logs a failed request with its URL)."""

    def __init__(self, secret: str):
        super().__init__()
        self.secret = secret

    def filter(self, record: logging.LogRecord) -> bool:
        if record.exc_info and not record.exc_text:
            record.exc_text = logging.Formatter().formatException(record.exc_info)
        text = record.getMessage()
        if self.secret in text or self.secret in (record.exc_text or ""):
            record.msg, record.args = text.replace(self.secret, "[secret]"), None
            record.exc_text = record.exc_text and record.exc_text.replace(self.secret, "[secret]")
        return True


def _announce_when(ready: Path, line: str) -> None:
    """Print ``line`` on the server's loop as soon as the file ``ready`` exists (the preheated kernel is done)."""
    from tornado.ioloop import PeriodicCallback

    start = time.perf_counter()

    def check():
        if ready.exists():
            poll.stop()
            print(f"{line} (ready after {time.perf_counter() - start:.1f} s; Ctrl-C to stop)", flush=True)

    poll = PeriodicCallback(check, 100)
    poll.start()


def _config(port: int, token: str, kernel_timeout: int, max_kernels: int, origins: tuple[str, ...]):
    """Voilà's settings: 127.0.0.1, token, Host and Origin checks, our template, kernels, quiet logs."""
    from traitlets.config import Config

    from .app_server import AppKernelManager, log_request

    tornado = {"ws_ping_timeout": 30000, "log_function": log_request,
               "allow_remote_access": False, "local_hostnames": ["localhost", *(urlsplit(o).hostname for o in origins)],
               "allow_origin_pat": "|".join(re.escape(o) for o in origins)}
    return Config({
        "Voila": {"ip": "127.0.0.1", "port": port, "port_retries": 0, "open_browser": False, "token": token,
                  "log_level": "ERROR", "tornado_settings": tornado},
        "VoilaConfiguration": {"template": "ngwear", "preheat_kernel": True, "default_pool_size": 1,
                               "multi_kernel_manager_class": AppKernelManager,
                               "extension_denylist": ["@voila-dashboards/jupyterlab-preview"]},
        "AppKernelManager": {"max_kernels": max_kernels},
        "PasswordIdentityProvider": {"allow_password_change": False},  # it would write a Jupyter config file
        "MappingKernelManager": {"cull_idle_timeout": kernel_timeout,
                                 "cull_interval": max(1, min(10, kernel_timeout // 2))},
        "KernelManager": {"transport": "ipc"},
    })
