"""The typed readers under attack: every file a user hands pinmech (scene, drawn linkage,
study, synthesis, hand, URDF, robot.yaml) is read through file_limits and units, so a
hostile file is one line naming the file, with the reader's exit code, in well under a
second -- never a RecursionError's traceback, never minutes of parsing, never memory gone.

Each attack is a file made from a bundled one; the time bound (5 s for the whole command,
imports included, on a loaded 2-core machine) is what "refused before any work" means:
the hangs these attacks found ran past 20 s (pint's power towers: hours).
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest

from pinmech.cli import main
from pinmech.file_limits import MAX_FILE_BYTES, MAX_NESTING
from pinmech.units import MAX_UNIT_POWER, MIN_MAGNITUDE, to_si
from pinmech.exceptions import UnitError

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
#: (command, bundled file, extra arguments): one of each kind of file a command reads.
FILES = {
    "scene": ("solve", MODELS / "scenes" / "four_bar.toml", []),
    "linkage": ("build", MODELS / "linkages" / "four_bar.toml", ["-o", "{tmp}/out.urdf"]),
    "study": ("study", MODELS / "studies" / "four_bar_sensitivity.toml", ["--workers", "0", "--quiet"]),
    "synthesis": ("synth", MODELS / "synthesis" / "four_bar_function.toml", []),
}
EXIT = {"scene": 4, "linkage": 3, "study": 4, "synthesis": 4}


def _absolute(text: str) -> str:
    """The bundled file's relative model paths made absolute, so a copy runs from tmp_path."""
    return re.sub(r'((?:urdf|linkage|scene) = ")\.\./', rf'\g<1>{MODELS.as_posix()}/', text)


def _run(kind: str, tmp_path: Path, content: bytes) -> tuple[int, str, float]:
    """Write `content` as a `kind` file in tmp_path and run its command: exit code, stderr, seconds."""
    command, _, extra = FILES[kind]
    path = tmp_path / f"attack_{kind}.toml"
    path.write_bytes(content)
    began = time.monotonic()
    code = main([command, str(path), *(a.format(tmp=tmp_path) for a in extra)])
    return code, str(path), time.monotonic() - began


def _bundled(kind: str) -> str:
    return _absolute(FILES[kind][1].read_text(encoding="utf-8"))


def _refused(code: int, path: str, kind: str, err: str, seconds: float, *words: str) -> None:
    """One line, naming the file, the reader's exit code, each of `words`, within 5 s."""
    lines = err.strip().splitlines()
    assert code == EXIT[kind] and len(lines) == 1 and "Traceback" not in err, err
    assert path in lines[0] and all(w in lines[0] for w in words), lines[0]
    assert seconds < 5, seconds


@pytest.mark.parametrize("kind", FILES)
@pytest.mark.parametrize("attack", ["arrays", "inline tables"])
def test_nesting_deeper_than_any_file_needs_is_one_line(kind, attack, tmp_path, capsys):
    depth = 100_000 if attack == "arrays" else 5_000  # deep enough for tomllib's RecursionError
    nested = "[" * depth + "]" * depth if attack == "arrays" else "{a = " * depth + "1" + "}" * depth
    code, path, seconds = _run(kind, tmp_path, f"deep = {nested}\n{_bundled(kind)}".encode())
    _refused(code, path, kind, capsys.readouterr().err, seconds, "nested", str(MAX_NESTING))


@pytest.mark.parametrize("kind", FILES)
def test_nesting_just_past_the_limit_is_refused_too(kind, tmp_path, capsys):
    """Past MAX_NESTING but within the parser's stack: refused by the walk, not the stack."""
    depth = MAX_NESTING + 1
    code, path, seconds = _run(kind, tmp_path, f"deep = {'[' * depth}{']' * depth}\n{_bundled(kind)}".encode())
    _refused(code, path, kind, capsys.readouterr().err, seconds, "nested", str(MAX_NESTING))


