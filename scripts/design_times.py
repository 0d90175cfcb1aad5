"""How long the bundled design studies and syntheses take, as a user runs them.

Each command runs as a user types it (`pinmech study FILE --workers 0 --quiet`, `pinmech
synth FILE`), in a fresh process from a scratch folder beside models/, once; the
report gives its wall time and the CPU time the process used (user + system, children
included), its exit code, and the machine it ran on with its load average before the
command: on a shared machine the wall time grows with the load, the CPU time much less.

    python scripts/design_times.py --out docs/_generated/design_times.md   # every command
    python scripts/design_times.py --only five_bar_actuators                # some of them

The documentation quotes the file docs/_generated/design_times.md this writes; a command
left out with `--only` is a row saying it was not run.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from interleave import machine  # noqa: E402

#: name -> the command line, as a user types it from the repository's root.
COMMANDS: dict[str, str] = {
    "four_bar_sensitivity": "pinmech study models/studies/four_bar_sensitivity.toml --workers 0 --quiet",
    "four_bar_tolerance": "pinmech study models/studies/four_bar_tolerance.toml --workers 0 --quiet",
    "four_bar_grid": "pinmech study models/studies/four_bar_grid.toml --workers 0 --quiet",
    "five_bar_workspace": "pinmech study models/studies/five_bar_workspace.toml --workers 0 --quiet",
    "five_bar_actuators": "pinmech study models/studies/five_bar_actuators.toml --workers 0 --quiet",
    "delta_workspace": "pinmech study models/studies/delta_workspace.toml --workers 0 --quiet",
    "four_bar_path": "pinmech synth models/synthesis/four_bar_path.toml",
    "watt_path": "pinmech synth models/synthesis/watt_path.toml",
}


def timed(command: str) -> tuple[float, float, int]:
    """Wall time [s], CPU time [s] and exit code of one command, run in a fresh process
    from a scratch folder holding a link to models/."""
    argv = [sys.executable, "-m", "pinmech", *command.split()[1:]]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    with tempfile.TemporaryDirectory(prefix="pinmech-times-") as scratch:
        (Path(scratch) / "models").symlink_to(ROOT / "models")
        start = time.perf_counter()
        run = subprocess.run(argv, cwd=scratch, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                             env={**os.environ, "MPLBACKEND": "Agg"}, check=False)
        wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, run.returncode


def report(names: list[str]) -> str:
    """The Markdown table: a row a command, measured or marked not run."""
    lines = [f"One run of each command, in a fresh process; {machine()}.", "",
             "| command | wall [s] | CPU [s] | load average before | exit |", "| --- | --- | --- | --- | --- |"]
    for name, command in COMMANDS.items():
        if name not in names:
            lines.append(f"| `{command}` | not run | | | |")
            continue
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
        wall, cpu, code = timed(command)
        lines.append(f"| `{command}` | {wall:.1f} | {cpu:.1f} | {load:.1f} | {code} |")
        print(lines[-1], file=sys.stderr, flush=True)
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=sorted(COMMANDS), help="time these commands only")
    parser.add_argument("--out", type=Path, help="also write the Markdown report to this file")
    args = parser.parse_args(argv)
    text = report(args.only or list(COMMANDS))
    print(text, end="")
    if args.out:
        args.out.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
