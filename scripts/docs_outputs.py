"""Write every printed output the documentation shows, by running the commands that print it.

    python scripts/docs_outputs.py            # rewrite docs/_generated/*.txt and README's outputs
    python scripts/docs_outputs.py --check    # exit 1, naming the file, when one is out of date

Each output is `$ pinmech ...` then what pinmech printed (stdout, then stderr), run from a
scratch folder holding a link to models/ (so files the command writes land there), with
the exit code a line of its own when it is not 0, and paths as seen from the
repository's root (not this machine's folders). The docs include these files (MyST
`literalinclude`); README.md's output blocks follow a marker line `<!-- output: NAME -->`
and are rewritten from the same files. docs/_generated/exit_codes.md is the exit-code table,
from the error classes in pinmech/exceptions.py; docs/_generated/singular_accuracy.md what
scripts/singular_accuracy.py prints (the same at every run). tests/test_docs_examples.py checks that all
of it is what the code prints now.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import re
import shlex
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GENERATED = ROOT / "docs" / "_generated"

#: name -> the command line, as a user types it (run from the repository's root).
COMMANDS: dict[str, str] = {
    "r_rtr_solve": "pinmech solve models/scenes/r_rtr.toml",
    "r_rtr_check": "pinmech check models/scenes/r_rtr.hand.toml",
    "four_bar_drawn_solve": "pinmech solve models/scenes/four_bar_drawn.toml",
    "four_bar_drawn_build": "pinmech build models/linkages/four_bar.toml -o four_bar_drawn.urdf",
    "four_bar_drawn_sweep": "pinmech sweep models/scenes/four_bar_drawn.toml --steps 73 --csv four_bar.csv "
                            "--paths coupler.png",
    "jansen_build": "pinmech build models/linkages/jansen.toml -o jansen.urdf",
    "planar_arm_solve": "pinmech solve models/scenes/planar_arm.toml",
    "planar_arm_check": "pinmech check models/scenes/planar_arm.hand.toml",
    "slider_crank_forces": "pinmech forces models/scenes/slider_crank_dynamic.toml",
    "slider_crank_torque": "pinmech sweep models/scenes/slider_crank_dynamic.toml --csv sc.csv "
                           "--torque-plot torque.png",
    "slider_crank_check": "pinmech check models/scenes/slider_crank_dynamic.hand.toml",
    "four_bar_solve": "pinmech solve models/scenes/four_bar.toml",
    "crank_shaper_sweep": "pinmech sweep models/scenes/crank_shaper.toml --json lines.jsonl",
    "four_bar_sensitivity": "pinmech study models/studies/four_bar_sensitivity.toml --workers 0",
    "four_bar_tolerance": "pinmech study models/studies/four_bar_tolerance.toml --workers 0",
    "r_rtr_solve_json": "pinmech solve models/scenes/r_rtr.toml --json",
}

#: name -> a sweep whose CSV header (the first line it prints) a page lists, one column a line.
COLUMNS: dict[str, str] = {
    "r_rtr_csv_columns": "pinmech sweep models/scenes/r_rtr.toml --steps 2",
    "slider_crank_csv_columns": "pinmech sweep models/scenes/slider_crank_dynamic.toml --steps 2",
}

#: name -> a script of scripts/ whose printed Markdown (a deterministic table) a page includes.
SCRIPTS: dict[str, str] = {
    "singular_accuracy": "singular_accuracy.py",
}

#: README.md's shortened example: of r_rtr_solve (a tutorial shows it whole), its first
#: lines (the command, title, model, drivers), then these sections, whole.
README_EXCERPTS = {"r_rtr_solve_excerpt": ("r_rtr_solve", 4, ("Positions", "Velocities of points"))}


def run(command: str) -> str:
    """The text `command` prints, run in-process from a scratch folder beside models/."""
    from pinmech.cli import main

    argv = shlex.split(command)
    assert argv[0] == "pinmech", command
    out, err = io.StringIO(), io.StringIO()
    with tempfile.TemporaryDirectory() as scratch, _cwd(Path(scratch)):
        os.symlink(ROOT / "models", Path(scratch) / "models")
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv[1:])
        text = f"$ {command}\n{out.getvalue()}{err.getvalue()}"
        for folder in (str(ROOT), os.path.realpath(scratch), scratch):  # as from the repository's root
            text = text.replace(folder + os.sep, "")
    if code:
        text += f"(exit {code})\n"
    return text.rstrip() + "\n"


@contextlib.contextmanager
def _cwd(path: Path):
    before = Path.cwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(before)


def script_output(script: str) -> str:
    """What `python scripts/SCRIPT` prints (run in this process, as its `__main__`)."""
    import runpy

    out = io.StringIO()
    saved = sys.argv
    sys.argv = [str(ROOT / "scripts" / script)]
    try:
        with contextlib.redirect_stdout(out):
            runpy.run_path(str(ROOT / "scripts" / script), run_name="__main__")
    finally:
        sys.argv = saved
    return out.getvalue().rstrip() + "\n"


def excerpt(text: str, head: int, sections: tuple[str, ...]) -> str:
    """The first `head` lines of a report, then each named section (up to its blank line)."""
    lines = text.splitlines()
    out = lines[:head]
    for title in sections:
        start = lines.index(title)
        end = lines.index("", start) if "" in lines[start:] else len(lines)
        out += ["", *lines[start:end]]
    return "\n".join(out) + "\n...\n"


def exit_code_table() -> str:
    """The exit code of every error class, from pinmech/exceptions.py (Markdown table)."""
    import pinmech.draw  # noqa: F401  (registers DrawError)
    from pinmech import exceptions

    rows, todo = [], [exceptions.PinmechError, exceptions.Interrupted]
    while todo:
        cls = todo.pop(0)
        todo += cls.__subclasses__()
        if cls.__name__.startswith("_"):
            continue
        if cls is exceptions.SweepError:
            code = "its cause's"
        elif cls is exceptions.Interrupted:
            code = "130, 143, 129"
        else:
            code = str(cls.exit_code)
        summary = " ".join(cls.__doc__.split("\n\n")[0].split()).replace("|", "\\|")
        rows.append((code, cls.__name__, summary))
    rows.sort(key=lambda r: (int(r[0].split(",")[0]) if r[0][0].isdigit() else 99, r[1]))
    lines = ["| exit | error | when |", "| --- | --- | --- |", "| 0 | | success |"]
    lines += [f"| {code} | `{name}` | {summary} |" for code, name, summary in rows]
    return "\n".join(lines) + "\n"


def expected() -> dict[Path, str]:
    """Every generated file and the text it must hold now."""
    files = {GENERATED / f"{name}.txt": run(command) for name, command in COMMANDS.items()}
    for name, command in COLUMNS.items():
        header = run(command).splitlines()[1]
        files[GENERATED / f"{name}.txt"] = f"$ {command} | head -1\n" + "\n".join(header.split(",")) + "\n"
    for name, (source, head, sections) in README_EXCERPTS.items():
        files[GENERATED / f"{name}.txt"] = excerpt(files[GENERATED / f"{source}.txt"], head, sections)
    files[GENERATED / "exit_codes.md"] = exit_code_table()
    for name, script in SCRIPTS.items():
        files[GENERATED / f"{name}.md"] = script_output(script)
    return files


_MARKER = re.compile(r"(<!-- output: (\w+) -->\n```text\n)(.*?)(```)", re.S)


def readme_with(files: dict[Path, str], readme: str) -> str:
    """README.md with each marked output block holding its generated file."""
    return _MARKER.sub(lambda m: m.group(1) + files[GENERATED / f"{m.group(2)}.txt"] + m.group(4), readme)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="only say which file is out of date")
    args = parser.parse_args(argv)
    files = expected()
    readme = ROOT / "README.md"
    files[readme] = readme_with(files, readme.read_text(encoding="utf-8"))
    stale = [path for path, text in files.items() if not path.exists() or path.read_text(encoding="utf-8") != text]
    if args.check:
        for path in stale:
            print(f"{path.relative_to(ROOT)} is out of date: run python scripts/docs_outputs.py")
        return 1 if stale else 0
    GENERATED.mkdir(parents=True, exist_ok=True)
    for path in stale:
        path.write_text(files[path], encoding="utf-8")
        print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main())
