"""Tables of many poses (sweeps and arm paths): CSV with units in the column names, and
JSON lines, each row written as its pose is solved, so a long sweep streams.

Angles are in degrees in CSV (as users plot them) and in radians in JSON (SI, as
`pinmech solve --json`); everything else is SI in both.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Iterable
from typing import IO, TYPE_CHECKING

import numpy as np

from pinmech.solve.certify import EVERY_POSE, certified_text, dial_note
from pinmech.solve.diagnostics_sweep import design_of
from pinmech.solve.limits import limit_violations
from pinmech.solve.motion import Motion
from pinmech.io.report import motion_dict

if TYPE_CHECKING:
    from pinmech.model.mechanism import Mechanism
    from pinmech.solve.path import PathPoint
    from pinmech.io.sweep import Sweep, SweepPose


#: A CSV cell of the condition-number column at a pose the certification dial left uncertified.
NOT_CERTIFIED_CELL = "not certified"


def sweep_dial_note(sweep: Sweep) -> str | None:
    """The line a sweep's outputs carry where its solver certified fewer poses than all
    (certify.py), else None."""
    return dial_note(sweep.solver.certify)


def columns(sweep: Sweep, first: Motion) -> list[str]:
    """CSV column names with units, from the first solved pose."""
    unit = "deg" if sweep.is_angular else "m"
    cols = [f"{sweep.driver}.q [{unit}]"]
    planar = sweep.mechanism.plane_normal is not None
    for name, link in first.links.items():
        if planar:
            angle = "angle" if link.angle_axis == "x" else f"angle_of_{link.angle_axis}_axis"  # x normal to the plane
            cols += [f"{name}.{angle} [deg]", f"{name}.omega [rad/s]", f"{name}.alpha [rad/s^2]"]
        else:
            cols += [f"{name}.|omega| [rad/s]", f"{name}.|alpha| [rad/s^2]"]
    for name in first.points:
        cols += [f"{name}.{c} [m]" for c in "xyz"]
        cols += [f"{name}.v{c} [m/s]" for c in "xyz"] + [f"{name}.|v| [m/s]"]
        cols += [f"{name}.a{c} [m/s^2]" for c in "xyz"] + [f"{name}.|a| [m/s^2]"]
    for name in first.sliders:
        cols += [f"{name}.s [m]", f"{name}.v_rel [m/s]", f"{name}.a_rel [m/s^2]", f"{name}.|a_cor| [m/s^2]"]
    cols += design_of(sweep).columns()  # transmission and pressure angles, mechanical advantage
    return cols + ["closure_residual [1]", "condition_number [1]", "newton_iterations [1]", "beyond_limits", "pose",
                   "error"]


def row(sweep: Sweep, pose: SweepPose, width: int) -> list[object]:
    """One CSV row in the units of `columns` (empty cells where the pose failed)."""
    first = math.degrees(pose.value) if sweep.is_angular else pose.value
    if pose.motion is None:
        return [first] + [""] * (width - 3) + ["failed", pose.error]
    m, out = pose.motion, [first]
    normal = sweep.mechanism.plane_normal
    for link in m.links.values():
        if normal is not None:
            out += [math.degrees(link.angle), float(normal @ link.angular_velocity),
                    float(normal @ link.angular_acceleration)]
        else:
            out += [_norm(link.angular_velocity), _norm(link.angular_acceleration)]
    for p in m.points.values():
        v, a = p.velocity.tolist(), p.acceleration.tolist()
        out += p.position.tolist() + v + [math.hypot(*v)] + a + [math.hypot(*a)]
    for s in m.sliders.values():
        out += [s.s, s.s_dot, s.s_ddot, _norm(s.coriolis_acceleration)]
    out += design_of(sweep).cells(pose)
    acc = pose.accuracy
    beyond = " ".join(v.joint for v in limit_violations(sweep.mechanism, m))
    condition = acc.condition if acc.certified else NOT_CERTIFIED_CELL
    return out + [acc.residual, condition, acc.iterations, beyond, "interpolated" if pose.interpolated else "solved",
                  ""]


class SweepCsv:
    """Writes a sweep's poses as CSV rows as they come (`add`), then `close`."""

    def __init__(self, sweep: Sweep, stream: IO[str]) -> None:
        self.sweep, self.stream, self.writer = sweep, stream, csv.writer(stream)
        self.commented = False
        self.header: list[str] | None = None
        self.pending: list[SweepPose] = []  # failures before the first solved pose
        self.count = 0

    def add(self, pose: SweepPose) -> None:
        if self.header is None:
            if pose.motion is None:
                self.pending.append(pose)  # the header waits for the first solved pose
                return
            self.header = self._columns(pose)
            self._comment()
            self.writer.writerow(self.header)
            for failed in self.pending:
                self._write(failed)
            self.pending = []
        self._write(pose)

    def _comment(self) -> None:
        """A `# ` line before the header where the sweep certified fewer poses than all."""
        note = sweep_dial_note(self.sweep)
        if note and not self.commented:
            self.stream.write(f"# {note}; {NOT_CERTIFIED_CELL}: a pose left to its residuals\n")
            self.commented = True

    def _columns(self, pose: SweepPose) -> list[str]:
        """The header, from the first solved pose (subclasses add columns)."""
        return columns(self.sweep, pose.motion)

    def _row(self, pose: SweepPose) -> list[object]:
        """One row in the units of the header (subclasses add cells)."""
        return row(self.sweep, pose, len(self.header))

    def _write(self, pose: SweepPose) -> None:
        self.writer.writerow([f"{x:.12g}" if type(x) is float else x for x in self._row(pose)])
        self.count += 1

    def close(self) -> int:
        """Finish (a sweep where every pose failed gets a short table); the row count."""
        if self.header is None:
            self._comment()
            unit = "deg" if self.sweep.is_angular else "m"
            self.writer.writerow([f"{self.sweep.driver}.q [{unit}]", "pose", "error"])
            for failed in self.pending:
                first = math.degrees(failed.value) if self.sweep.is_angular else failed.value
                self.writer.writerow([_cell(first), "failed", failed.error])
                self.count += 1
        return self.count


