"""`ngwear explore` is a server others may reach: only its token, host and origin, saves only into its folder.

Neither a misbehaving websocket client nor a crowd of plain requests can grow the server or block it.

Requests are made as an attacker would make them (``http.client`` with any ``Host`` and ``Origin``, websocket
clients that speak another protocol or read nothing); the page and its *save into* field in Debian's Chromium.
Screenshots: ``out/browser-artifacts/test_app_server/``.
"""
import base64
import http.client
import json
import os
import re
import signal
import socket
import sys
import time
import uuid
from pathlib import Path

import pytest
from browser import Shots, alive, app_url, chromium, free_port, kernels_of, server, wait_until
from conftest import PAPER

websockets = pytest.importorskip("websockets.sync.client")
from websockets.exceptions import ConnectionClosed, InvalidStatus  # noqa: E402

pytestmark = pytest.mark.browser
V1 = "v1.kernel.websocket.jupyter.org"
PROXY = "https://ngwear.example.org"
PICTURE = "img.ngwear-picture"


def explore(port: int, tmp_path: Path, *flags):
    argv = [sys.executable, "-m", "ngwear.cli", "explore", str(PAPER), "--port", str(port),
            "--out", str(tmp_path / "saved"), *flags]
    return server(argv, port, tmp_path / "server.log", ready="(ready after")


def get(port: int, path: str, **headers) -> tuple[int, dict, str]:
    """Status, headers and body of ``GET path`` with exactly these headers (``Host`` included, if given)."""
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    try:
        connection.request("GET", path, headers=headers)
        response = connection.getresponse()
        return response.status, dict(response.getheaders()), response.read().decode(errors="replace")
    finally:
        connection.close()


def kernel_id(body: str) -> str:
    return re.search(r'kernelId": "([0-9a-f-]+)"', body).group(1)


def channels(port: int, kernel: str, query: str = "", *, host: str = "127.0.0.1", subprotocols=(V1,), **kw):
    """A websocket client of ``kernel``'s channels, connected to 127.0.0.1 with the ``Host`` header ``host:port``."""
    return websockets.connect(f"ws://{host}:{port}/api/kernels/{kernel}/channels?session_id={uuid.uuid4().hex}{query}",
                              sock=socket.create_connection(("127.0.0.1", port)), proxy=None, max_size=None,
                              subprotocols=list(subprotocols) or None, **kw)


def refused(port: int, kernel: str, query: str = "", **kw) -> int:
    """The HTTP status with which the server refuses a websocket handshake (0 if it accepts it)."""
    try:
        channels(port, kernel, query, **kw).close()
    except InvalidStatus as err:
        return err.response.status_code
    return 0


def deaf_channels(port: int, kernel: str, query: str) -> socket.socket:
    """A raw websocket client of ``kernel``'s channels (v1 protocol) that sends and never reads."""
    client = socket.create_connection(("127.0.0.1", port))
    client.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    key = base64.b64encode(os.urandom(16)).decode()
    client.sendall(f"GET /api/kernels/{kernel}/channels?session_id={uuid.uuid4().hex}{query} HTTP/1.1\r\n"
                   f"Host: 127.0.0.1:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                   f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: {V1}\r\n\r\n"
                   .encode())
    assert client.recv(12) == b"HTTP/1.1 101", "the handshake is accepted"
    return client


def masked(payload: bytes) -> bytes:
    """``payload`` as a client's binary websocket frame (RFC 6455: FIN, opcode 2, masked)."""
    n, mask = len(payload), os.urandom(4)
    length = bytes([0x80 | n]) if n < 126 else bytes([0x80 | 126]) + n.to_bytes(2, "big")
    return bytes([0x82]) + length + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload))


def v1_frame(msg_type: str, content: dict, session: str) -> bytes:
    """A shell message in the v1 kernel websocket protocol: offsets (8 bytes each, little-endian), then the parts."""
    header = {"msg_id": uuid.uuid4().hex, "msg_type": msg_type, "session": session, "username": "",
              "version": "5.3", "date": "2025-01-01T00:00:00Z"}
    parts = [b"shell", *(json.dumps(x).encode() for x in (header, {}, {"version": "1.0.0"}, content))]
    offsets = [8 * (len(parts) + 2)]
    for part in parts:
        offsets.append(offsets[-1] + len(part))
    return b"".join(x.to_bytes(8, "little") for x in (len(offsets), *offsets)) + b"".join(parts)


def control_comm(session: str, comm: str) -> bytes:
    """``comm_open`` of the widgets' control comm."""
    return v1_frame("comm_open", {"comm_id": comm, "target_name": "jupyter.widget.control", "data": {}}, session)


