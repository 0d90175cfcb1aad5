"""Cycles: one driver swept through a range, every pose solved, closed and rated.

One `LoopSolver` (one `pin.Data`) serves the whole sweep, and each pose starts from the
previous one, so the sweep stays on the assembly branch it started on. Rows are produced
lazily, so a sweep of a million poses streams to a CSV file in bounded memory.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import IO

import numpy as np
import pinocchio as pin

from pinmech.analysis import (
    Drivers,
    check_scene_names,
    coincident_points,
    load_mechanism,
    report_lists,
    scene_drivers,
    scene_guess,
)
from pinmech.exceptions import LoopClosureError, SceneError, SingularPoseError, SweepError
from pinmech.mechanism import Mechanism
from pinmech.motion import Motion, evaluate_motion
from pinmech.results import Accuracy
from pinmech.scene import Scene
from pinmech.solve_loops import LoopSolver


@dataclass(frozen=True)
class SweepPose:
    """One pose of a sweep: the driver value, and the motion (None where the pose failed)."""

    index: int
    value: float
    motion: Motion | None
    accuracy: Accuracy | None
    error: str = ""


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
    last_q: np.ndarray | None = None  # configuration of the last pose solved (for drawing)

    @classmethod
    def from_scene(cls, scene: Scene, driver: str | None = None) -> Sweep:
        if not scene.section("drivers"):
            raise SceneError("the scene has no [drivers.NAME] table to sweep (an arm's task scene is "
                             "followed in time by `pinmech path`)", path=str(scene.path), key="drivers")
        mechanism = load_mechanism(scene)
        drivers = scene_drivers(scene, mechanism)
        check_scene_names(scene, mechanism)
        scene.names("sweep", "links"), scene.names("sweep", "points")  # lists of names, or a SceneError now
        name = driver or drivers.names[0]
        if name not in drivers.names:
            raise SceneError(f"'{name}' is not a driver of the scene ({', '.join(drivers.names)})",
                             path=str(scene.path), key="drivers")
        solver = LoopSolver(mechanism, drivers.names, **scene.solver_options())
        return cls(scene, mechanism, solver, name, float(drivers.q[drivers.names.index(name)]), drivers)

    @property
    def is_angular(self) -> bool:
        return self.mechanism.joint(self.driver).is_angular

    def default_values(self, steps: int = 361) -> np.ndarray:
        """One full turn from the scene's angle (both ends included), or +-the mechanism's size."""
        span = 2 * math.pi if self.is_angular else self.mechanism.length_scale
        return np.linspace(self.start, self.start + span, steps)

    def poses(self, values: Iterable[float], *, skip_failures: bool = False, warm_start: bool = True,
              predictor: bool = True) -> Iterator[SweepPose]:
        """Solve the poses one after the other, each from the previous one (lazy).

        Args:
            skip_failures: keep a failing pose as a row with its error instead of stopping.
            warm_start: start Newton from the previous pose (default; keeps the branch).
                False starts every pose from the scene's guess: slower, and may jump branch.
            predictor: (default) start from the previous pose moved along its own rates
                and accelerations (q + v dt + a dt^2 / 2 on the manifold, dt = step / driver
                speed): fewer Newton iterations, and the last one lands at rounding level
                (see scripts/benchmark_sweep.py). Falls back to the warm start at zero speed.

        Raises:
            SweepError: a pose where the loop cannot close or the Jacobian is singular,
                naming the driver value, unless `skip_failures` (then the row says why).
        """
        d = self.drivers
        k = d.names.index(self.driver)
        q_drv, v_drv, a_drv = d.q.copy(), d.v.copy(), d.a.copy()
        guess = scene_guess(self.scene, self.mechanism)
        points, links = report_lists(self.scene)
        coincident = coincident_points(self.scene)
        start_guess, previous = guess, None
        model = self.mechanism.model
        for index, value in enumerate(values):
            q_drv[k] = value
            if predictor and previous is not None and v_drv[k] != 0:
                dt = (value - previous[0]) / v_drv[k]
                guess = pin.integrate(model, previous[1].q, previous[1].v * dt + 0.5 * previous[1].a * dt * dt)
            elif not warm_start:
                guess = start_guess
            try:
                sol = self.solver.solve(q_drv, v_drv, a_drv, guess=guess)
            except (LoopClosureError, SingularPoseError) as exc:
                where = self._format(value)
                if not skip_failures:
                    raise SweepError(f"sweep stopped at {self.driver} = {where}: {exc}", driver=self.driver,
                                     value=float(value), cause=exc) from exc
                yield SweepPose(index, float(value), None, None, f"{type(exc).__name__}: {exc}")
                continue
            guess, previous = sol.q, (value, sol)
            self.last_q = sol.q
            motion = evaluate_motion(self.mechanism, self.solver.data, sol.q, sol.v, sol.a,
                                     points=points, links=links, coincident=coincident)
            yield SweepPose(index, float(value), motion, sol.accuracy)

    def _format(self, value: float) -> str:
        return f"{math.degrees(value):.6g} deg" if self.is_angular else f"{value:.6g} m"


# -------------------------------------------------------------------------- table
def columns(sweep: Sweep, first: Motion) -> list[str]:
    """CSV column names with units, from the first solved pose."""
    unit = "deg" if sweep.is_angular else "m"
    cols = [f"{sweep.driver}.q [{unit}]"]
    planar = sweep.mechanism.plane_normal is not None
    for name in first.links:
        if planar:
            cols += [f"{name}.angle [deg]", f"{name}.omega [rad/s]", f"{name}.alpha [rad/s^2]"]
        else:
            cols += [f"{name}.|omega| [rad/s]", f"{name}.|alpha| [rad/s^2]"]
    for name in first.points:
        cols += [f"{name}.{c} [m]" for c in "xyz"]
        cols += [f"{name}.v{c} [m/s]" for c in "xyz"] + [f"{name}.|v| [m/s]"]
        cols += [f"{name}.a{c} [m/s^2]" for c in "xyz"] + [f"{name}.|a| [m/s^2]"]
    for name in first.sliders:
        cols += [f"{name}.v_rel [m/s]", f"{name}.a_rel [m/s^2]", f"{name}.|a_cor| [m/s^2]"]
    return cols + ["closure_residual [1]", "condition_number [1]", "newton_iterations [1]", "error"]


def row(sweep: Sweep, pose: SweepPose, width: int) -> list[object]:
    """One CSV row in the units of `columns` (empty cells where the pose failed)."""
    first = math.degrees(pose.value) if sweep.is_angular else pose.value
    if pose.motion is None:
        return [first] + [""] * (width - 2) + [pose.error]
    m, out = pose.motion, [first]
    normal = sweep.mechanism.plane_normal
    for link in m.links.values():
        if normal is not None:
            out += [math.degrees(link.angle), float(normal @ link.angular_velocity),
                    float(normal @ link.angular_acceleration)]
        else:
            out += [float(np.linalg.norm(link.angular_velocity)), float(np.linalg.norm(link.angular_acceleration))]
    for p in m.points.values():
        out += list(p.position) + list(p.velocity) + [float(np.linalg.norm(p.velocity))]
        out += list(p.acceleration) + [float(np.linalg.norm(p.acceleration))]
    for name, s in m.sliders.items():
        out += [m.joints[name].v, m.joints[name].a, float(np.linalg.norm(s.coriolis_acceleration))]
    acc = pose.accuracy
    return out + [acc.residual, acc.condition, acc.iterations, ""]


def write_csv(sweep: Sweep, poses: Iterable[SweepPose], stream: IO[str]) -> int:
    """Stream poses to CSV as they are solved; returns the number of rows written."""
    writer = csv.writer(stream)
    header: list[str] | None = None
    pending: list[SweepPose] = []
    count = 0
    for pose in poses:
        if header is None:
            if pose.motion is None:
                pending.append(pose)  # header waits for the first solved pose
                continue
            header = columns(sweep, pose.motion)
            writer.writerow(header)
            for failed in pending:
                writer.writerow([_cell(x) for x in row(sweep, failed, len(header))])
                count += 1
        writer.writerow([_cell(x) for x in row(sweep, pose, len(header))])
        count += 1
    if header is None:
        writer.writerow([f"{sweep.driver}.q", "error"])
        for failed in pending:
            writer.writerow([failed.value, failed.error])
            count += 1
    return count


def _cell(x: object) -> object:
    return f"{x:.12g}" if isinstance(x, float) else x
