"""How long `pinmech solve` takes from a shell, against importing Pinocchio alone.

Three commands, each run `--runs` times in fresh processes, interleaved (one of each per
round, so the machine's load hits them alike): `python -c pass` (the interpreter),
`python -c "import pinocchio"` (the floor of any Pinocchio tool) and
`pinmech solve models/scenes/r_rtr.toml` (the installed console script, output thrown
away). Reported: the median wall time of each with its spread (fastest and slowest run),
and the ratio of the medians of `pinmech solve` to `import pinocchio`. The project's
target on that ratio (at most 1.5) is read by the exit code alone (1 over it).

Where the time goes, from one more run of each kind:
- `PYTHONPROFILEIMPORTTIME=1` (python -X importtime) on `pinmech solve`: the self time of
  every module summed by top-level package, and the costliest single modules;
- `pinmech.cli.main(["solve", SCENE])` after `import pinmech.cli`, timed twice in one
  process (the first call pays the one-off costs: lazy imports, unit registry), then
  under cProfile: the functions with the largest cumulative time.

Run: python scripts/startup_time.py [--runs 10] [--scene FILE] [--out FILE.md]
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from interleave import machine  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: Every child runs here, outside the checkout, so `python -c` imports the pinmech the
#: console script imports (a regular install's copy, not the source tree beside it).
NEUTRAL = Path(tempfile.gettempdir())
SCENE = ROOT / "models" / "scenes" / "r_rtr.toml"
IMPORT_LINE = re.compile(r"import time:\s+(\d+)\s+\|\s+(\d+)\s+\|( *)(\S+)")

TIMED = """
import contextlib, io, sys, time
import pinmech.cli
times = []
for _ in range(2):
    with contextlib.redirect_stdout(io.StringIO()):
        t0 = time.perf_counter()
        code = pinmech.cli.main(["solve", sys.argv[1]])
        times.append(time.perf_counter() - t0)
    if code:
        sys.exit(f"pinmech solve exited with {code}")
print(*times)
"""

PROFILE = """
import cProfile, contextlib, io, pstats, sys
import pinmech.cli
profile = cProfile.Profile()
with contextlib.redirect_stdout(io.StringIO()):
    code = profile.runcall(pinmech.cli.main, ["solve", sys.argv[1]])
if code:
    sys.exit(f"pinmech solve exited with {code}")
stats = pstats.Stats(profile)
rows = sorted(stats.stats.items(), key=lambda kv: -kv[1][3])
print(f"total {stats.total_tt:.6f}")
for (path, line, name), (cc, nc, tt, ct, callers) in rows[:int(sys.argv[2])]:
    print(f"{ct:.6f} {path}:{line}({name})")
"""


def pinmech_command(scene: Path) -> list[str]:
    """The `pinmech` console script next to this interpreter (`python -m pinmech` if none)."""
    script = Path(sys.executable).with_name("pinmech")
    exe = [str(script)] if script.exists() else [sys.executable, "-m", "pinmech"]
    return [*exe, "solve", str(scene)]


def commands(scene: Path) -> dict[str, list[str]]:
    return {
        "python -c pass": [sys.executable, "-c", "pass"],
        'python -c "import pinocchio"': [sys.executable, "-c", "import pinocchio"],
        f"pinmech solve {scene.relative_to(ROOT) if scene.is_relative_to(ROOT) else scene}":
            pinmech_command(scene),
    }


def wall_time(command: list[str], env: dict[str, str] | None = None) -> float:
    """Wall time [s] of one run; a failing command stops the script with its message."""
    t0 = time.perf_counter()
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                          check=False, env=env, cwd=NEUTRAL)
    elapsed = time.perf_counter() - t0
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed (exit {done.returncode}): {done.stderr.strip()[-500:]}")
    return elapsed


def interleaved(cmds: dict[str, list[str]], runs: int) -> dict[str, list[float]]:
    """Wall times [s] of `runs` runs of every command, one of each per round (after one
    untimed round that warms the file cache)."""
    for command in cmds.values():
        wall_time(command)
    times: dict[str, list[float]] = {name: [] for name in cmds}
    for _ in range(runs):
        for name, command in cmds.items():
            times[name].append(wall_time(command))
    return times


def import_costs(command: list[str]) -> tuple[dict[str, float], list[tuple[float, str]], float]:
    """From one run under -X importtime: self time [s] summed by top-level package, every
    module's self time, and the cumulative time of all top-level imports [s]."""
    env = dict(os.environ, PYTHONPROFILEIMPORTTIME="1")
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                          check=False, env=env, cwd=NEUTRAL)
    by_package: dict[str, float] = defaultdict(float)
    modules, total = [], 0.0
    for match in IMPORT_LINE.finditer(done.stderr):
        own, cumulative, indent, name = int(match[1]) * 1e-6, int(match[2]) * 1e-6, match[3], match[4]
        by_package[name.split(".")[0]] += own
        modules.append((own, name))
        if len(indent) == 1:  # a top-level import: its cumulative time holds its children
            total += cumulative
    return dict(by_package), sorted(modules, reverse=True), total