def request_states(session: str, comm: str) -> bytes:
    """``request_states`` on the control comm: the kernel answers with every widget's state (a new message each time)."""
    return v1_frame("comm_msg", {"comm_id": comm, "data": {"method": "request_states"}}, session)


def rss_mb(pid: int) -> float:
    return int(re.search(r"VmRSS:\s+(\d+)", Path(f"/proc/{pid}/status").read_text()).group(1)) / 1024


def test_only_the_token_host_and_origin_are_served_and_saves_stay_in_the_folder(tmp_path):
    port, shots = free_port(), Shots("test_app_server")
    named = f"http://ngwear.example.org:{port}"  # the app under a name, as behind a proxy that keeps the Host
    resolve = "--host-resolver-rules=MAP evil.example 127.0.0.1, MAP ngwear.example.org 127.0.0.1"
    with explore(port, tmp_path, "--allow-origin", PROXY, "--allow-origin", named) as app, chromium(resolve) as browser:
        url = app_url(tmp_path / "server.log")
        token = url.split("?token=")[1]
        here = f"127.0.0.1:{port}"
        spare = kernels_of(app.pid)
        assert len(token) >= 32 and len(spare) == 1

        for query in ("", "?token=wrong"):  # no page and no kernel without the token: Jupyter's login form
            status, headers, _ = get(port, f"/{query}")
            assert status == 302 and headers["Location"].startswith("/login"), (query, status)
        assert kernels_of(app.pid) == spare
        page = browser.new_page(viewport={"width": 1280, "height": 1100})
        with shots.on_failure(page):
            page.goto(f"http://{here}/")
            assert "/login" in page.url and page.query_selector(PICTURE) is None
            shots(page, "without-token")

            status, _, body = get(port, f"/?token={token}", Host=f"evil.example:{port}",
                                  Origin=f"http://evil.example:{port}")  # a foreign page's request, now with the token
            assert status == 403
            rebound = browser.new_page()  # a name that resolves to 127.0.0.1 (DNS rebinding), token and all
            assert rebound.goto(f"http://evil.example:{port}/?token={token}").status == 403
            rebound.close()
            allowed = browser.new_page()  # the allowed name: the whole app works, websockets included
            allowed.goto(f"{named}/?token={token}")
            allowed.wait_for_function(f"() => {{ const i = document.querySelector('{PICTURE}');"
                                      " return i && i.complete && i.naturalWidth > 0; }", timeout=90_000)
            allowed.close()
            page.goto(url)
            page.wait_for_function(f"() => {{ const i = document.querySelector('{PICTURE}');"
                                   " return i && i.complete && i.naturalWidth > 0; }", timeout=90_000)
            kernel = kernel_id(page.content())
            cookie = "; ".join(f"{c['name']}={c['value']}" for c in page.context.cookies())

            # the kernel's API and websocket: the token (or the page's cookie) from 127.0.0.1's or the proxy's origin
            assert get(port, f"/api/kernels/{kernel}")[0] == 403
            assert get(port, f"/api/kernels/{kernel}?token={token}")[0] == 200
            assert get(port, f"/api/kernels/{kernel}?token={token}", Host=f"evil.example:{port}")[0] == 403
            assert get(port, f"/api/kernels/{kernel}?token={token}", Host="ngwear.example.org", Origin=PROXY)[0] == 200
            assert get(port, f"/api/kernels/{kernel}", Cookie=cookie, Origin=f"http://{here}")[0] == 200
            assert get(port, f"/api/kernels/{kernel}", Cookie=cookie, Origin="http://127.0.0.1:1")[0] != 200
            assert get(port, "/", Cookie=cookie, Origin="http://127.0.0.1:1")[0] == 403  # a page on another port
            assert refused(port, kernel) == 403
            assert refused(port, kernel, f"&token={token}", host="evil.example") == 403
            assert refused(port, kernel, origin=f"http://{here}", additional_headers={"Cookie": cookie}) == 0
            assert refused(port, kernel, origin="http://evil.example", additional_headers={"Cookie": cookie}) == 403
            assert refused(port, kernel, origin=PROXY, additional_headers={"Cookie": cookie}) == 0
            assert refused(port, kernel, f"&token={token}", subprotocols=()) == 400  # the legacy protocol

            # save into: the app's folder or a folder inside it, however the path is spelled
            root, elsewhere = (tmp_path / "saved").resolve(), tmp_path / "elsewhere"
            elsewhere.mkdir()
            root.mkdir()
            (root / "link").symlink_to(elsewhere)
            for spelled in (str(elsewhere), "link", "../elsewhere", f"{root}/sub/../../elsewhere", "~"):
                page.fill(".ngwear-folder input", spelled)
                page.click("button.ngwear-save_scene")
                page.wait_for_function("(s) => document.querySelector('.ngwear-message').textContent.includes(s)",
                                       arg=f"save into: {spelled} is outside {root}")
                assert "\n" not in page.inner_text(".ngwear-message").strip()
            shots(page, "save-refused")
            page.fill(".ngwear-folder input", "sub")
            page.click("button.ngwear-save_scene")
            page.wait_for_function("() => document.querySelector('.ngwear-message').textContent.includes('saved scene')")
            assert page.inner_text(".ngwear-message").strip() == f"saved scene: {root / 'sub' / 'paper_strip-1.toml'}"
            assert not any(elsewhere.iterdir())
    log = (tmp_path / "server.log").read_text()
    assert log.count(token) == 1 and f"at {url} (ready" in log, "the token is printed in the URL line only"