@pytest.mark.parametrize("kind", FILES)
def test_a_file_larger_than_the_cap_is_refused_before_it_is_read(kind, tmp_path, capsys):
    """A sparse file of MAX_FILE_BYTES + 1 (no disk used): its size is read, not its bytes."""
    path = tmp_path / f"attack_{kind}.toml"
    with open(path, "wb") as stream:
        stream.write(_bundled(kind).encode())
        stream.truncate(MAX_FILE_BYTES + 1)
    command, _, extra = FILES[kind]
    began = time.monotonic()
    code = main([command, str(path), *(a.format(tmp=tmp_path) for a in extra)])
    _refused(code, str(path), kind, capsys.readouterr().err, time.monotonic() - began, "MiB",
             f"{MAX_FILE_BYTES // 2**20} MiB")


@pytest.mark.parametrize("kind", ["scene", "linkage"])
@pytest.mark.parametrize("form", ["byte-order mark", "CRLF", "byte-order mark and CRLF"])
def test_a_windows_editors_file_reads_as_the_same_file(kind, form, tmp_path, capsys):
    """A BOM and CRLF line ends change nothing: the same exit code and the same stdout."""
    text = _bundled(kind)
    assert _run(kind, tmp_path, text.encode()) [0] == 0
    plain = capsys.readouterr().out
    edited = text.replace("\n", "\r\n") if "CRLF" in form else text
    content = ("\ufeff" + edited if "mark" in form else edited).encode("utf-8")
    assert _run(kind, tmp_path, content)[0] == 0, capsys.readouterr().err
    assert capsys.readouterr().out == plain


@pytest.mark.parametrize("kind", FILES)
@pytest.mark.parametrize("content", [b"\xff\xfe t\x00i\x00", "title = 'caf\xe9'\n".encode("latin-1"), b"x = 1\n\x00\n"],
                         ids=["UTF-16", "Latin-1", "NUL"])
def test_text_that_is_not_utf8_toml_is_one_line(kind, content, tmp_path, capsys):
    code, path, seconds = _run(kind, tmp_path, content)
    _refused(code, path, kind, capsys.readouterr().err, seconds, "malformed TOML")


@pytest.mark.parametrize("text", ["1 mm**9**9**9", "1 mm^9^9^9", "1 mm**99999999/mm**99999998", "1 m^5",
                                  "1 mm ** 9 ** 9"])
def test_a_power_tower_in_a_unit_is_refused_at_once(text):
    """pint evaluates a unit's powers before pinmech sees the dimension: 9**9**9 has 369
    million digits. Refused by the text, in milliseconds."""
    began = time.monotonic()
    with pytest.raises(UnitError, match=rf"power is a whole number up to {MAX_UNIT_POWER}"):
        to_si(text, "length", where="f.toml, key")
    assert time.monotonic() - began < 0.5


@pytest.mark.parametrize("text, kind", [("2 kg*m^2", "moment_of_inertia"), ("3 mm/s**2", "acceleration"),
                                        ("1 m / s ^ 2", "acceleration")])
def test_the_powers_people_write_still_read(text, kind):
    assert to_si(text, kind) > 0


@pytest.mark.parametrize("text", ["1e-300 mm", "-1e-60 m", "5e-51 m"])
def test_a_length_whose_square_underflows_is_refused(text):
    """(1e-300 m)^2 is 0 in float64: a link of that length is no link to the solver."""
    with pytest.raises(UnitError, match="underflow"):
        to_si(text, "length", where="f.toml, key")
    assert to_si(f"{MIN_MAGNITUDE:g} m", "length") == MIN_MAGNITUDE  # the limit itself reads


@pytest.mark.parametrize("expression", ["9**9**9", "crank**9**9**9", "(crank)**99", "9**9**9 mm"])
def test_a_power_in_a_linkage_expression_is_refused_at_once(expression, tmp_path, capsys):
    """A drawn linkage's [params] and lengths: `**` is not in the expression grammar."""
    text = _bundled("linkage").replace('crank = "40 mm"', f'crank = "40 mm"\nzz = "{expression}"', 1)
    text = text.replace('A  = ["crank", "0 mm"]', f'A  = ["{expression}", "0 mm"]', 1)
    code, path, seconds = _run("linkage", tmp_path, text.encode())
    _refused(code, path, "linkage", capsys.readouterr().err, seconds)
