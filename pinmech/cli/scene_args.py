"""A command's scene, read from its arguments (`--set`, `--angle` shortcuts), and options
that fall back on the scene's `[sweep]` values, each error blaming the flag or the key written."""

from __future__ import annotations

import argparse
from typing import Any, NamedTuple

from pinmech.exceptions import PinmechError, SceneError


class Option(NamedTuple):
    """An option's value and where it came from: its flag, or the scene's `[sweep]` key
    (`key` set), so that an error blames the one the user wrote."""

    value: Any
    flag: str
    key: str | None
    scene: Any

    @property
    def name(self) -> str:
        """How the user wrote it: "--steps", or "sweep.steps"."""
        return self.key or self.flag

    @property
    def where(self) -> str:
        """Where the user wrote it, for a message: "--steps", or "scene.toml: [sweep] steps"."""
        if self.key is None:
            return self.flag
        return f"{self.scene.path}: [sweep] {self.key.removeprefix('sweep.')}"

    def error(self, message: str) -> PinmechError:
        """A usage error naming the flag (exit 2), or a scene error naming the file and key (4)."""
        if self.key is None:
            return PinmechError(f"{self.flag} {message}")
        return SceneError(message, path=str(self.scene.path), key=self.key)

    def quantity(self, kind: str) -> float:
        """The value in SI; a unit error names the flag, or the file and key."""
        if self.key is None:
            from pinmech.units import to_si

            return to_si(self.value, kind, where=self.flag)
        return self.scene.quantity(self.value, kind, self.key)


def option_or_scene(given: Any, flag: str, scene, options: dict[str, Any], key: str, default: Any = None) -> Option:
    """A flag's value if given, else the scene's `[sweep] key`, else `default`."""
    if given is not None:
        return Option(given, flag, None, scene)
    if key in options:
        return Option(options[key], flag, f"sweep.{key}", scene)
    return Option(default, flag, None, scene)


def implied_note(scene) -> None:
    """Say on stderr which scene a drawn linkage passed as one was read as."""
    if scene.implied is not None:
        import sys

        body = "\n".join(f"    {line}" for line in scene.implied.splitlines())
        print(f"pinmech: {scene.path} is a drawn linkage, not a scene: solved at its drawn pose, as the scene\n"
              f"{body}\n  (write such a scene file to drive it from other values)", file=sys.stderr)


def certify_argument(value: str) -> str:
    """--certify's value checked (certify.py's levels), else an OptionRefused naming it."""
    from pinmech.exceptions import OptionError, OptionRefused
    from pinmech.solve.certify import checked_certify

    try:
        return checked_certify(value)
    except OptionError as exc:
        raise OptionRefused(f"--{exc}", options=["--certify"]) from None


def scene_from_args(args: argparse.Namespace):
    """The command's scene: its file with --set and the --angle/--speed/--acceleration
    shortcuts applied (a drawn linkage's file: the scene it stands for, noted on stderr)."""
    from pinmech.io.scene import Scene

    overrides = list(args.overrides)
    if getattr(args, "kernel", None):
        overrides.append(f'solver.kernel="{args.kernel}"')
    if getattr(args, "certify", None):
        overrides.append(f'solver.certify="{certify_argument(args.certify)}"')
    shortcuts = {"angle": args.angle, "speed": args.speed, "acceleration": args.acceleration}
    if any(shortcuts.values()):
        scene = Scene.load(args.scene)
        drivers = list(scene.file.drivers)
        if len(drivers) != 1:
            raise PinmechError(f"--angle/--speed/--acceleration need a single driver; {args.scene} has "
                               f"{len(drivers)}: use --set drivers.NAME.angle=...")
        name = drivers[0]
        spec = scene.file.drivers[name]
        keys = {"angle": spec.key_of(0), "speed": spec.key_of(1), "acceleration": "acceleration"}
        overrides += [f'drivers.{name}.{keys[k]}="{v}"' for k, v in shortcuts.items() if v]
    scene = Scene.load(args.scene, overrides)
    implied_note(scene)
    return scene
