"""Headless chromium driven through its DevTools protocol: open a live page, run script in
it, move and click its mouse, photograph it. The design page's browser tests and the
tutorial's pictures take this route (`pinmech.draw.browser` photographs saved files).

Chromium is started with the flags of `pinmech.draw.browser` and
`--remote-debugging-port=0`; the address it prints on stderr is the browser's DevTools
websocket, spoken to with `websockets`' synchronous client, one page target attached.
"""

from __future__ import annotations

import base64
import json
import re
import subprocess
import tempfile
import time
from pathlib import Path

from pinmech.draw.browser import FLAGS, end_process_group, remove_profile
from pinmech.exceptions import PinmechError
from pinmech.outputs import write_with

#: How long chromium may take to say where its DevTools listen [s].
START_TIMEOUT_S = 30.0


class DevToolsPage:
    """One page of a headless chromium; a context manager (the browser ends with it).

    Args:
        chromium: the executable; url: the page to open; window: (width, height) [pixels].
    """

    def __init__(self, chromium: str, url: str, window: tuple[int, int] = (1200, 800)) -> None:
        from websockets.sync.client import connect

        self._profile = Path(tempfile.mkdtemp(prefix="pinmech-chromium-"))
        self.process = subprocess.Popen(
            [chromium, *FLAGS, f"--window-size={window[0]},{window[1]}", "--remote-debugging-port=0",
             f"--user-data-dir={self._profile}", "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)
        self._connection = connect(self._browser_address(), max_size=2**26, open_timeout=START_TIMEOUT_S)
        self._socket = self._connection.__enter__()
        self._next = 0
        target = self._call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self._session = self._call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        self.call("Emulation.setDeviceMetricsOverride", {"width": window[0], "height": window[1],
                                                         "deviceScaleFactor": 1, "mobile": False})
        self.call("Page.enable")
        self.call("Page.navigate", {"url": url})

    def _browser_address(self) -> str:
        deadline = time.monotonic() + START_TIMEOUT_S
        said = []
        while time.monotonic() < deadline:
            line = self.process.stderr.readline()
            if not line and self.process.poll() is not None:
                break
            said.append(line.strip())
            found = re.search(r"DevTools listening on (ws://\S+)", line)
            if found:
                return found.group(1)
        self.close()
        raise PinmechError(f"chromium did not open its DevTools: {' '.join(said[-5:]) or 'it said nothing'}")

    def _call(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        self._next += 1
        message = {"id": self._next, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        self._socket.send(json.dumps(message))
        while True:
            reply = json.loads(self._socket.recv(timeout=60))
            if reply.get("id") == self._next:
                if "error" in reply:
                    raise PinmechError(f"DevTools {method}: {reply['error'].get('message')}")
                return reply.get("result", {})

    def call(self, method: str, params: dict | None = None) -> dict:
        """A DevTools command to the page; its result."""
        return self._call(method, params, self._session)

    def evaluate(self, expression: str):
        """The value of a JavaScript expression in the page (promises awaited).

        Raises:
            PinmechError: the expression threw (its message quoted).
        """
        result = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True,
                                                "awaitPromise": True})
        if "exceptionDetails" in result:
            raise PinmechError(f"the page threw: {result['exceptionDetails'].get('text')} "
                               f"{result['exceptionDetails'].get('exception', {}).get('description', '')}")
        return result["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 30.0, every: float = 0.05):
        """Poll `expression` until it is truthy; its value.

        Raises:
            PinmechError: still falsy after `timeout` [s].
        """
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                value = self.evaluate(expression)
            except PinmechError:  # not there yet (the page still loading)
                value = None
            if value:
                return value
            time.sleep(every)
        raise PinmechError(f"the page did not reach `{expression}` within {timeout} s")

    def mouse(self, kind: str, x: float, y: float, buttons: int = 1) -> None:
        """A mouse event at (x, y) CSS pixels: kind "mousePressed", "mouseMoved", "mouseReleased"."""
        params = {"type": kind, "x": x, "y": y, "button": "left" if buttons else "none", "buttons": buttons}
        if kind != "mouseMoved":
            params["clickCount"] = 1
        self.call("Input.dispatchMouseEvent", params)

    def drag(self, start: tuple[float, float], end: tuple[float, float], steps: int = 10,
             settle: str | None = None) -> None:
        """Press at `start`, move in `steps` to `end`, release; `settle`: an expression
        waited for after each move (e.g. the page's answer)."""
        self.mouse("mouseMoved", *start, buttons=0)
        self.mouse("mousePressed", *start)
        for i in range(1, steps + 1):
            t = i / steps
            self.mouse("mouseMoved", start[0] + t * (end[0] - start[0]), start[1] + t * (end[1] - start[1]))
            if settle:
                self.wait_for(settle)
        self.mouse("mouseReleased", *end)

    def screenshot(self, png: Path) -> Path:
        """The page as it is drawn now, written to `png`."""
        data = self.call("Page.captureScreenshot", {"format": "png"})["data"]
        picture = base64.b64decode(data)
        write_with(png, lambda temporary: Path(temporary).write_bytes(picture))
        return Path(png)

    def close(self) -> None:
        try:
            if getattr(self, "_connection", None) is not None:
                self._connection.__exit__(None, None, None)
        finally:
            end_process_group(self.process)  # the browser and every helper it started
            remove_profile(self._profile)

    def __enter__(self) -> DevToolsPage:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
