"""The design page's web server: Starlette on uvicorn, on 127.0.0.1 only, every request
refused without the random token of the page's address (HTTP 403; a websocket closed
before it is accepted, which its handshake answers with HTTP 403). One websocket per page; each message is answered in a
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
#: After a frame, the diagnostics wait this long for the page's next drag [s]: while the
#: mouse moves, frames follow each other at once; when it pauses, the diagnostics come.
PAUSE_S = 0.03
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

    from starlette.websockets import WebSocketDisconnect

    lock = threading.Lock()

    def allowed(params) -> bool:
        return secrets.compare_digest(params.get("token", ""), token)

    async def page(request):
        if not allowed(request.query_params):
            return PlainTextResponse("403: this page needs the token of its address", status_code=403)
        return HTMLResponse(page_html(session.turn.linkage.title), headers={"Cache-Control": "no-store"})

    async def socket_(websocket):
        if not allowed(websocket.query_params):
            await websocket.close(code=POLICY_VIOLATION)
            return
        await websocket.accept()
        await _send(websocket, session.first)
        waiting: asyncio.Queue = asyncio.Queue()
        reader = asyncio.ensure_future(_read(websocket, waiting))
        try:
            await _send(websocket, await run_in_threadpool(locked, session.diagnostics))
            while True:
                message = await waiting.get()
                if message is None:
                    return
                reply = await run_in_threadpool(locked, answer, session, saving, message)
                await _send(websocket, reply)
                if reply.get("type") == "frame" and reply.get("ok"):
                    await asyncio.sleep(PAUSE_S)  # a drag still moving sends its next place by then
                    if waiting.empty():
                        await _send(websocket, await run_in_threadpool(locked, session.diagnostics))
        except (WebSocketDisconnect, asyncio.CancelledError, RuntimeError):
            return
        finally:
            reader.cancel()

    def locked(function, *args):
        with lock:
            try:
                return function(*args)
            except Exception as exc:  # a bug of pinmech's, said on the page rather than a dead socket
                return {"type": "error", "error": f"pinmech failed unexpectedly ({type(exc).__name__}: {exc}); "
                                                  "please report it"}

    async def refused(request):
        return PlainTextResponse("403: this page needs the token of its address", status_code=403)

    return Starlette(routes=[Route("/", page), WebSocketRoute("/ws", socket_), Route("/{rest:path}", refused)])


async def _read(websocket, waiting: asyncio.Queue) -> None:
    """Put the page's messages on `waiting` as they come (None when it goes); a message
    that is no JSON object is answered as an error."""
    try:
        while True:
            text = await websocket.receive_text()
            try:
                waiting.put_nowait(json.loads(text))
            except json.JSONDecodeError:
                waiting.put_nowait({"type": "malformed"})
    except Exception:  # the page went (WebSocketDisconnect), or the server stops
        waiting.put_nowait(None)


async def _send(websocket, reply: dict) -> None:
    await websocket.send_text(as_json(reply))


def as_json(reply: dict) -> str:
    """The reply as JSON, NaN and infinities as null (JSON has neither)."""
    try:
        return json.dumps(reply, allow_nan=False, default=_plain)
    except ValueError:
        return json.dumps(finite(reply), allow_nan=False, default=_plain)


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
