"""The server of ``ngwear explore``: Voilà with guards for a server that others may reach.

Voilà (with jupyter_server's token, ``Host`` and ``Origin`` checks, configured in
:mod:`ngwear.views.app`) serves the page, its kernel API and websockets; :class:`Server` swaps
three of its handlers for guarded ones and :class:`AppKernelManager` bounds the kernels:

* :class:`Page`: the page refuses a foreign ``Origin`` (jupyter_server checks it only for websockets
  and writes) and answers "busy" (503) instead of starting a kernel beyond ``max_kernels``;
* :class:`KernelSocket`: only the v1 kernel protocol (``v1.kernel.websocket.jupyter.org``, what
  Voilà's page speaks), every frame checked before it is parsed, at most 32 MB waiting for a client
  that does not read, at most ``BURST`` messages at once and ``RATE`` a second from a client (a
  page sends a few, one per slider move; each ``request_states`` is answered with every widget's
  state, ~0.3 MB, which jupyter_server keeps for a client that has gone until it reconnects).
  Voilà reads the header of every binary frame it sends as a v1 frame: a legacy-protocol frame
  (one with buffers, as the widgets' state with its pictures) has 2⁶⁰ as its offset count there,
  and building that list blocked the server and grew it without bound; jupyter_server parses the
  frames it receives the same way, and takes a closing connection for a legacy one;
* :class:`RequestInfo`: Voilà's request-info socket (it sends a page's query string, token
  included, to whoever names the kernel's id, which ``ps`` shows) needs the token like the rest;
* :class:`AppKernelManager`: at most ``max_kernels`` kernels (the preheated one included); a kernel
  handed to a page that never connects ends after ``unopened_timeout`` seconds (a page connects
  within seconds of its HTML), one whose page has gone after the culling timeout.

* :class:`TemplateFiles`: Voilà's template files, a path that leaves them refused (404) before Voilà's handler,
  which failed on it (500, a traceback in the log).

:func:`stop_on_signals`: SIGINT and SIGTERM always stop the server, by force if it does not stop.
"""
from __future__ import annotations

import asyncio
import os
import signal
import threading
import time
import uuid

import psutil
from jupyter_server.auth.decorator import ws_authenticated
from jupyter_server.base.handlers import JupyterHandler
from jupyter_server.base.websocket import WebSocketMixin
from jupyter_server.log import log_request as jupyter_log_request
from jupyter_server.services.kernels.kernelmanager import AsyncMappingKernelManager
from tornado import web
from tornado.iostream import StreamBufferFullError
from traitlets import Float, Integer
from voila.app import Voila
from voila.request_info_handler import RequestInfoSocketHandler
from voila.static_file_handler import TemplateStaticFileHandler
from voila.tornado.handler import TornadoVoilaHandler
from voila.tornado.kernel_websocket_handler import VoilaKernelWebsocketHandler

V1 = "v1.kernel.websocket.jupyter.org"
WRITE_BUFFER = 32 * 2**20
BURST, RATE = 100, 20.0  # messages a client may send at once, and per second after that


