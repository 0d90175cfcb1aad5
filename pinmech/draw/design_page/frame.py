"""One turn of a drawn linkage, solved as `pinmech sweep` solves it: the data a page draws.

The spec is written to a private folder with a scene beside it (its driver at the drawn
pose's value, so the sweep starts on the drawn assembly), and `Sweep.from_scene` solves
it: the page's curves are the rows `pinmech sweep` prints for the same two files. A pose
that cannot close (a fold, a branch end) is a gap in the curves, its driver value kept.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pinmech.exceptions import ModelError
from pinmech.model.linkage import Linkage, linkage_from_spec
from pinmech.model.linkage_spec import LinkageSpec
from pinmech.model.linkage_write import linkage_toml

#: Poses of one turn, both ends included (as `pinmech sweep`'s default).
STEPS = 361


@dataclass
class Turn:
    """A solved turn of the driver.

    Attributes:
        linkage: the drawing (SI, drawn pose).
        sweep: the `Sweep` that solved it (its mechanism, solver, driver).
        values: the driver's values [rad or m], STEPS of them.
        paths: point name -> (STEPS, 2) world positions [m], NaN where the pose failed.
        poses: the `SweepPose` of every value (motion None where it failed).
        errors: pose index -> why it failed (the named error's text).
        folds: driver values [rad or m] of the folds the turn met.
    """

    linkage: Linkage
    sweep: object
    values: np.ndarray
    paths: dict[str, np.ndarray]
    poses: list
    errors: dict[int, str] = field(default_factory=dict)
    folds: list[float] = field(default_factory=list)


class TurnSolver:
    """Solves turns of changed specs in one private folder (the files of the last one kept)."""

    def __init__(self, driver: str | None = None, speed: str = "60 rpm") -> None:
        self._folder = tempfile.TemporaryDirectory(prefix="pinmech-design-")
        self.folder = Path(self._folder.name)
        self.driver, self.speed = driver, speed

    def close(self) -> None:
        self._folder.cleanup()

    def solve(self, spec: LinkageSpec, source: str) -> Turn:
        """Draw `spec`, then sweep its driver over one turn from the drawn pose.

        Raises:
            ModelError: a drawing that cannot be drawn (circles that do not meet), a spatial linkage.
            PinmechError: a drawing that loads but cannot be swept (named by its class).
        """
        from pinmech.io.scene import Scene
        from pinmech.io.sweep import Sweep

        linkage = linkage_from_spec(spec, source)
        if linkage.spatial:
            raise ModelError("the design page draws planar linkages only", path=source)
        (self.folder / "linkage.toml").write_text(linkage_toml(spec), encoding="utf-8")
        tables = scene_tables(linkage, "linkage.toml", self._driver(spec, source), self.speed)
        sweep = Sweep.from_scene(Scene.from_tables(tables, self.folder / "scene.toml"))
        values = np.asarray(sweep.default_values(STEPS))
        return _turn(linkage, sweep, values)

    def _driver(self, spec: LinkageSpec, source: str) -> tuple[str, float]:
        """The driver's name and its value at the drawn pose [rad or m]."""
        from pinmech.model.linkage_model import linkage_mechanism

        mech = linkage_mechanism(linkage_from_spec(spec, source))
        name = self.driver or next(iter(mech.joints))
        if name not in mech.joints:
            raise ModelError(f"'{name}' is not a joint of the linkage's tree ({', '.join(mech.joints)})", path=source)
        return name, mech.joint(name).coordinate(mech.reference)


def drawn_points(linkage: Linkage) -> list[str]:
    """The names drawn on the page: every pin and point a link carries."""
    carried = {n for names in linkage.links.values() for n in names}
    return [n for n in linkage.points if n in carried]


def scene_tables(linkage: Linkage, linkage_file: str, driver: tuple[str, float], speed: str) -> dict:
    """A scene's tables for the linkage: its driver at `driver`'s value (full precision),
    every drawn point reported."""
    name, value = driver
    return {"title": linkage.title, "linkage": linkage_file,
            "drivers": {name: {"angle": f"{value!r} rad", "speed": speed}},
            "report": {"points": drawn_points(linkage)}}


def _turn(linkage: Linkage, sweep, values: np.ndarray) -> Turn:
    names = drawn_points(linkage)
    paths = {n: np.full((len(values), 2), np.nan) for n in names}
    poses, errors, folds = [], {}, []
    for pose in sweep.poses(values, skip_failures=True):
        poses.append(pose)
        if pose.motion is None:
            errors[pose.index] = pose.error
            if pose.fold is not None and not any(abs(pose.fold - f) <= 1e-12 for f in folds):
                folds.append(pose.fold)
            continue
        for n in names:
            paths[n][pose.index] = pose.motion.points[n].position[:2]
    return Turn(linkage, sweep, values, paths, poses, errors, folds)


def angle_text(value: float, angular: bool) -> str:
    """A driver value for a message: degrees or millimetres."""
    return f"{math.degrees(value):.6g} deg" if angular else f"{value * 1e3:.6g} mm"