def profile_after_import(scene: Path, top: int) -> tuple[float, list[tuple[float, str]]]:
    """cProfile of the solve command once pinmech.cli is imported: total [s] and the
    functions with the largest cumulative time [s]."""
    done = subprocess.run([sys.executable, "-c", PROFILE, str(scene), str(top)], capture_output=True,
                          text=True, check=False, cwd=NEUTRAL)
    if done.returncode != 0:
        sys.exit(f"profiling pinmech solve failed: {done.stderr.strip()[-500:]}")
    lines = done.stdout.split("\n")
    total = float(lines[0].split()[1])
    return total, [(float(t), where) for t, where in (ln.split(" ", 1) for ln in lines[1:] if ln)]


def solve_after_import(scene: Path) -> tuple[float, float]:
    """Wall time [s] of `main(["solve", SCENE])` once pinmech.cli is imported, and of the
    same call again in that process (what stays once every one-off cost is paid)."""
    done = subprocess.run([sys.executable, "-c", TIMED, str(scene)], capture_output=True, text=True,
                          check=False, cwd=NEUTRAL)
    if done.returncode != 0:
        sys.exit(f"timing pinmech solve failed: {done.stderr.strip()[-500:]}")
    first, second = (float(x) for x in done.stdout.split())
    return first, second


def measured_package() -> Path:
    """The pinmech package the commands import: a regular install's copy in site-packages,
    or the checkout itself for an editable install."""
    done = subprocess.run([sys.executable, "-c", "import pinmech; print(pinmech.__file__)"], capture_output=True,
                          text=True, check=False, cwd=NEUTRAL)
    if done.returncode != 0:
        sys.exit(f"import pinmech failed: {done.stderr.strip()[-500:]}")
    return Path(done.stdout.strip()).parent


def uncompiled_modules(package: Path) -> list[str]:
    """pinmech's source files that every timed run compiles again: they have no bytecode in
    `__pycache__` (or an older one), and PYTHONDONTWRITEBYTECODE, which the commands inherit,
    keeps the untimed round from writing it. Empty when the bytecode is, or will be, cached
    (pip compiles a regular install's bytecode; an editable install runs the checkout's
    source)."""
    if not os.environ.get("PYTHONDONTWRITEBYTECODE"):
        return []
    out = []
    for source in sorted(package.rglob("*.py")):
        cached = Path(importlib.util.cache_from_source(str(source)))
        if not cached.is_file() or cached.stat().st_mtime < source.stat().st_mtime:
            out.append(str(source.relative_to(package.parent)))
    return out


def _short(where: str) -> str:
    """A profiler location with site-packages and the checkout stripped."""
    where = where.replace(str(ROOT) + os.sep, "")
    return re.sub(r".*site-packages/", "", where)


