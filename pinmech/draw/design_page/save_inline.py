"""The linkage file rewritten in place: only the values a drag or a parameter changed are
replaced, on their own lines, so that every comment (inline or on its own line), the
spacing and the order of the user's file stay. Kept only when the rewritten text reads back
as exactly the page's linkage; otherwise (an adopted answer, an entry written over several
lines) the caller writes the linkage whole.
"""

from __future__ import annotations

import re
import tomllib

from pinmech.model.linkage_spec import LinkageSpec, linkage_spec
from pinmech.model.linkage_write import joint_toml, value_toml

#: The tables whose entries a page's edit changes: their values are rewritten line by line.
EDITED = ("params", "joints")
_TABLE = re.compile(r"^\s*\[([A-Za-z0-9_.-]+)\]\s*(#.*)?$")


def rewritten(text: str, old: LinkageSpec, new: LinkageSpec, source: str) -> str | None:
    """`text` (the file that reads as `old`) with the entries that differ in `new` rewritten,
    or None when it cannot be done line by line (keys added or removed, other tables
    changed, an entry over several lines, a result that does not read back as `new`)."""
    changes = _changes(old, new)
    if changes is None:
        return None
    lines = text.splitlines(keepends=True)
    table = ""
    for i, line in enumerate(lines):
        heading = _TABLE.match(line)
        if heading:
            table = heading.group(1)
            continue
        key = _key(line)
        if key is not None and (table, key) in changes:
            lines[i] = _with_value(line, changes.pop((table, key)))
            if lines[i] is None:
                return None
    if changes:
        return None
    out = "".join(lines)
    try:
        again = linkage_spec(tomllib.loads(out), source)
    except Exception:  # noqa: BLE001 -- any failure to read back means: write the file whole
        return None
    return out if again == new else None


def _changes(old: LinkageSpec, new: LinkageSpec) -> dict[tuple[str, str], str] | None:
    """(table, key) -> the new value's TOML text, for the entries of EDITED that differ."""
    for name in type(new).__struct_fields__:
        if name not in EDITED and getattr(old, name) != getattr(new, name):
            return None
    out = {}
    for table, text in (("params", value_toml), ("joints", joint_toml)):
        before, after = getattr(old, table), getattr(new, table)
        if list(before) != list(after):
            return None
        out.update({(table, k): text(v) for k, v in after.items() if before[k] != v})
    return out


def _key(line: str) -> str | None:
    """The bare or quoted key a `key = value` line sets (None for other lines)."""
    found = re.match(r'^\s*([A-Za-z0-9_-]+|"[^"\\]*")\s*=', line)
    return None if found is None else found.group(1).strip('"')


def _with_value(line: str, value: str) -> str | None:
    """`line` with the value after its "=" replaced, its trailing comment kept; None when the
    value does not end on this line (an array or table over several lines)."""
    start = line.index("=") + 1
    end = _value_end(line, start)
    if end is None:
        return None
    lead = line[start:len(line) - len(line[start:].lstrip(" \t"))]
    rest = line[end:]
    gap = rest[:len(rest) - len(rest.lstrip(" \t"))] if rest.strip() else ""
    newline = "\n" if line.endswith("\n") else ""
    return f"{line[:start]}{lead or ' '}{value}{gap}{rest.strip()}{newline}" if rest.strip() else \
        f"{line[:start]}{lead or ' '}{value}{newline}"


def _value_end(line: str, start: int) -> int | None:
    """Where the inline value starting after `start` ends (before spaces and a comment), or
    None when its brackets are still open at the line's end."""
    depth, quote, i, last = 0, "", start, start
    while i < len(line):
        ch = line[i]
        if quote:
            if ch == "\\" and quote == '"':
                i += 1
            elif ch == quote:
                quote = ""
            last = i + 1
        elif ch in "\"'":
            quote, last = ch, i + 1
        elif ch in "[{":
            depth, last = depth + 1, i + 1
        elif ch in "]}":
            depth, last = depth - 1, i + 1
        elif ch == "#":
            break
        elif not ch.isspace():
            last = i + 1
        i += 1
    return None if depth or quote else last
