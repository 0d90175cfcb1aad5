"""The colour a model file gives each link's visuals. URDF: the first `<visual>` whose
`<material>` has a `<color rgba>` or names a material defined at the top level with one.
MJCF: the first geom of a moving body that its `rgba` or material colours, as Pinocchio's
MJCF parser reads it (default classes included). Read once per file (and again when the
file changes); pinmech.model.display falls back to its palette for links the file does not
colour."""

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


#: The colour Pinocchio's MJCF parser gives a geom that neither `rgba` nor a material colours.
UNCOLOURED = (1.0, 1.0, 1.0)
_MJCF_CACHE: dict[tuple[str, int, int], dict[int, RGB]] = {}


def mjcf_joint_colours(path: str, model) -> dict[int, RGB]:
    """Pinocchio joint id -> RGB in [0, 1] of the first geom the MJCF file colours on it
    ({} for an unreadable file). `model`: the mechanism's model, built from that file."""
    try:
        stamp = os.stat(path).st_mtime_ns
    except OSError:
        return {}
    key = (path, stamp, id(model))
    if key not in _MJCF_CACHE:
        from pinmech.model.mjcf import mjcf_visuals

        out: dict[int, RGB] = {}
        for obj in mjcf_visuals(path, model).geometryObjects:
            rgb = (float(obj.meshColor[0]), float(obj.meshColor[1]), float(obj.meshColor[2]))
            if obj.parentJoint not in out and rgb != UNCOLOURED:
                out[obj.parentJoint] = rgb
        _MJCF_CACHE.clear()  # one file at a time is what a run draws
        _MJCF_CACHE[key] = out
    return dict(_MJCF_CACHE[key])

