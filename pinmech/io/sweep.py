"""Cycles: one driver swept through a range, every pose solved, closed and rated.

One `LoopSolver` (one `pin.Data`) serves the whole sweep, and each pose starts from the
previous one, so the sweep stays on the assembly branch it started on (solve_cycle.py:
how, and the accuracy choices). Poses are produced lazily, a chunk at a time, so a sweep
of a million poses streams to a CSV file in bounded memory.

The scene's `[sweep]` table (its keys, typed) is sweep_table.py's.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from pinmech.arguments import instance_of, real_number
from pinmech.exceptions import (AssemblyError, DriverLimitError, ModelError, PinmechError, SceneError, SingularPoseError,
                                SweepError)
from pinmech.model.mechanism import Mechanism
from pinmech.solve.motion import Motion, evaluate_motion
from pinmech.solve.results import Accuracy
from pinmech.io.scene import Scene
from pinmech.io.scene_model import (
    Drivers,
    check_scene_names,
    coincident_points,
    load_mechanism,
    report_lists,
    scene_drivers,
    scene_solver,
)
from pinmech.solve.crossing import is_change_point
from pinmech.solve.cycle import RangeChunk, solve_range
from pinmech.solve.loops import LoopSolver

_SINGULAR_PASSED = ("a singular pose the sweep went on past (a change point: the crossing of two branches, where "
                    "no assembly can be told and the rates are undefined): written as a failed row")
_SINGULAR_OTHER = ("a singular pose the sweep went on past (not a change point: the rates undefined there, the "
                   "pose after it closing on the sweep's assembly): written as a failed row")
_CHANGE_POINT_END = ("the sweep's {which} pose is a change point (the crossing of two branches: the pins in line, "
                     "the rates undefined): written as a failed row; {how}")
_FIRST_HOW = "the poses after it are on the branch continuation reaches from the drawn pose"
_LAST_HOW = "the sweep ends on it, on the branch it arrived on"


@dataclass(frozen=True)
class SweepPose:
    """One pose of a sweep: the driver value, and the motion (None where the pose failed).

    `interpolated` poses were not solved but interpolated between solved ones; their
    accuracy is the one measured where the interpolation error peaks (solve_cycle.py).
    """

    index: int
    value: float
    motion: Motion | None
    accuracy: Accuracy | None
    error: str = ""
    interpolated: bool = False
    note: str = ""
    fold: float | None = None  # a failed pose's DriverLimitError: the swept driver's fold [rad or m]


@dataclass(frozen=True)
class DriverValues(Sequence):
    """`steps` evenly spaced driver values from `first` to `last` [rad or m], both ends
    included, as `np.linspace` gives them but computed when read: a sweep streams in
    constant memory (a sweep of 1e10 poses too: the commands refuse more than
    counts.MAX_POSES before any work, as a study that would not end)."""

    first: float
    last: float
    steps: int

    def __post_init__(self) -> None:
        if isinstance(self.steps, bool) or not isinstance(self.steps, int) or self.steps < 1:
            raise ModelError(f"steps must be a positive whole number, got {self.steps!r}")
        object.__setattr__(self, "first", real_number(self.first, "the driver's first value"))
        object.__setattr__(self, "last", real_number(self.last, "the driver's last value"))
        if not (math.isfinite(self.first) and math.isfinite(self.last)):
            raise ModelError(f"the driver's range must be finite numbers, got {self.first!r} to {self.last!r}")

    def __len__(self) -> int:
        return self.steps

    def __getitem__(self, index):  # int -> float, slice -> array
        if isinstance(index, slice):
            return np.array([self._at(i) for i in range(*index.indices(self.steps))])
        i = index + self.steps if index < 0 else index
        if not 0 <= i < self.steps:
            raise IndexError(f"pose {index} of {self.steps}")
        return self._at(i)

    def __iter__(self) -> Iterator[float]:
        return (self._at(i) for i in range(self.steps))

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        return np.linspace(self.first, self.last, self.steps, dtype=dtype)

    def _at(self, i: int) -> float:
        if i == self.steps - 1 and self.steps > 1:
            return float(self.last)
        step = (self.last - self.first) / (self.steps - 1) if self.steps > 1 else 0.0
        return float(self.first + i * step)


def sweep_options(scene: Scene) -> dict[str, Any]:
    """The `[sweep]` keys the scene gives (validated when it was read), by their names in the file."""
    return scene.file.sweep.given()


def _no_drivers(mechanism: Mechanism, arm_pose: bool = False) -> str:
    """What to add to a scene without `[drivers]` to sweep it."""
    motors = mechanism.motors
    if motors:
        tables = " and ".join(f"[drivers.{m}]" for m in motors)
        return (f"has no [drivers] to sweep: add {tables} with their angle and speed (the motors the sidecar "
                f"names, {', '.join(motors)}, drive a solve at rest, but a sweep needs the ones it moves)")
    arm = "; or, for an arm held at its [pose], a [[task]] to follow in time (pinmech path)" if arm_pose else ""
    return ("has no [drivers] to sweep: add a [drivers.JOINT] table (angle, speed) for each joint the scene drives "
            f"({mechanism.mobility} for this mechanism){arm}")


@dataclass
class Sweep:
    """A scene set up for sweeping one of its drivers.

    Attributes:
        driver: the swept joint (the scene's first driver unless named).
        start: the scene's value of the driver [rad or m], where the sweep starts by default.
    """

    scene: Scene
    mechanism: Mechanism
    solver: LoopSolver
    driver: str
    start: float
    drivers: Drivers
    last_q: np.ndarray | None = None  # configuration of the last pose, None if it failed (drawings, return_gap)
    first_q: np.ndarray | None = None  # configuration of the first pose, None if it failed
    extra_points: tuple[str, ...] = ()  # frames a figure draws beyond the reported points (need_points)
    fold_end: float | None = None  # where a sweep `to_fold` ended: the driver's fold [rad or m]

    @classmethod
    def from_scene(cls, scene: Scene, driver: str | None = None, *, mechanism: Mechanism | None = None) -> Sweep:
        """The sweep of a scene's driver (its only one unless `driver` names one).

        `mechanism`: the scene's model, loaded already (`load_mechanism(scene)`, or the
        drawn linkage it names, `linkage_mechanism`); default: loaded here.

        Raises:
            SceneError: a scene without drivers (a task scene is followed in time by
                `pinmech path`), or a driver that is not one of the scene's.
        """
        instance_of(scene, Scene, "Sweep.from_scene's scene")
        if scene.is_task:
            raise SceneError("has no [drivers] to sweep; a task scene ([[task]]) is followed in time: "
                             "pinmech path SCENE --duration ... (pinmech animate SCENE --duration ... "
                             "animates it)", path=str(scene.path), key="drivers")
        mechanism = load_mechanism(scene) if mechanism is None else mechanism
        if not scene.file.drivers:
            raise SceneError(_no_drivers(mechanism, bool(scene.file.pose)), path=str(scene.path), key="drivers")
        drivers = scene_drivers(scene, mechanism)
        check_scene_names(scene, mechanism)
        name = driver or drivers.names[0]
        if name not in drivers.names:
            raise SceneError(f"'{name}' is not a driver of the scene ({', '.join(drivers.names)})",
                             path=str(scene.path), key="drivers")
        solver = scene_solver(scene, mechanism, drivers)
        return cls(scene, mechanism, solver, name, float(drivers.q[drivers.names.index(name)]), drivers)

    @property
    def is_angular(self) -> bool:
        return self.mechanism.joint(self.driver).is_angular

    def default_values(self, steps: int = 361) -> DriverValues:
        """One full turn from the scene's angle (both ends included), or +-the mechanism's
        size; computed when read (a `DriverValues`)."""
        span = 2 * math.pi if self.is_angular else self.mechanism.length_scale
        return DriverValues(self.start, self.start + span, steps)

    def chunks(self, values: Iterable[float], *, start: str = "predictor", batch: bool = True,
               interpolate: int = 1, through_folds: bool = False) -> Iterator[RangeChunk]:
        """The poses' q, v, a and accuracy as arrays, a chunk at a time (no motion read-out):
        the quickest way through a long sweep. Options: see `poses`."""
        d = self.drivers
        numeric = isinstance(values, np.ndarray) and values.dtype.kind in "fiu"  # solve_range checks finiteness
        return solve_range(self.solver, self.driver, values if numeric else self._checked(values), driver_q=d.q,
                           driver_v=d.v, driver_a=d.a, start=start, batch=batch, interpolate=interpolate,
                           through_folds=through_folds)

    def poses(self, values: Iterable[float], *, skip_failures: bool = False, start: str = "predictor",
              batch: bool = True, interpolate: int = 1, warm_start: bool | None = None,
              predictor: bool | None = None, through_folds: bool = False,
              to_fold: bool = False, past_change_points: bool = False) -> Iterator[SweepPose]:
        """Solve the poses one after the other, each from the previous one (lazy).

        Args:
            skip_failures: keep a failing pose as a row with its error instead of stopping.
            start: "predictor" (default): from the previous pose moved along its path
                derivatives (q' dx + q'' dx^2 / 2 on the manifold), one Newton step;
                "warm": from the previous pose as it is; "cold": every pose from the
                scene's guess (slower, and it may change branch).
            batch: on dense sweeps, solve the poses between exactly solved ones together
                from interpolated guesses (same tolerance, several times faster).
            interpolate: > 1 solves every n-th pose and interpolates the others (quintic
                Hermite in q, q', q''), for dense plots: faster, less accurate, with the
                accuracy measured in each interval.
            warm_start, predictor: older spelling of `start` ("warm" is predictor=False,
                "cold" warm_start=False).
            through_folds: at a fold of the driver (a limit angle), go on onto the other
                branch with the driver turning back, values past the fold mirrored at it
                (a whole coupler curve of a non-Grashof linkage); the pose after it carries
                a note. Without it, the poses past a fold fail with DriverLimitError.
            to_fold: at a fold of the driver (without through_folds), end the sweep at the
                last pose before it: a rocker driven to its toggle has reached the end of its
                range of motion on this assembly, not an error (`fold_end` says where).
            past_change_points: a pose exactly on a change point (singular, or on both
                assemblies at once) becomes a failed row with a note when the pose after it
                closes, and the sweep goes on (without: it stops the sweep, as any failure); along
                the continuation only (`start="predictor"`): a cold or warm start's failure is
                never taken for a change point.

        Raises:
            SweepError: a pose where the loop cannot close or the Jacobian is singular,
                naming the driver value, unless `skip_failures` (then the row says why).
        """
        if warm_start is False:
            start = "cold"
        elif predictor is False:
            start = "warm"
        points, links = report_lists(self.scene)
        if self.extra_points:  # the reported points (None: every point), then the frames a figure draws
            points = list(dict.fromkeys([*(self.mechanism.points if points is None else points), *self.extra_points]))
        coincident = coincident_points(self.scene)
        self.fold_end = None
        held: tuple[SweepPose, SweepError, bool] | None = None  # a singular pose, written if the sweep goes on past it
        before = None  # the last pose solved [q]
        for chunk in self.chunks(values, start=start, batch=batch, interpolate=interpolate,
                                 through_folds=through_folds):
            for j, value in enumerate(chunk.values.tolist()):
                index = chunk.start + j
                if held is not None and j not in chunk.errors:
                    yield held[0]
                    held = None
                if j in chunk.errors:
                    exc = chunk.errors[j]
                    before = self.last_q if self.last_q is not None else before
                    self.last_q = None  # the sweep did not end on a solved pose (return_gap: NaN)
                    if index == 0:
                        self.first_q = None
                    fold = self._fold(exc)
                    if to_fold and fold is not None and not skip_failures and index > 0:
                        self.fold_end = fold
                        return
                    stop = SweepError(f"sweep stopped at {self.driver} = {self._format(value)}: {exc}",
                                      driver=self.driver, value=value, cause=exc)
                    # a change point's own pose, kept if the next one closes: only along the
                    # continuation (a cold or warm start's other assembly is no change point)
                    if past_change_points and not skip_failures and held is None and fold is None \
                            and start == "predictor" and isinstance(exc, (SingularPoseError, AssemblyError)):
                        crossing = self._crossing(exc, value, before)
                        if index == 0 and crossing:  # the sweep begins on it: it goes on from the drawn pose
                            yield SweepPose(index, value, None, None, f"{type(exc).__name__}: {exc}",
                                            note=_CHANGE_POINT_END.format(which="first", how=_FIRST_HOW))
                            continue
                        if index > 0:
                            held = (SweepPose(index, value, None, None, f"{type(exc).__name__}: {exc}",
                                              note=_SINGULAR_PASSED if crossing else _SINGULAR_OTHER), stop, crossing)
                            continue
                    if not skip_failures:
                        raise held[1] if held is not None else stop from exc
                    yield SweepPose(index, value, None, None, f"{type(exc).__name__}: {exc}", fold=fold,
                                    note=chunk.notes.get(j, ""))  # a change point passed on the way
                    continue
                sol = chunk.solution
                self.last_q = sol.q[j]
                if index == 0:
                    self.first_q = sol.q[j]
                with self.solver.lock:  # the solver's Data, which another thread may be using
                    motion = evaluate_motion(self.mechanism, self.solver.data, sol.q[j], sol.v[j], sol.a[j],
                                             points=points, links=links, coincident=coincident)
                yield SweepPose(index, value, motion, sol.accuracy(j), interpolated=bool(chunk.interpolated[j]),
                                note=chunk.notes.get(j, ""))
        if held is not None and not held[2]:
            raise held[1]
        if held is not None:  # the sweep ends on a change point: a row, not a failure
            yield SweepPose(held[0].index, held[0].value, None, None, held[0].error,
                            note=_CHANGE_POINT_END.format(which="last", how=_LAST_HOW))

    def _crossing(self, exc: Exception, value: float, before) -> bool:
        """Whether a singular (or unkept) pose at the swept `value` is a change point: the
        closed pose the error carries, else the pose Newton closes there from the last
        solved one, is a crossing of two branches (crossing.py)."""
        q = getattr(exc, "partial", None)
        if q is None and before is not None:
            row = np.array(self.drivers.q, dtype=float)
            row[self.drivers.names.index(self.driver)] = value
            try:
                q, _, _ = self.solver.close(before, row)
            except PinmechError:
                return False
        if q is None:
            return False
        with self.solver.lock:
            return is_change_point(self.solver, q, self.driver)

    def need_points(self, names) -> None:
        """Evaluate these frames (a drawn linkage's pins, by name) at every pose as well, for a
        figure that draws them though the scene does not report them."""
        self.extra_points = tuple(dict.fromkeys([*self.extra_points, *names]))

    def _fold(self, exc: Exception) -> float | None:
        """The swept driver's value at the fold a DriverLimitError names [rad or m], else None."""
        if not isinstance(exc, DriverLimitError) or len(exc.limit) != len(self.drivers.names):
            return None
        return float(exc.limit[self.drivers.names.index(self.driver)])

    def return_gap(self) -> float:
        """How far the sweep's last pose is from its first: the largest joint difference,
        angles modulo a turn [rad], slides in mechanism sizes (NaN where either failed).
        After a sweep of whole turns of the driver, a mechanism back on its start has a gap
        at the closure tolerance."""
        if self.first_q is None or self.last_q is None:
            return math.nan
        return self.solver.turn_gap(self.first_q, self.last_q)

    def _checked(self, values: Iterable[float]) -> Iterator[float]:
        """The driver values as floats, or a ModelError naming the first that is not a finite number."""
        unit = "rad" if self.is_angular else "m"
        if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
            raise ModelError(f"values of {self.driver} must be numbers [{unit}], got {values!r:.80}",
                             path=self.mechanism.source)
        for index, value in enumerate(values):
            cast = isinstance(value, (str, bytes, bool, np.bool_, complex, np.complexfloating))  # never cast
            try:
                number = math.nan if cast else float(value)
            except (TypeError, ValueError):
                number = math.nan
            if not math.isfinite(number):
                raise ModelError(f"value {index} of {self.driver} is {value!r:.40}, not a finite number [{unit}]",
                                 path=self.mechanism.source)
            yield number

    def _format(self, value: float) -> str:
        return f"{math.degrees(value):.6g} deg" if self.is_angular else f"{value:.6g} m"
