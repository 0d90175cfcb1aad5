"""Interleaved timing rounds, shared by the benchmark scripts.

A row is anything with `run` (one call, or None for a row that has no time), `calls` (how
many calls make one sample), `poses` (what one call solves) and `times` (a list that gets
one entry a round: seconds per pose). Each round times every row once, the order rotated
from round to round so the machine's load falls on every row alike, with garbage
collection paused during a sample, as timeit does.
"""

from __future__ import annotations

import gc
import os
import platform
import time
from dataclasses import dataclass, field
from typing import Callable


@dataclass
class Timed:
    """A call to time: `run` solves `poses` poses; `times` in seconds per pose."""

    run: Callable[[], object]
    poses: int = 1
    calls: int = 1
    times: list[float] = field(default_factory=list)


def time_rounds(rows: list, rounds: int) -> None:
    """`rounds` interleaved rounds over the rows that have a `run`."""
    live = [r for r in rows if r.run is not None]
    for k in range(rounds if live else 0):
        for row in live[k % len(live):] + live[: k % len(live)]:
            gc.collect()
            gc.disable()
            try:
                t0 = time.perf_counter()
                for _ in range(row.calls):
                    row.run()
                row.times.append((time.perf_counter() - t0) / (row.calls * row.poses))
            finally:
                gc.enable()


def machine() -> str:
    """The machine a report was measured on, for its reader: the CPU's model, its cores,
    the architecture, and the load average when the run started (a shared machine's
    other work slows every row alike, interleaved, but not the absolute times)."""
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as info:
            model = next((line.split(":", 1)[1].strip() for line in info if line.startswith("model name")), model)
    except OSError:
        pass
    load = f", load average {os.getloadavg()[0]:.1f} at the start" if hasattr(os, "getloadavg") else ""
    return f"{model}, {os.cpu_count()} cores, {platform.machine()}{load}"
