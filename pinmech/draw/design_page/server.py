"""The design page's web server: Starlette on uvicorn, on 127.0.0.1 only, every request
refused without the random token of the page's address (HTTP 403; a websocket closed
with code 1008 before it opens). One websocket per page; each message is answered in a
worker thread (`messages.answer`), one at a time, so a drag never waits behind a queue:
the page sends its next drag when the last one's frame has come back.
"""

from __future__ import annotations

import asyncio
import json
import math
import secrets
import socket
import threading
from importlib import resources

HOST = "127.0.0.1"
#: WebSocket close code for a refused token (RFC 6455: policy violation).
POLICY_VIOLATION = 1008


def page_html(title: str) -> str:
    """The page: HTML with its stylesheet and script inlined (nothing else is fetched)."""
    import html

    folder = resources.files("pinmech.draw.design_page") / "static"
    text = (folder / "page.html").read_text(encoding="utf-8")
    return (text.replace("{{title}}", html.escape(title))
            .replace("{{css}}", (folder / "page.css").read_text(encoding="utf-8"))
            .replace("{{js}}", (folder / "page.js").read_text(encoding="utf-8")))


def make_app(session, saving, token: str):
    """The Starlette app of one session: GET / (the page) and /ws, both behind the token."""
    from starlette.applications import Starlette
    from starlette.concurrency import run_in_threadpool
    from starlette.responses import HTMLResponse, PlainTextResponse
    from starlette.routing import Route, WebSocketRoute

    from pinmech.draw.design_page.messages import answer

    lock = threading.Lock()

    def allowed(params) -> bool:
        return secrets.compare_digest(params.get("token", ""), token)

    async def page(request):
        if not allowed(request.query_params):
            return PlainTextResponse("403: this page needs the token of its address", status_code=403)
        return HTMLResponse(page_html(session.turn.linkage.title), headers={"Cache-Control": "no-store"})

    def locked_answer(message: dict) -> dict:
        with lock:
            return answer(session, saving, message)

    async def socket_(websocket):
        if not allowed(websocket.query_params):
            await websocket.close(code=POLICY_VIOLATION)
            return
        await websocket.accept()
        await websocket.send_text(json.dumps(finite(session.first), allow_nan=False, default=_plain))
        from starlette.websockets import WebSocketDisconnect

        try:
            while True:
                message = json.loads(await websocket.receive_text())
                reply = await run_in_threadpool(locked_answer, message)
                await websocket.send_text(json.dumps(finite(reply), allow_nan=False, default=_plain))
        except (WebSocketDisconnect, asyncio.CancelledError):
            return

    async def refused(request):
        return PlainTextResponse("403: this page needs the token of its address", status_code=403)

    return Starlette(routes=[Route("/", page), WebSocketRoute("/ws", socket_), Route("/{rest:path}", refused)])


def finite(value):
    """`value` with every NaN or infinity made None (JSON has neither)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite(v) for v in value]
    return value


def _plain(value):
    """JSON for what json does not know (numpy scalars); NaN and inf are refused upstream."""
    return float(value)


def bound_socket(port: int = 0) -> socket.socket:
    """A listening TCP socket on 127.0.0.1 (port 0: one the system picks)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.bind((HOST, port))
    sock.listen(16)
    return sock


class PageServer:
    """A running page: its address (with the token) and a way to stop it.

    Args:
        session: the `Session`; saving: its `Saving`; port: 0 for any free port.
    """

    def __init__(self, session, saving, port: int = 0) -> None:
        import uvicorn

        self.token = secrets.token_urlsafe(24)
        self.socket = bound_socket(port)
        self.port = self.socket.getsockname()[1]
        config = uvicorn.Config(make_app(session, saving, self.token), log_level="warning", ws="websockets-sansio",
                                lifespan="off", ws_max_size=64 * 2**20)
        self.server = uvicorn.Server(config)
        self.thread: threading.Thread | None = None

    @property
    def url(self) -> str:
        return f"http://{HOST}:{self.port}/?token={self.token}"

    def serve(self) -> None:
        """Serve until stopped (Ctrl-C, or `stop` from another thread)."""
        self.server.run(sockets=[self.socket])

    def start(self) -> PageServer:
        """Serve in a background thread (tests, scripts); returns when it listens."""
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()
        while not self.server.started and self.thread.is_alive():
            threading.Event().wait(0.01)
        return self

    def stop(self) -> None:
        self.server.should_exit = True
        if self.thread is not None:
            self.thread.join(timeout=10)
