"""`pinmech solve` start-up of this checkout against another (main), and `import pinocchio`.

Three commands, each a fresh process, `--runs` interleaved rounds (the order rotated each
round, so the machine's load falls on all alike): `python -c "import pinocchio"`, and
`python -m pinmech solve models/scenes/r_rtr.toml` with PYTHONPATH on each checkout (output
thrown away; each must exit 0). Reported: median wall time, fastest and slowest run, and
each `solve`'s median over `import pinocchio`'s (issue 23's target: at most 1.5).

Run: python scripts/startup_checkouts.py [--other /work/main] [--runs 10]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _command(argv: list[str], pythonpath: Path | None) -> tuple[list[str], dict[str, str]]:
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    if pythonpath is not None:
        env["PYTHONPATH"] = str(pythonpath)
    return [sys.executable, *argv], env


def _wall(argv: list[str], env: dict[str, str]) -> float:
    """Seconds one fresh process takes; a failed run stops the script (no time for a crash)."""
    t0 = time.perf_counter()
    done = subprocess.run(argv, env=env, cwd=tempfile.gettempdir(), stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE)
    seconds = time.perf_counter() - t0
    if done.returncode != 0:
        sys.exit(f"{' '.join(argv)} failed: {done.stderr.decode()[-400:]}")
    return seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--other", type=Path, default=Path("/work/main"), help="the checkout to compare with")
    parser.add_argument("--runs", type=int, default=10)
    args = parser.parse_args()
    solve = ["-m", "pinmech", "solve", str(ROOT / "models" / "scenes" / "r_rtr.toml")]
    rows = {"import pinocchio": _command(["-c", "import pinocchio"], None),
            f"solve ({args.other})": _command(solve, args.other.resolve()),
            f"solve ({ROOT})": _command(solve, ROOT)}
    times: dict[str, list[float]] = {name: [] for name in rows}
    names = list(rows)
    for k in range(args.runs):
        for name in names[k % len(names):] + names[: k % len(names)]:
            times[name].append(_wall(*rows[name]))
    floor = statistics.median(times["import pinocchio"])
    print(f"{args.runs} interleaved rounds, fresh processes; seconds: median [fastest, slowest]")
    for name, seconds in times.items():
        median = statistics.median(seconds)
        print(f"  {name:<50} {median:6.3f} [{min(seconds):.3f}, {max(seconds):.3f}]  "
              f"x{median / floor:.2f} of import pinocchio")


if __name__ == "__main__":
    main()
