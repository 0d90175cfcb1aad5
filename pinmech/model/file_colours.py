"""The colour a URDF gives each link's visuals: the first `<visual>` whose `<material>`
has a `<color rgba>` or names a material defined at the top level with one. Read once per
file (and again when the file changes); pinmech.model.display falls back to its palette for
links the file does not colour."""

from __future__ import annotations

import functools
import os
import xml.etree.ElementTree as ET

RGB = tuple[float, float, float]


def urdf_link_colours(path: str) -> dict[str, RGB]:
    """Link name -> RGB in [0, 1] its URDF's visuals are painted with ({} for a file that
    is not a readable URDF, or colours none)."""
    try:
        stamp = os.stat(path).st_mtime_ns
    except OSError:
        return {}
    return dict(_read(path, stamp))


@functools.lru_cache(maxsize=32)
def _read(path: str, stamp: int) -> tuple[tuple[str, RGB], ...]:
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError):
        return ()
    if root.tag != "robot":
        return ()
    named = {m.get("name"): c for m in root.findall("material") if (c := _rgba(m)) is not None}
    out = []
    for link in root.findall("link"):
        for visual in link.findall("visual"):
            material = visual.find("material")
            colour = None if material is None else _rgba(material) or named.get(material.get("name"))
            if colour is not None:
                out.append((link.get("name", ""), colour))
                break
    return tuple(out)


def _rgba(material: ET.Element) -> RGB | None:
    """The RGB of a `<material>`'s `<color rgba>` (None without one, or unreadable)."""
    colour = material.find("color")
    try:
        values = [float(x) for x in colour.get("rgba", "").split()] if colour is not None else []
    except ValueError:
        return None
    return (values[0], values[1], values[2]) if len(values) == 4 else None
