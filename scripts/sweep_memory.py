"""Peak resident memory of a long sweep streamed out (a child process, ru_maxrss).

A sweep solves its poses a chunk at a time (solve_cycle.CHUNK of them), `pinmech sweep`
writes each CSV row as its pose comes, and the figure keeps at most 20,000 poses, so
memory stays flat however many poses: this runs the CLI on the R-RTR (one pose per
degree, many turns) for a small and a large number of poses, CSV to a pipe that this
script only counts, and a figure, and prints both peaks.

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
CHILD = (
    "import resource, sys; from pinmech.cli import main; rc = main(sys.argv[1:]); sys.stdout.flush(); "
    "print('peak', resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr); sys.exit(rc)"
)


def peak_rss_mb(poses: int, plot: bool = True) -> tuple[float, float, int]:
    """Peak RSS [MB] of `pinmech sweep` over `poses` poses, its time [s], and the CSV rows."""
    with tempfile.TemporaryDirectory() as tmp:
        args = [sys.executable, "-c", CHILD, "sweep", str(SCENE), "--from", "0 deg", "--to", f"{poses - 1} deg",
                "--steps", str(poses), "--csv", "/dev/stdout"]
        if plot:
            args += ["--plot", os.path.join(tmp, "sweep.png")]
        start = time.perf_counter()
        with subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as child:
            rows = sum(1 for _ in child.stdout) - 1  # the header
            err = child.stderr.read()
        if child.returncode:
            raise RuntimeError(f"pinmech sweep failed: {err}")
        elapsed = time.perf_counter() - start
    peak = next(line for line in err.splitlines() if line.startswith("peak"))
    return int(peak.split()[1]) / 1024, elapsed, rows


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=1_000_000)
    args = parser.parse_args(argv)
    for n in (min(1000, args.poses), args.poses):
        mb, seconds, rows = peak_rss_mb(n)
        print(f"{n:>9} poses: peak RSS {mb:6.1f} MB, {seconds:7.1f} s, {rows} CSV rows, and a figure")


if __name__ == "__main__":
    main()
