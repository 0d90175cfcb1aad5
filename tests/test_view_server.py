"""`pinmech view`: meshcat's server listens on loopback only, and stops with pinmech
(Enter, Ctrl-C, SIGTERM, SIGHUP, even SIGKILL). Checked on the listening sockets."""

from __future__ import annotations

import importlib.util
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(importlib.util.find_spec("meshcat") is None, reason='needs pip install "pinmech[viz]"')
psutil = pytest.importorskip("psutil")

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "models" / "scenes" / "r_rtr.toml"


def _listening(pid: int) -> list[tuple[str, int]]:
    return [(c.laddr.ip, c.laddr.port) for c in psutil.Process(pid).net_connections(kind="inet")
            if c.status == psutil.CONN_LISTEN]


def test_the_server_listens_on_loopback_only():
    from pinmech.draw.view_server import start_server

    process, zmq_url, web_url = start_server()
    try:
        sockets = _listening(process.pid)
        assert len(sockets) >= 2  # the web server and the ZeroMQ socket
        assert {ip for ip, _ in sockets} == {"127.0.0.1"}, sockets  # not 0.0.0.0 nor ::
        ports = {port for _, port in sockets}
        assert int(web_url.rsplit(":", 1)[1].split("/")[0]) in ports and int(zmq_url.rsplit(":", 1)[1]) in ports
    finally:
        process.kill()
        process.wait(timeout=10)


def _view() -> tuple[subprocess.Popen, int]:
    """`pinmech view` waiting for Enter; its meshcat server's pid."""
    view = subprocess.Popen([sys.executable, "-m", "pinmech", "view", str(SCENE)], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    url = view.stdout.readline()
    assert url.startswith("http://127.0.0.1:"), (url, view.stderr.read() if view.poll() is not None else "")
    [server] = psutil.Process(view.pid).children()
    assert {ip for ip, _ in _listening(server.pid)} == {"127.0.0.1"}
    return view, server.pid


def _gone(pid: int, within: float = 20.0) -> bool:
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        if not psutil.pid_exists(pid) or psutil.Process(pid).status() == psutil.STATUS_ZOMBIE:
            return True
        time.sleep(0.05)
    return False


@pytest.mark.parametrize("stop", ["enter", signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGKILL])
def test_the_server_stops_with_pinmech(stop):
    view, server = _view()
    try:
        if stop == "enter":
            view.stdin.write("\n")
            view.stdin.flush()
        else:
            view.send_signal(stop)
        view.wait(timeout=30)
        assert _gone(server), "meshcat's server outlived pinmech"
        if stop != signal.SIGKILL:
            assert "Traceback" not in view.stderr.read()
    finally:
        for pid in (view.pid, server):
            if psutil.pid_exists(pid):
                psutil.Process(pid).kill()