def test_misbehaving_websocket_clients_neither_grow_nor_block_the_server(tmp_path):
    port = free_port()
    with explore(port, tmp_path) as app:
        token = app_url(tmp_path / "server.log").split("?token=")[1]
        kernel = kernel_id(get(port, f"/?token={token}")[2])
        start, samples = time.monotonic(), [rss_mb(app.pid)]

        # a legacy client: no v1 subprotocol, comm_open + request_states (then 11 GB, and the server blocked)
        assert refused(port, kernel, f"&token={token}", subprotocols=()) == 400
        # a v1 client asking for every widget's state 20 times a second, reading nothing, until the server
        # drops it (32 MB waiting: sooner on a quiet machine, as fast as the kernel answers on a loaded one)
        session, comm = uuid.uuid4().hex, uuid.uuid4().hex
        with deaf_channels(port, kernel, f"&token={token}") as client, pytest.raises(OSError):
            client.sendall(masked(control_comm(session, comm)))
            while time.monotonic() - start < 180:
                for _ in range(20):
                    client.sendall(masked(request_states(session, comm)))
                time.sleep(1)
                samples.append(rss_mb(app.pid))
        # a v1 client asking 2 000 times at once, then gone (jupyter_server keeps the answers for its return)
        with channels(port, kernel, f"&token={token}") as client:
            client.send(control_comm(session, comm))
            with pytest.raises(ConnectionClosed):
                for _ in range(2000):
                    client.send(request_states(session, comm))
                while True:     # the sends may all leave before the server reads the 101st: then its close comes
                    client.recv(timeout=60)
        while time.monotonic() - start < 40:
            time.sleep(1)
            samples.append(rss_mb(app.pid))
        print(f"server RSS [MB] every second: {[round(s) for s in samples]}")
        assert max(samples) - samples[0] < 150, "the server's memory grows"
        assert get(port, "/voila/static/voila.js")[0] == 200 and get(port, f"/?token={token}")[0] == 200

        kernels = kernels_of(app.pid)
        app.send_signal(signal.SIGTERM)
        app.wait(30)
    log = (tmp_path / "server.log").read_text()
    assert app.returncode == 0 and "SIGTERM: stopping" in log and "ngwear explore: stopped" in log
    assert "more than 100 messages" in log and "does not read" in log
    assert not any(alive(pid) for pid in kernels), "SIGTERM leaves no kernel running"


def test_kernels_are_capped_and_those_of_unopened_pages_end(tmp_path):
    port, cap = free_port(), 2
    with explore(port, tmp_path, "--max-kernels", str(cap), "--no-token") as app:
        assert app_url(tmp_path / "server.log") == f"http://127.0.0.1:{port}/"
        answers, counts = [], []
        for _ in range(cap + 2):  # plain GETs (no token needed with --no-token): nobody opens these pages
            answers.append(get(port, "/"))
            time.sleep(2)
            counts.append(len(kernels_of(app.pid)))
        assert [a[0] for a in answers] == [200] * cap + [503] * 2 and max(counts) <= cap
        assert "ngwear explore is busy: 2 kernels in use (--max-kernels)" in answers[-1][2]
        pages = kernels_of(app.pid)
        wait_until(lambda: not any(alive(pid) for pid in pages), 60, "the kernels of the unopened pages have ended")
        wait_until(lambda: len(kernels_of(app.pid)) == 1, 60, "a new spare kernel has started")
        assert get(port, "/")[0] == 200
    assert f"ngwear: warning: --no-token: anyone who can reach port {port}" in (tmp_path / "server.log").read_text()
