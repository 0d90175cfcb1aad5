"""meshcat's server for `pinmech view`: on loopback only, and gone when pinmech is.

meshcat's own server (`meshcat.servers.zmqserver`) binds its ZeroMQ socket to 127.0.0.1
but its web server to every interface (tornado's default), so anyone on the network could
open the drawing, and it is started in a session of its own, so closing the terminal
leaves it running. This module runs the same server with its web server bound to
127.0.0.1, and makes it exit as soon as its standard input closes: when pinmech exits,
however it exits (even killed), the pipe closes and the server stops.
"""

from __future__ import annotations

import os
import select
import subprocess
import sys
import tempfile
import threading
import time
from typing import IO

from pinmech.exceptions import PinmechError

#: The only address the viewer listens on.
HOST = "127.0.0.1"


def start_server(timeout: float = 30.0) -> tuple[subprocess.Popen, str, str]:
    """Start the server in a child process; its process, ZeroMQ address and web address.

    Raises:
        PinmechError: the server stopped, or said nothing within `timeout` [s], before
            saying where it listens (its stderr quoted).
    """
    errors: IO[bytes] = tempfile.TemporaryFile()
    process = subprocess.Popen([sys.executable, "-u", "-m", "pinmech.draw.view_server"], stdin=subprocess.PIPE,
                               stdout=subprocess.PIPE, stderr=errors, start_new_session=True)
    urls: dict[str, str] = {}
    deadline = time.monotonic() + timeout
    while len(urls) < 2:
        ready, _, _ = select.select([process.stdout], [], [], max(0.0, deadline - time.monotonic()))
        line = process.stdout.readline().decode("utf-8", "replace").strip() if ready else ""
        if not ready or (not line and process.poll() is not None):
            process.kill()
            process.wait(timeout=10)
            errors.seek(0)
            said = " ".join(errors.read().decode("utf-8", "replace").split()[-40:])
            why = "did not start" if not ready else f"stopped at start (exit code {process.returncode})"
            raise PinmechError(f"the meshcat server {why}: {said or 'it said nothing'}")
        key, _, value = line.partition("=")
        if key in ("zmq_url", "web_url"):
            urls[key] = value
    return process, urls["zmq_url"], urls["web_url"]


def main() -> None:
    """The child process: meshcat's bridge on loopback, until standard input closes."""
    import warnings

    with warnings.catch_warnings():  # meshcat's server module imports a deprecated zmq module
        warnings.simplefilter("ignore", DeprecationWarning)
        from meshcat.servers.zmqserver import ZMQWebSocketBridge

    class LoopbackBridge(ZMQWebSocketBridge):
        def make_app(self):  # tornado's listen(port) binds every interface; bind loopback only
            app = super().make_app()
            listen = app.listen
            app.listen = lambda port, **options: listen(port, address=HOST, **options)
            return app

    bridge = LoopbackBridge(host=HOST)
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())  # nobody reads stdout now: a full pipe would block
    threading.Thread(target=_exit_when_stdin_closes, daemon=True).start()
    bridge.run()


def _exit_when_stdin_closes() -> None:
    sys.stdin.buffer.read()  # returns at end of file: the parent has gone
    os._exit(0)


if __name__ == "__main__":
    main()
