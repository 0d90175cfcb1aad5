"""How long one drag takes on the design page (pinmech design), measured on this machine.

For each linkage, a joint is dragged through `--drags` distinct places (each a new linkage:
drawn, loaded, its turn of 361 poses solved) by a websocket client of the page's own
server, as the browser sends them; timed from sending the drag to receiving

    frame:        the curves of every point over the turn, the drawing, folds (what the page
                  redraws at once), as JSON;
    + diagnostics: plus the time the server takes to compute the diagnostics panel's data
                  (Grashof/Barker class, transmission angle over the turn and its least
                  value, limit positions as ghosts, swing or stroke, Q) from the same turn,
                  sent next (after a pause of server.PAUSE_S for a next drag, not counted).

Printed: the median and the spread (fastest, slowest) of each, against the page's targets
(one update <= 30 ms for a four-bar, <= 100 ms for a Watt or Stephenson six-bar). The
browser's own drawing of the frame is not included.

Run: python scripts/benchmark_design_page.py [--drags 40]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: (linkage file, the joint dragged, the target of one update [ms])
CASES = (
    ("four_bar.toml", "B", 30.0),
    ("slider_crank.toml", "A", 30.0),
    ("watt.toml", "D", 100.0),
    ("stephenson.toml", "D", 100.0),
)


def measure(file: str, joint: str, drags: int) -> tuple[list[float], list[float]]:
    """Milliseconds to the frame and to the diagnostics, per drag, over the real server."""
    from websockets.sync.client import connect

    from pinmech.draw.design_page.messages import Saving
    from pinmech.draw.design_page.server import PageServer
    from pinmech.draw.design_page.session import Session, read_design_file

    spec, source, driver, speed = read_design_file(ROOT / "models" / "linkages" / file)
    session = Session(spec, source, driver=driver, speed=speed)
    server = PageServer(session, Saving(Path("/nonexistent/never-saved.toml"), "")).start()
    x0, y0 = session.turn.linkage.points[joint][:2]
    frames, totals = [], []
    try:
        with connect(f"ws://127.0.0.1:{server.port}/ws?token={server.token}", max_size=2**26) as ws:
            _until(ws, "diagnostics")  # the first frame and its diagnostics
            for i in range(drags + 3):  # the first three warm up
                dx = 1e-4 * (1 + i % 7) * (1 if i % 2 else -1)
                started = time.perf_counter()
                ws.send(json.dumps({"type": "drag", "joint": joint, "x": x0 + dx, "y": y0 + 0.5 * dx}))
                frame = _until(ws, "frame")
                at_frame = time.perf_counter()
                if not frame["ok"]:
                    raise SystemExit(f"{file}: the drag failed: {frame['error']}")
                diagnostics = _until(ws, "diagnostics")
                if i >= 3:  # the work of one update: the frame as received, plus the diagnostics'
                    frames.append(1e3 * (at_frame - started))  # computation (the server waits PAUSE_S
                    totals.append(frames[-1] + diagnostics["ms"])  # for a next drag before it, not counted)
    finally:
        server.stop()
        session.close()
    return frames, totals


def _until(ws, kind: str) -> dict:
    while True:
        message = json.loads(ws.recv(timeout=120))
        if message["type"] == kind:
            return message


def _stats(values: list[float]) -> str:
    return f"{statistics.median(values):7.1f} ms ({min(values):.1f} .. {max(values):.1f})"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--drags", type=int, default=40, help="drags measured per linkage (default 40)")
    args = parser.parse_args(argv)
    print(f"one drag on the design page, {args.drags} drags each: median (fastest .. slowest)")
    print(f"{'linkage':<20} {'frame (curves)':<28} {'frame + diagnostics':<28} target")
    for file, joint, target in CASES:
        frames, totals = measure(file, joint, args.drags)
        met = "met" if statistics.median(totals) <= target else (
            "frame met, with diagnostics not" if statistics.median(frames) <= target else "not met")
        print(f"{file:<20} {_stats(frames):<28} {_stats(totals):<28} <= {target:.0f} ms: {met}")


if __name__ == "__main__":
    main()
