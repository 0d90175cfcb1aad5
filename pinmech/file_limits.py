"""What pinmech reads from a user's file, at most: a size and a nesting depth, checked
before the content is parsed or walked, so that a huge or hostile file is one named error
in a fraction of a second, never minutes of parsing, a RecursionError or memory gone.

A scene, a drawn linkage, a study, a synthesis file or a hand file is a few kilobytes; a
URDF with its meshes named (not inlined) is rarely above a megabyte. `MAX_FILE_BYTES`
(64 MiB) leaves room for any of them; `MAX_NESTING` (64 levels of tables and arrays) for
any TOML or YAML a person writes (the files pinmech reads nest 4 deep at most).
A byte-order mark (Windows editors write one) and CRLF line ends are read as plain UTF-8.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pinmech.exceptions import PinmechError

#: The largest file pinmech reads [bytes].
MAX_FILE_BYTES = 64 * 2**20
#: The deepest nesting of tables and arrays in a TOML or YAML file pinmech reads.
MAX_NESTING = 64


def file_text(path: Path, what: str, error: type[PinmechError]) -> str:
    """The text of the file at `path` (UTF-8, a leading byte-order mark dropped), refused
    above MAX_FILE_BYTES before it is read (`what`: "scene", "URDF", ... for the message).

    Raises:
        error: "no such <what> file", a file too large, or text that is not UTF-8, naming
            the file.
    """
    return file_bytes(path, what, error).decode("utf-8-sig")


def file_bytes(path: Path, what: str, error: type[PinmechError]) -> bytes:
    """The bytes of the file at `path`, refused above MAX_FILE_BYTES (a pipe or a device
    is read up to the limit, not to its end)."""
    path = Path(path)
    if not path.is_file():
        raise error(f"no such {what} file", path=str(path))
    size = path.stat().st_size
    if size > MAX_FILE_BYTES:
        raise error(_too_large(what, size), path=str(path))
    with open(path, "rb") as stream:
        data = stream.read(MAX_FILE_BYTES + 1)
    if len(data) > MAX_FILE_BYTES:
        raise error(_too_large(what, len(data)), path=str(path))
    return data


def check_nesting(value: Any, what: str, path: Path, error: type[PinmechError]) -> None:
    """Refuse tables and arrays nested deeper than MAX_NESTING (walked without recursion).

    Raises:
        error: naming the file, the depth reached and the limit.
    """
    todo = [(value, 1)]
    while todo:
        item, depth = todo.pop()
        children = item.values() if isinstance(item, dict) else item if isinstance(item, list) else ()
        for child in children:
            if isinstance(child, (dict, list)):
                if depth + 1 > MAX_NESTING:
                    raise error(f"tables and arrays nested more than {MAX_NESTING} deep: no {what} file nests "
                                "so deep", path=str(path))
                todo.append((child, depth + 1))


def nested_too_deep(what: str, path: Path, error: type[PinmechError]) -> PinmechError:
    """The error of a file whose parser ran out of stack (a RecursionError)."""
    return error(f"tables and arrays nested too deep to read (more than {MAX_NESTING} levels): no {what} file "
                 "nests so deep", path=str(path))


def _too_large(what: str, size: int) -> str:
    return (f"{size / 2**20:.1f} MiB is more than the {MAX_FILE_BYTES / 2**20:.0f} MiB a {what} file may hold: "
            "is it the right file?")
