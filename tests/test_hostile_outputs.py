"""Output paths under attack, over every writer: a symbolic link planted at an output's name,
a missing or read-only folder, a folder given as a file, two outputs on one path, `..`, an
output over an input, and a writer stopped mid-write. Each output is written whole through
one function (outputs.write_with, through a temporary file renamed over the name) or not
at all: the link is replaced, never written through onto the file it points to; a bad
path is one line with exit 2 before anything is computed.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from pinmech.cli import main
from pinmech.outputs import write_whole, write_with

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "models" / "scenes" / "four_bar.toml"
LINKAGE = ROOT / "models" / "linkages" / "four_bar.toml"
STUDY = ROOT / "models" / "studies" / "four_bar_sensitivity.toml"
SYNTH = ROOT / "models" / "synthesis" / "four_bar_function.toml"

#: writer -> (argv with {out} the output's path, the file written at {out} + suffix)
WRITERS = {
    "sweep --csv": (["sweep", str(SCENE), "--steps", "3", "--csv", "{out}"], ""),
    "sweep --json": (["sweep", str(SCENE), "--steps", "3", "--json", "{out}"], ""),
    "sweep --plot": (["sweep", str(SCENE), "--steps", "3", "--plot", "{out}"], ""),
    "polygon -o": (["polygon", str(SCENE), "-o", "{out}"], ""),
    "build -o": (["build", str(LINKAGE), "-o", "{out}"], ""),
    "study --out .csv": (["study", str(STUDY), "--workers", "0", "--quiet", "--out", "{out}"], ".csv"),
    "study --out .json": (["study", str(STUDY), "--workers", "0", "--quiet", "--out", "{out}"], ".json"),
}
SUFFIX = {"sweep --plot": ".png", "polygon -o": ".svg", "build -o": ".urdf"}


def _argv(writer: str, out: Path) -> list[str]:
    return [a.format(out=out) for a in WRITERS[writer][0]]


def _name(writer: str) -> str:
    return "out" + SUFFIX.get(writer, "") if WRITERS[writer][1] == "" else "out"


@pytest.mark.parametrize("writer", WRITERS)
@pytest.mark.parametrize("dangling", [False, True], ids=["link to a file", "dangling link"])
def test_a_link_at_the_output_is_replaced_never_written_through(writer, dangling, tmp_path, capsys):
    victim = tmp_path / "elsewhere" / "victim.txt"
    victim.parent.mkdir()
    if not dangling:
        victim.write_text("not yours\n")
    out = tmp_path / _name(writer)
    written = Path(f"{out}{WRITERS[writer][1]}")
    os.symlink(victim, written)
    assert main(_argv(writer, out)) == 0, capsys.readouterr().err
    assert not written.is_symlink() and written.stat().st_size > 0
    assert victim.read_text() == "not yours\n" if not dangling else not victim.exists()
    assert sorted(p.name for p in victim.parent.iterdir()) == ([] if dangling else ["victim.txt"])


@pytest.mark.parametrize("writer", WRITERS)
@pytest.mark.parametrize("place, said", [("missing/sub/{name}", "no such folder"), ("{name}/..", "folder"),
                                         ("..", "folder"), ("dir", "folder")])
def test_a_path_that_cannot_be_the_file_is_one_line_before_any_work(writer, place, said, tmp_path, capsys):
    (tmp_path / "dir").mkdir()
    (tmp_path / "dir.csv").mkdir()  # `--out dir` of a study: its PREFIX.csv a folder
    (tmp_path / "dir.json").mkdir()
    out = tmp_path / place.format(name=_name(writer))
    if place == "..":
        out = Path(os.path.relpath(tmp_path.parent, Path.cwd())) / ".."
    assert main(_argv(writer, out)) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and said in err and "Traceback" not in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir", "dir.csv", "dir.json"]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a read-only folder")
@pytest.mark.parametrize("writer", WRITERS)
def test_a_read_only_folder_is_one_line_before_any_work(writer, tmp_path, capsys):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        assert main(_argv(writer, folder / _name(writer))) == 2
    finally:
        folder.chmod(0o755)
    err = capsys.readouterr().err.strip()
    assert "not writable" in err and len(err.splitlines()) == 1 and not list(folder.iterdir())


@pytest.mark.parametrize("argv, said", [
    (["sweep", str(SCENE), "--steps", "3", "--csv", "{t}/a", "--json", "{t}/a"], "both name"),
    (["sweep", str(SCENE), "--steps", "3", "--csv", "{t}/a", "--json", "{t}/./x/../a"], "both name"),
    (["sweep", str(SCENE), "--steps", "3", "--csv", str(SCENE)], "would overwrite"),
    (["synth", "{t}/syn_1.toml", "--out", "{t}/syn"], "would overwrite"),
])
def test_two_outputs_on_one_path_or_an_output_over_an_input_is_refused(argv, said, tmp_path, capsys):
    for name in ("syn.toml", "syn_1.toml"):
        (tmp_path / name).write_text(SYNTH.read_text())
    before = sorted(p.name for p in tmp_path.iterdir())
    (tmp_path / "x").mkdir()
    assert main([a.format(t=tmp_path) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert said in err and len(err.splitlines()) == 1, err
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*before, "x"])


def test_a_study_writing_into_a_missing_folder_is_refused_before_it_runs(tmp_path, capsys):
    """Before: the study ran, then failed writing PREFIX.csv (minutes lost on a big one)."""
    assert main(["study", str(STUDY), "--workers", "0", "--out", str(tmp_path / "none" / "run")]) == 2
    captured = capsys.readouterr()
    assert "no such folder" in captured.err and captured.out == ""  # no summary: nothing ran


@pytest.mark.parametrize("stop", [KeyboardInterrupt, SystemExit, OSError])
def test_a_writer_stopped_mid_write_leaves_the_old_file_and_a_partial(stop, tmp_path):
    """SIGINT and SIGTERM arrive as KeyboardInterrupt (interrupts.py): the file asked for
    keeps its old content; what was written is NAME.partial; no temporary is left. (A
    sweep's streamed rows stopped by a real signal: tests/test_outputs.py.)"""
    out = tmp_path / "out.csv"
    out.write_text("old, complete\n")

    def half(temporary: Path) -> None:
        temporary.write_text("half of the rows\n")
        raise stop()

    with pytest.raises(stop):
        write_with(out, half)
    assert out.read_text() == "old, complete\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv", "out.csv.partial"]


def test_write_whole_replaces_a_link_with_the_text(tmp_path):
    victim = tmp_path / "victim"
    victim.write_text("keep")
    os.symlink(victim, tmp_path / "link")
    write_whole(tmp_path / "link", "new")
    assert victim.read_text() == "keep" and (tmp_path / "link").read_text() == "new"
    assert not (tmp_path / "link").is_symlink()


def test_every_writer_goes_through_the_atomic_writer():
    """No module writes a file but outputs.py (and user_cache.py, atomic on its own): a
    `write_text`, `open(..., "w")`, `savefig(path)` or `.save(path)` elsewhere would write
    the destination in place, half a file on a signal."""
    import re

    allowed = {"outputs.py", "user_cache.py"}
    pattern = re.compile(r"\.write_text\(|\.write_bytes\(|open\([^)]*[\"'][wax]b?[\"']|savefig\(|"
                         r"pictures\[0\]\.save\(path|(?<!recorder)\.save\(path")
    found = []
    for path in (ROOT / "pinmech").rglob("*.py"):
        if path.name in allowed:
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            if pattern.search(line) and "temporary" not in line and "folder" not in line:
                found.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert not found, "\n".join(found)