def _ms(seconds: float) -> str:
    return f"{seconds * 1e3:.0f}"


def report(scene: Path, runs: int, top: int) -> tuple[str, float]:
    """The Markdown report and the ratio of medians `pinmech solve` / `import pinocchio`."""
    cmds = commands(scene)
    times = interleaved(cmds, runs)
    names = list(cmds)
    medians = {n: statistics.median(t) for n, t in times.items()}
    ratio = medians[names[2]] / medians[names[1]]
    lines = [f"{runs} runs of each command, interleaved, wall time [ms]; {machine()}:", "",
             "| command | median | fastest | slowest |", "| --- | --- | --- | --- |"]
    lines += [f"| `{n}` | {_ms(medians[n])} | {_ms(min(t))} | {_ms(max(t))} |" for n, t in times.items()]
    lines += ["", f"`{names[2]}` takes {ratio:.2f} x `{names[1]}` (medians).", ""]
    package = measured_package()
    editable = package.resolve() == ROOT / "pinmech"
    where = "the checkout's source (an editable install)" if editable else "a regular install (in site-packages)"
    lines += [f"pinmech measured: {where}.", ""]
    uncached = uncompiled_modules(package)
    if uncached:
        lines += [(f"Every `pinmech solve` above compiled pinmech's own modules from source ({len(uncached)} files "
                   "without cached bytecode, and PYTHONDONTWRITEBYTECODE is set, so no run could cache it), which "
                   "numpy and Pinocchio, compiled when installed, do not pay: with its bytecode cached (after an "
                   "installation, or one run without that variable) pinmech starts faster than measured here."), ""]
    by_package, modules, total = import_costs(cmds[names[2]])
    lines += [f"Imports of `pinmech solve` (python -X importtime, one run; {_ms(total)} ms in all, "
              "inflated by the profiling), self time summed by top-level package [ms]: "
              + ", ".join(f"{p} {_ms(t)}" for p, t in sorted(by_package.items(), key=lambda kv: -kv[1])[:top])
              + ".", "", "Costliest single modules (self time) [ms]: "
              + ", ".join(f"{n} {_ms(t)}" for t, n in modules[:top]) + ".", ""]
    first, second = solve_after_import(scene)
    run_total, functions = profile_after_import(scene, 2 * top)
    lines += [(f"After `import pinmech.cli`, `main(['solve', SCENE])` takes {_ms(first)} ms (a second call in "
              f"the same process: {_ms(second)} ms). Under cProfile ({_ms(run_total)} ms in all, inflated "
              "by the profiling), the largest cumulative times [ms]:"), ""]
    lines += [f"- {_ms(t)} `{_short(where)}`" for t, where in functions]
    return "\n".join(lines) + "\n", ratio


def main(argv: list[str] | None = None) -> float:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=10, help="timed runs of each command")
    parser.add_argument("--scene", type=Path, default=SCENE, help="scene file given to pinmech solve")
    parser.add_argument("--top", type=int, default=8, help="how many packages and modules to name (twice as many functions)")
    parser.add_argument("--out", type=Path, help="also write the Markdown report to this file")
    args = parser.parse_args(argv)
    if args.runs < 1 or args.top < 1:
        parser.error("--runs and --top must be at least 1")
    if not args.scene.is_file():
        parser.error(f"no scene file {args.scene}")
    text, ratio = report(args.scene.resolve(), args.runs, args.top)
    print(text, end="")
    if args.out:
        args.out.write_text(text)
    return ratio


#: The project's target on the ratio of medians (the exit code's; the report states none).
TARGET_RATIO = 1.5

if __name__ == "__main__":
    _ratio = main()
    if _ratio > TARGET_RATIO:
        print(f"target missed: {_ratio:.2f} x import pinocchio, over {TARGET_RATIO} x", file=sys.stderr)
    sys.exit(1 if _ratio > TARGET_RATIO else 0)
