"""``ngwear explore``: the explorer as a web app, served by Voilà on 127.0.0.1.

Voilà (optional extra ``ngwear[app]``) shows a notebook's outputs as a page, without its code,
and gives every page its own kernel, so that the same ipywidgets explorer as in Jupyter runs as an
app.  ngwear serves a one-cell notebook calling :func:`page` with the scene, and configures:

* its own template (``app_data/voila/templates/ngwear``): Voilà's lab template without the icon
  fonts and mermaid.js it loads from CDNs, so that the page needs nothing from the internet;
* its own kernel spec, this Python, whatever kernels the user has installed;
* the end of the kernels of closed pages: a kernel whose page has gone and that has been idle for
  ``kernel_timeout`` seconds is shut down (Voilà would keep it, ~500 MB, until the server stops);
* one kernel preheated: Voilà runs the page's notebook before a page asks for it (import, solve,
  first render with its shader compilation), so that a page shows its first picture in about two
  seconds; the URL is printed once the first one is ready;
* Ctrl-C (or SIGTERM) stops the server and shuts its kernels down.
"""
from __future__ import annotations

import json
import logging
import os
import socket
import sys
import tempfile
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

from ..model.scene import Scene

DATA = Path(__file__).with_name("app_data")
KERNEL = "ngwear-explore"
DEFAULT_PORT = 8866


def page(scene: dict, folder: str, ready: str):
    """The app's page, run in the page's kernel: the explorer of ``scene`` (a scene's dict), saving into ``folder``.

    Touches the file ``ready`` when done (the server announces its URL once the first kernel is ready).
    """
    import ipywidgets as W

    from .explore import Explorer, RunError

    try:
        return Explorer(Scene.from_dict(scene)).widget(folder)
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


def serve(scene: Scene, *, port: int, folder: Path, kernel_timeout: int = 60) -> int:
    """Serve the explorer of ``scene`` on http://127.0.0.1:``port``/ until Ctrl-C; returns the exit status."""
    from voila.app import Voila

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
        app = Voila(config=_config(port, kernel_timeout))
        app.initialize([str(path)])
        print(f"ngwear explore: {scene.name}: preparing the first page's kernel …", flush=True)
        _announce_when(ready, f"ngwear explore: {scene.name} at http://127.0.0.1:{port}/")
        app.start()
        print("ngwear explore: stopped", flush=True)
    return 0


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


def _kernel_manager():
    """Jupyter's kernel manager, culling a kernel only once a page has connected to it (or after 5 min without).

    A page gets a preheated kernel that may have been idle longer than the culling timeout; the
    culler would otherwise end it in the second between the page's HTML and its websocket.
    """
    from jupyter_server.services.kernels.kernelmanager import AsyncMappingKernelManager

    class KernelManager(AsyncMappingKernelManager):
        def __init__(self, **kw):
            super().__init__(**kw)
            self._claimed = set()

        def notify_connect(self, kernel_id):
            super().notify_connect(kernel_id)
            self._claimed.add(kernel_id)

        async def cull_kernel_if_idle(self, kernel_id):
            idle = datetime.now(timezone.utc) - self._kernels[kernel_id].last_activity
            if kernel_id in self._claimed or idle > timedelta(seconds=max(300, self.cull_idle_timeout)):
                await super().cull_kernel_if_idle(kernel_id)

    return KernelManager


def _config(port: int, kernel_timeout: int):
    """Voilà's settings: 127.0.0.1, our template, one preheated kernel, culling, quiet logs."""
    from traitlets.config import Config

    return Config({
        "Voila": {"ip": "127.0.0.1", "port": port, "port_retries": 0, "open_browser": False,
                  "log_level": "ERROR", "tornado_settings": {"ws_ping_timeout": 30000}},
        "VoilaConfiguration": {"template": "ngwear", "preheat_kernel": True, "default_pool_size": 1,
                               "multi_kernel_manager_class": _kernel_manager(),
                               "extension_denylist": ["@voila-dashboards/jupyterlab-preview"]},
        "MappingKernelManager": {"cull_idle_timeout": kernel_timeout,
                                 "cull_interval": max(1, min(10, kernel_timeout // 2))},
        "KernelManager": {"transport": "ipc"},
    })