class AppKernelManager(AsyncMappingKernelManager):
    """Jupyter's kernel manager with a cap on the kernels and a short life for kernels never connected to."""

    max_kernels = Integer(4, config=True, help="most kernels at once, the preheated one included")
    unopened_timeout = Float(20.0, config=True, help="end a page's kernel that no page has connected to [s]")

    def __init__(self, **kw):
        super().__init__(**kw)
        self._claimed, self._unopened, self._starting = set(), {}, {}
        self._stopping = False

    def kernels(self) -> int:
        """Kernels running or starting."""
        return len(set(self._kernels) | set(self._starting))

    def busy(self) -> bool:
        """Whether a new page would wait for a kernel: all ``max_kernels`` taken, none of them a spare."""
        spares = sum(task.done() and not task.cancelled() and task.exception() is None
                     for pool in getattr(self, "_pools", {}).values() for task in pool)
        return self.kernels() >= self.max_kernels and not (spares or any(self._starting.values()))

    async def start_kernel(self, *, kernel_id=None, **kwargs):
        """Start a kernel within the cap: a spare waits for a free slot, a page's kernel beyond it is refused."""
        spare = kwargs.get("env", {}).get("VOILA_PREHEAT") == "True"
        while spare and self.kernels() >= self.max_kernels and not self._stopping:
            await asyncio.sleep(0.5)
        if self._stopping:
            raise RuntimeError("the server is stopping")
        if self.kernels() >= self.max_kernels:
            raise web.HTTPError(503, reason=busy_text(self.max_kernels))
        kernel_id = kernel_id or str(uuid.uuid4())
        self._starting[kernel_id] = spare
        try:
            return await super().start_kernel(kernel_id=kernel_id, **kwargs)
        finally:
            del self._starting[kernel_id]

    def notify_connect(self, kernel_id):
        super().notify_connect(kernel_id)
        self._claimed.add(kernel_id)

    async def cull_kernel_if_idle(self, kernel_id):
        """Cull as Jupyter does a kernel a page has connected to; end one never connected to after a short while.

        Voilà's manager does not call this for its preheated spare.
        """
        if kernel_id in self._claimed:
            return await super().cull_kernel_if_idle(kernel_id)
        seen = self._unopened.setdefault(kernel_id, time.monotonic())
        if time.monotonic() - seen > self.unopened_timeout:
            self.log.warning("ending kernel %s: no page connected to it", kernel_id)
            await self.shutdown_kernel(kernel_id)

    async def shutdown_kernel(self, kernel_id, *args, **kwargs):
        self._claimed.discard(kernel_id)
        self._unopened.pop(kernel_id, None)
        return await super().shutdown_kernel(kernel_id, *args, **kwargs)

    async def shutdown_all(self, *args, **kwargs):
        self._stopping = True
        return await super().shutdown_all(*args, **kwargs)


def busy_text(max_kernels: int) -> str:
    return (f"ngwear explore is busy: {max_kernels} kernel{'s' * (max_kernels > 1)} in use (--max-kernels). "
            "Close a page, or try again once a closed page's kernel has ended (--kernel-timeout)")


class Page(TornadoVoilaHandler):
    """The page: a foreign ``Origin`` refused, "busy" instead of a kernel beyond the cap."""

    @web.authenticated
    async def get(self, path=None):
        if not self.check_origin():
            raise web.HTTPError(403, reason="Origin not allowed")
        if self.kernel_manager.busy():
            self.set_header("Retry-After", "30")
            raise web.HTTPError(503, reason=busy_text(self.kernel_manager.max_kernels))
        await super().get(path)


def log_request(handler) -> None:
    """jupyter_server's request log (it scrubs tokens from URLs); a page refused as busy in one line."""
    if handler.get_status() == 503:
        handler.log.warning("busy: refused a page from %s", handler.request.remote_ip)
    else:
        jupyter_log_request(handler)


def is_v1_frame(message) -> bool:
    """Whether ``message`` is a binary v1 kernel frame whose offsets fit in it.

    A frame is ``n`` (8 bytes, little-endian), ``n`` offsets of 8 bytes, then the parts between
    consecutive offsets: the channel, header, parent header, metadata, content and buffers.
    """
    if not isinstance(message, bytes) or len(message) < 8:
        return False
    n = int.from_bytes(message[:8], "little")
    if not 6 <= n <= len(message) // 8 - 1:
        return False
    offsets = [int.from_bytes(message[8 * i:8 * i + 8], "little") for i in range(1, n + 1)]
    return 8 * (n + 1) <= offsets[0] and all(a <= b for a, b in zip(offsets, offsets[1:])) and \
        offsets[-1] <= len(message)


class _PlainErrors:
    """A refused websocket handshake answered in one line (Voilà's server has no page template for it)."""

    def write_error(self, status_code: int, **kwargs) -> None:
        self.set_header("Content-Type", "text/plain; charset=utf-8")
        self.finish(f"{status_code}: {self._reason}\n")


