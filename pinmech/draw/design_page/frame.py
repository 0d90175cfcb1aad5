"""One turn of a drawn linkage, solved as `pinmech sweep` solves it: the data a page draws.

The spec is drawn (`linkage_from_spec`; its mechanism built once by `linkage_mechanism`,
then written in place while drags change only dimensions, `mechanism_reuse.py`) and given a scene (its driver
at the drawn pose's value, so the sweep starts on the drawn assembly; the one `save.py`
writes), and `Sweep.from_scene` solves it, its poses taken as arrays (`Sweep.chunks`) and its points read by one compiled call
(`frame_paths`, the numbers `evaluate_motion` gives `pinmech sweep`'s rows): the page's
curves are the rows `pinmech sweep` prints for the same two files. A pose that cannot
close (a fold, a branch end) is a gap in the curves, its error and fold kept.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pinmech.exceptions import ModelError
from pinmech.model.linkage import Linkage, linkage_from_spec
from pinmech.model.linkage_spec import LinkageSpec

#: Poses of one turn, both ends included (as `pinmech sweep`'s default).
STEPS = 361
#: Poses solved at a time: past a fold every pose fails, slowly, and the turn stops at the
#: first chunk that fails (the poses solved before the fold are all kept).
STOP_CHUNK = 16


@dataclass
class Turn:
    """A solved turn of the driver.

    Attributes:
        linkage: the drawing (SI, drawn pose).
        sweep: the `Sweep` that solved it (its mechanism, solver, driver).
        values: the driver's values [rad or m], STEPS of them.
        names: the drawn points, in the order of the arrays' axis 1.
        q: (STEPS, nq) configurations, NaN rows where a pose failed.
        v, a: (STEPS, nv) joint rates and accelerations at the driver's speed [rad/s, m/s, /s].
        position, velocity, acceleration: (STEPS, len(names), 2) world x, y [m, m/s, m/s^2].
        errors: pose index -> the error of a pose that failed (the turn stops at the first:
            the poses after it are not solved, their rows NaN).
        notes: pose index -> what the path passed on its way there.
        folds: pose index -> the driver's fold value [rad or m] its DriverLimitError names.
    """

    linkage: Linkage
    sweep: object
    values: np.ndarray
    names: list[str]
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    errors: dict[int, Exception] = field(default_factory=dict)
    notes: dict[int, str] = field(default_factory=dict)
    folds: dict[int, float] = field(default_factory=dict)

    def path(self, name: str) -> np.ndarray:
        """(STEPS, 2) positions of a drawn point [m], NaN where the pose failed."""
        return self.position[:, self.names.index(name)]


class TurnSolver:
    """Solves turns of changed specs, driven at `driver` (default: the tree's first joint)
    at `speed` (text, e.g. "60 rpm")."""

    def __init__(self, driver: str | None = None, speed: str = "60 rpm") -> None:
        from pinmech.draw.design_page.mechanism_reuse import MechanismReuse

        self.driver, self.speed = driver, speed
        self._reuse = MechanismReuse()

    def close(self) -> None:
        return None

    def rollback(self) -> None:
        """The last turn solved is not kept: the kept turn's mechanism as it was."""
        self._reuse.rollback()

    def solve(self, spec: LinkageSpec, source: str) -> Turn:
        """Draw `spec`, then sweep its driver over one turn from the drawn pose.

        Raises:
            ModelError: a drawing that cannot be drawn (circles that do not meet), a spatial linkage.
            PinmechError: a drawing that loads but cannot be swept (named by its class).
        """
        from pinmech.io.scene import Scene
        from pinmech.io.sweep import Sweep

        self._reuse.keep()  # the last turn, unless rolled back, is the page's
        linkage = linkage_from_spec(spec, source)
        if linkage.spatial:
            raise ModelError("the design page draws planar linkages only", path=source)
        mechanism = self._reuse.mechanism_for(linkage)  # the last one written in place, if it can be
        try:
            tables = scene_tables(linkage, Path(source).name, self._driver(mechanism, source), self.speed)
            scene = Scene.from_tables(tables, Path(source).with_name("scene.toml"))
            sweep = Sweep.from_scene(scene, mechanism=mechanism)  # the scene's linkage, drawn from `spec`
            return _turn(linkage, sweep, np.asarray(sweep.default_values(STEPS)))
        except Exception:
            self._reuse.rollback()
            raise

    def _driver(self, mechanism, source: str) -> tuple[str, float]:
        """The driver's name and its value at the drawn pose [rad or m] (the reference)."""
        name = self.driver or next(iter(mechanism.joints))
        if name not in mechanism.joints:
            raise ModelError(f"'{name}' is not a joint of the linkage's tree ({', '.join(mechanism.joints)})",
                             path=source)
        return name, float(mechanism.joint(name).coordinate(mechanism.reference))


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
    """The turn's poses as arrays, every drawn point's place, rate and acceleration."""
    from pinmech.solve.sweep_frames import frame_paths

    names = drawn_points(linkage)
    nq, nv = sweep.mechanism.model.nq, sweep.mechanism.model.nv
    q, v, a = np.full((len(values), nq), np.nan), np.zeros((len(values), nv)), np.zeros((len(values), nv))
    errors, notes, folds = {}, {}, {}
    for chunk in _chunks(sweep, values):
        rows = slice(chunk.start, chunk.start + len(chunk))
        q[rows], v[rows], a[rows] = chunk.solution.q, chunk.solution.v, chunk.solution.a
        for j, exc in chunk.errors.items():
            errors[chunk.start + j] = exc
            fold = sweep._fold(exc)
            if fold is not None:
                folds[chunk.start + j] = fold
        notes.update({chunk.start + j: note for j, note in chunk.notes.items()})
        if chunk.errors:  # the turn stops there, as `pinmech sweep` stops
            break
    solved = ~np.isnan(q).any(axis=1)
    position, velocity, acceleration = (np.full((len(values), len(names), 2), np.nan) for _ in range(3))
    if solved.any():
        paths = frame_paths(sweep.mechanism, names, q[solved], np.nan_to_num(v[solved]), np.nan_to_num(a[solved]))
        position[solved], velocity[solved] = paths.position[..., :2], paths.velocity[..., :2]
        acceleration[solved] = paths.acceleration[..., :2]
    return Turn(linkage, sweep, values, names, q, v, a, position, velocity, acceleration, errors, notes, folds)


def _chunks(sweep, values: np.ndarray):
    """The sweep's poses in chunks of STOP_CHUNK (`Sweep.chunks`'s solve, chunked finer: the
    poses are the same however chunked), so that a turn that stops at a fold stops soon."""
    from pinmech.solve.cycle import solve_range

    d = sweep.drivers
    return solve_range(sweep.solver, sweep.driver, values, driver_q=d.q, driver_v=d.v, driver_a=d.a,
                       chunk=STOP_CHUNK)


def angle_text(value: float, angular: bool) -> str:
    """A driver value for a message: degrees or millimetres."""
    return f"{math.degrees(value):.6g} deg" if angular else f"{value * 1e3:.6g} mm"
