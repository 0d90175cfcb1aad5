"""Peak resident memory of a long sweep streamed to CSV (a child process, ru_maxrss).

A sweep yields its poses one at a time and `pinmech sweep --csv` writes each row as it
is solved, so memory stays flat however many poses: this runs the CLI on the R-RTR for
a small and a large number of poses and prints both peaks.

Run: python scripts/sweep_memory.py [--poses 1000000]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SCENE = Path(__file__).resolve().parents[1] / "models" / "scenes" / "r_rtr.toml"


def peak_rss_mb(poses: int) -> tuple[float, float, int]:
    """Peak RSS [MB] of `pinmech sweep` over `poses` poses (many turns), its time [s], rows."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "sweep.csv")
        start = time.perf_counter()
        code = (
            "import resource, sys; from pinmech.cli import main; rc = main(sys.argv[1:]); "
            "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr); sys.exit(rc)"
        )
        run = subprocess.run(
            [sys.executable, "-c", code, "sweep", str(SCENE), "--from", "0 deg", "--to", f"{poses} deg",
             "--steps", str(poses), "--csv", out],
            capture_output=True, text=True, check=True,
        )
        elapsed = time.perf_counter() - start
        with open(out, encoding="utf-8") as f:
            rows = sum(1 for _ in f) - 1
    return int(run.stderr.strip().splitlines()[-1]) / 1024, elapsed, rows


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=1_000_000)
    args = parser.parse_args(argv)
    for n in (1000, args.poses):
        mb, seconds, rows = peak_rss_mb(n)
        print(f"{n:>9} poses: peak RSS {mb:6.1f} MB, {seconds:7.1f} s, {rows} CSV rows")


if __name__ == "__main__":
    main()
