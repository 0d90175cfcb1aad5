"""The one message for keys a file's table does not know: every reader (scenes, hand
files, linkages, sidecars, study and synthesis files) words it the same way."""

from __future__ import annotations

from collections.abc import Iterable


def unknown_keys(given: Iterable, known: Iterable[str], hint: str | None = None) -> str | None:
    """"unknown key(s) a, b; known: x, y" for the keys of `given` not in `known` (None when
    there are none); `known` is listed in the order given, or `hint` replaces that list."""
    names = list(known)
    unknown = sorted(str(key) for key in set(given) - set(names))
    if not unknown:
        return None
    return f"unknown key(s) {', '.join(unknown)}; {hint or 'known: ' + ', '.join(names)}"
