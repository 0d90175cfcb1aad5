"""`pinmech solve` start-up of this checkout against another (main), and `import pinocchio`.

Three commands, each a fresh process, `--runs` interleaved rounds (the order rotated each
round, so the machine's load falls on all alike): `python -c "import pinocchio"`, and
`python -m pinmech solve models/scenes/r_rtr.toml` with PYTHONPATH on each checkout (output
thrown away; each must exit 0). Reported: median wall time, fastest and slowest run, the
median CPU time (user + system: what the process itself spent, less moved by other
processes on a shared machine than its wall time), and each `solve`'s medians over
`import pinocchio`'s (the project's target: at most 1.5).

Bytecode: by default every command reads its modules' bytecode from a cache in a temporary
folder (PYTHONPYCACHEPREFIX), written by one untimed round: what an installed pinmech does
(pip compiles it). With `--compile` (or when PYTHONDONTWRITEBYTECODE is set and the
checkouts have no __pycache__) each run compiles pinmech's source again, which numpy and
Pinocchio never pay.

Run: python scripts/startup_checkouts.py [--other /work/main] [--runs 10] [--compile]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _command(argv: list[str], pythonpath: Path | None, cache: str | None) -> tuple[list[str], dict[str, str]]:
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    if pythonpath is not None:
        env["PYTHONPATH"] = str(pythonpath)
    if cache is not None:  # bytecode written once to `cache`, then read: as an installed package
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = cache
    return [sys.executable, *argv], env


def _run(argv: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and CPU (user + system) seconds one fresh process takes; a failed run stops the
    script (no time for a crash)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(argv, env=env, cwd=tempfile.gettempdir(), stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE)
    seconds = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        sys.exit(f"{' '.join(argv)} failed: {done.stderr.decode()[-400:]}")
    return seconds, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--other", type=Path, default=Path("/work/main"), help="the checkout to compare with")
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--compile", action="store_true", help="no bytecode cache: every run compiles pinmech")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="pinmech-pyc-") as folder:
        _measure(args.other, args.runs, None if args.compile else folder)


def _measure(other: Path, runs: int, cache: str | None) -> None:
    solve = ["-m", "pinmech", "solve", str(ROOT / "models" / "scenes" / "r_rtr.toml")]
    rows = {"import pinocchio": _command(["-c", "import pinocchio"], None, cache),
            f"solve ({other})": _command(solve, other.resolve(), cache),
            f"solve ({ROOT})": _command(solve, ROOT, cache)}
    for row in rows.values():  # untimed: writes the bytecode cache, warms the file cache
        _run(*row)
    wall: dict[str, list[float]] = {name: [] for name in rows}
    cpu: dict[str, list[float]] = {name: [] for name in rows}
    names = list(rows)
    for k in range(runs):
        for name in names[k % len(names):] + names[: k % len(names)]:
            seconds, spent = _run(*rows[name])
            wall[name].append(seconds)
            cpu[name].append(spent)
    floor, cpu_floor = statistics.median(wall["import pinocchio"]), statistics.median(cpu["import pinocchio"])
    how = "bytecode cached" if cache else "pinmech compiled in every run"
    print(f"{runs} interleaved rounds, fresh processes, {how}; load average {os.getloadavg()[0]:.1f}; "
          "seconds: wall median [fastest, slowest], CPU median")
    for name, seconds in wall.items():
        median, spent = statistics.median(seconds), statistics.median(cpu[name])
        print(f"  {name:<50} {median:6.3f} [{min(seconds):.3f}, {max(seconds):.3f}]  CPU {spent:.3f}  "
              f"x{median / floor:.2f} (CPU x{spent / cpu_floor:.2f}) of import pinocchio")


if __name__ == "__main__":
    main()