def write_csv(sweep: Sweep, poses: Iterable[SweepPose], stream: IO[str]) -> int:
    """Stream poses to CSV as they are solved; returns the number of rows written."""
    table = SweepCsv(sweep, stream)
    for pose in poses:
        table.add(pose)
    return table.close()


class SweepJsonLines:
    """One JSON object per pose and line: the driver value [rad or m], the motion in SI
    (as `pinmech solve --json`), the accuracy, and how the pose was found."""

    def __init__(self, sweep: Sweep, stream: IO[str]) -> None:
        self.sweep, self.stream = sweep, stream

    def add(self, pose: SweepPose) -> None:
        self.stream.write(json.dumps(self._entry(pose)) + "\n")

    def _entry(self, pose: SweepPose) -> dict:
        """The pose's JSON object (subclasses add keys)."""
        entry = {"index": pose.index, self.sweep.driver: pose.value, "error": pose.error,
                 "pose": "failed" if pose.motion is None else "interpolated" if pose.interpolated else "solved"}
        certified = self.sweep.solver.certify
        if certified != EVERY_POSE:  # the dial: which poses have their condition number and assembly checked
            entry["certified"] = certified_text(certified)
        if pose.note:  # a change point passed or a fold crossed on the way to this pose
            entry["note"] = pose.note
        if pose.motion is not None:
            entry.update(motion_dict(pose.motion))
            entry["limit_violations"] = [v.as_dict() for v in limit_violations(self.sweep.mechanism, pose.motion)]
            entry["accuracy"] = pose.accuracy.as_dict()
            design = design_of(self.sweep).entry(pose)
            if design is not None:
                entry["design"] = design
        return entry

    def close(self) -> None:
        self.stream.flush()


class PathCsv:
    """An arm path: time, each one-dof joint's q [deg or m], v, a (a `<mimic>` follower's
    from its leader's), the drift, the condition number."""

    def __init__(self, mechanism: Mechanism, stream: IO[str]) -> None:
        self.mechanism, self.writer = mechanism, csv.writer(stream)
        self.joints = [j for j in mechanism.joints.values() if j.nv == 1 or j.name in mechanism.mimics]
        header = ["t [s]"]
        for j in self.joints:
            angular = mechanism.mimics[j.name].kind != "prismatic" if j.name in mechanism.mimics else j.is_angular
            units = ("deg", "rad/s", "rad/s^2") if angular else ("m", "m/s", "m/s^2")
            header += [f"{j.name}.{x} [{u}]" for x, u in zip(("q", "v", "a"), units)]
        self.writer.writerow(header + ["drift [m]", "angular_drift [rad]", "condition_number [1]"])
        self.count = 0

    def add(self, point: PathPoint) -> None:
        cells = [f"{point.time:.9g}"]
        for j in self.joints:
            q = self.mechanism.coordinate(point.q, j.name)
            mimic = self.mechanism.mimics.get(j.name)
            scale = mimic.multiplier if mimic else 1.0  # idx_v of a follower is its leader's
            angular = mimic.kind != "prismatic" if mimic else j.is_angular
            cells += [f"{math.degrees(q) if angular else q:.12g}", f"{scale * point.v[j.idx_v]:.12g}",
                      f"{scale * point.a[j.idx_v]:.12g}"]
        self.writer.writerow(cells + [f"{point.drift:.3e}", f"{point.angular_drift:.3e}", f"{point.condition:.6g}"])
        self.count += 1

    def close(self) -> int:
        return self.count


def _norm(x: np.ndarray) -> float:
    return math.hypot(*x.tolist())


def _cell(x: object) -> object:
    return f"{x:.12g}" if isinstance(x, float) else x