class KernelSocket(_PlainErrors, VoilaKernelWebsocketHandler):
    """The kernel websocket: v1 protocol only, frames checked, bounded output and input."""

    async def pre_get(self):
        offered = [p.strip() for p in self.request.headers.get("Sec-WebSocket-Protocol", "").split(",")]
        if V1 not in offered:
            raise web.HTTPError(400, reason=f"only the {V1} websocket protocol is served")
        await super().pre_get()

    async def open(self, kernel_id):
        self.ws_connection.stream.max_write_buffer_size = WRITE_BUFFER
        self._allowance, self._last = float(BURST), time.monotonic()
        await super().open(kernel_id)

    def on_message(self, message):
        if self.ws_connection is None or self.ws_connection.is_closing():
            return None  # once closing, jupyter_server would parse it as a legacy frame
        now = time.monotonic()
        self._allowance = min(BURST, self._allowance + RATE * (now - self._last)) - 1
        self._last = now
        if not is_v1_frame(message):
            self._refuse(1003, "a frame that is not a v1 kernel message")
        elif self._allowance < 0:
            self._refuse(1008, f"more than {BURST} messages at once or {RATE:g} a second")
        else:
            super().on_message(message)

    def write_message(self, message, binary=False):
        if self.ws_connection is None or self.ws_connection.is_closing():
            return None  # once closing, jupyter_server takes the protocol for the legacy one, and Voilà misreads it
        try:
            sent = super().write_message(message, binary)
        except StreamBufferFullError:
            return self._refuse(1008, f"its client does not read ({WRITE_BUFFER // 2**20} MB waiting)")
        if sent is not None:  # a closed connection fails every pending write: nothing to report
            sent.add_done_callback(lambda done: done.cancelled() or done.exception())
        return sent

    def _refuse(self, code: int, why: str) -> None:
        self.log.warning("closing the websocket of kernel %s: %s", self.kernel_id, why)
        self.close(code, why[:120])


class RequestInfo(_PlainErrors, WebSocketMixin, RequestInfoSocketHandler, JupyterHandler):
    """Voilà's request-info socket, for authenticated pages only."""

    def set_default_headers(self):
        """No page headers on a websocket (as jupyter_server's kernel websocket)."""

    @ws_authenticated
    async def get(self, *args, **kwargs):
        await super().get(*args, **kwargs)


class TemplateFiles(TemplateStaticFileHandler):
    """Voilà's template files, ``/voila/templates/<name>/static/<path>``: a path that leaves them is 404.

    Voilà's handler takes the path apart only after normalising it, so ``..%2f..`` failed inside it (500, with
    a traceback in the log).
    """

    def parse_url_path(self, path):
        parts = path.split("/")
        if len(parts) < 3 or parts[1] != "static" or any(part in ("", ".", "..") for part in parts):
            raise web.HTTPError(404)
        return super().parse_url_path(path)


class Server(Voila):
    """Voilà with the guarded page, kernel websocket, request-info socket and template files."""

    def init_handlers(self):
        guarded = {TornadoVoilaHandler: Page, VoilaKernelWebsocketHandler: KernelSocket,
                   RequestInfoSocketHandler: RequestInfo, TemplateStaticFileHandler: TemplateFiles}
        return [(route[0], guarded.get(route[1], route[1]), *route[2:]) for route in super().init_handlers()]


def stop_on_signals(grace: float, cleanup=None) -> None:
    """On SIGINT or SIGTERM stop the current event loop (the server then shuts its kernels down).

    If the process still runs ``grace`` seconds later (a handler or a kernel hangs), or on a second
    signal, its child processes (the kernels) are killed, ``cleanup()`` is called and it exits with
    status 1.  Python runs the handler between two bytecodes even while the loop is blocked.
    """
    from tornado.ioloop import IOLoop

    loop = IOLoop.current().asyncio_loop  # the loop Voilà's server runs on
    timer = None

    def force():
        os.write(2, f"ngwear explore: not stopped after {grace:g} s: killing its kernels\n".encode())
        for child in psutil.Process().children(recursive=True):
            try:
                child.kill()
            except psutil.NoSuchProcess:
                pass
        if cleanup is not None:
            cleanup()
        os._exit(1)

    def on_signal(signum, frame):
        nonlocal timer
        if timer is not None:
            timer.cancel()
            force()
        os.write(1, f"ngwear explore: {signal.Signals(signum).name}: stopping …\n".encode())
        loop.call_soon_threadsafe(loop.stop)
        timer = threading.Timer(grace, force)
        timer.daemon = True
        timer.start()

    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, on_signal)
