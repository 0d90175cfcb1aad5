"""A drawn linkage passed where a scene is expected (`pinmech solve four_bar.toml`): the
scene it stands for, its drivers at their drawn values.

The drivers are the linkage's ground pins, in its `ground` order, as many as its mobility
(a four-bar's O2; a five-bar's two motors), each at the value of the drawn pose and at a
unit rate (1 rad/s, 1 m/s: every velocity then reads as a rate per unit driver rate), and
every pin is reported. The scene is written out in the note the command prints, so the
user can copy it and drive the linkage otherwise.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from pinmech.exceptions import SceneError

#: Keys that make a TOML file a drawn linkage rather than a scene.
LINKAGE_KEYS = ("joints", "links")


def is_drawn_linkage(tables: dict[str, Any]) -> bool:
    """True for a drawn linkage's tables (joints and links, no model key of a scene)."""
    from pinmech.io.scene_file import MODEL_KEYS

    return all(k in tables for k in LINKAGE_KEYS) and not any(k in tables for k in MODEL_KEYS)


def implied_scene(path: Path, tables: dict[str, Any]) -> tuple[dict[str, Any], str]:
    """The scene's tables for the drawn linkage at `path`, and their TOML text.

    Raises:
        ModelError: the linkage itself is wrong (as `pinmech build` would say).
        SceneError: its ground pins cannot drive it (fewer tree pins on the ground than
            its mobility): the message says which scene to write.
    """
    from pinmech.angles import turn_degrees
    from pinmech.model.linkage_model import load_linkage

    mechanism = load_linkage(path)
    ground = [n for n in tables.get("ground", []) if isinstance(n, str)]
    pins = [n for n in ground if n in mechanism.joints and mechanism.joint(n).nv == 1]
    drivers = pins[: mechanism.mobility]
    if len(drivers) != mechanism.mobility:
        raise SceneError(f"a drawn linkage, not a scene: its mobility is {mechanism.mobility} and its ground pins "
                         f"that can drive it are {', '.join(pins) or 'none'}; write a scene: linkage = "
                         f"\"{path.name}\" with one [drivers.JOINT] angle (or position) per freedom "
                         f"(joints: {', '.join(mechanism.joints)})", path=str(path))
    table = {}
    for name in drivers:
        value = mechanism.coordinate(mechanism.reference, name)
        if mechanism.joint(name).is_angular:
            table[name] = {"angle": f"{_shortest(turn_degrees(math.degrees(value)))} deg", "speed": "1 rad/s"}
        else:
            table[name] = {"position": f"{_shortest(value * 1e3)} mm", "velocity": "1 m/s"}
    points = [n for n in tables.get("joints", {}) if _is_frame(mechanism, n)]
    scene = {"linkage": path.name, "drivers": table, "report": {"points": points}}
    if isinstance(tables.get("title"), str):
        scene["title"] = tables["title"]
    text = [f'linkage = "{path.name}"']
    for name, entry in table.items():
        text += [f"[drivers.{name}]", *(f'{key} = "{quantity}"' for key, quantity in entry.items())]
    text += ["[report]", "points = [" + ", ".join(f'"{n}"' for n in points) + "]"]
    return scene, "\n".join(text)


def _shortest(x: float) -> str:
    """The float's shortest exact text ("0", "62.72040000000001")."""
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text


def _is_frame(mechanism, name: str) -> bool:
    """Whether the model has a frame of this pin's name (a pin joining three links does not:
    it is split into A_upper, A_lower)."""
    from pinmech.exceptions import FrameNotFound

    try:
        mechanism.frame_id(name)
    except FrameNotFound:
        return False
    return True
