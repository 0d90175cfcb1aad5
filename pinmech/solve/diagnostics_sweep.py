"""Design diagnostics over a sweep: a few CSV columns and a JSON object per pose
(transmission and pressure angles [deg in CSV, rad in JSON], mechanical advantage), and
the summary printed when the sweep ends: each angle's least and largest value and where,
the outputs' limit positions (refined between the poses), swing or stroke, time ratio.

`DesignSweep` is fed every pose (as a figure recorder is); the tables ask it for the
pose's cells, computed once per pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pinmech.solve.diagnostics import _centre_dict, advantage_of, advantage_unit, barker_words
from pinmech.exceptions import DiagnosticError, PinmechError
from pinmech.solve.angle_watch import CONSTANT_ANGLE_DEG, AngleExtremes, AngleWatch
from pinmech.solve.change_points import BranchWatch
from pinmech.solve.fold_pose import fold_pose
from pinmech.solve.grashof import loop_classes
from pinmech.angles import position_text
from pinmech.solve.limit_positions import LimitFinder, LimitPosition, extreme_label, travel
from pinmech.solve.limit_watch import RateWatch
from pinmech.model.planar_linkage import planar_linkage
from pinmech.solve.instant_centres import instant_centres
from pinmech.solve.transmission import dyad_angles, find_dyads, find_outputs, input_links, output_rate

#: A ratio of rates (a mechanical advantage) whose spread over the poses is below this share
#: of it is one value: rates come from solves rounded at ~1e-15 relative (times the
#: Jacobian's condition number, under 1e3 away from toggles).
CONSTANT_RELATIVE = 1e-9


@dataclass
class _Extreme:
    """The least and largest of a quantity over the poses, and the driver values there."""

    low: float = math.inf
    low_at: float = math.nan
    high: float = -math.inf
    high_at: float = math.nan

    def add(self, value: float, at: float) -> None:
        if value < self.low:
            self.low, self.low_at = value, at
        if value > self.high:
            self.high, self.high_at = value, at

    @property
    def constant(self) -> bool:
        """Whether the quantity is one value at every pose (a parallelogram's rocker turning
        with its crank): its least and largest within CONSTANT_RELATIVE of it, so that the
        pose "where" it is least would be rounding's choice."""
        return bool(math.isfinite(self.low) and self.high - self.low <= CONSTANT_RELATIVE * abs(self.high))


class DesignSweep:
    """The diagnostics of each pose of a sweep, and of the whole sweep.

    Args:
        sweep: the `Sweep` (its mechanism, drivers and solver options).
    """

    def __init__(self, sweep) -> None:
        from pinmech.solve.loops import LoopSolver

        self.sweep, self.reason = sweep, ""
        self._cache: tuple[int, dict] = (-1, {})
        self._limits: tuple[int, list] = (-1, [])
        self._extremes: tuple[int, list] = (-1, [])
        self.count = 0
        try:
            self.linkage = planar_linkage(sweep.mechanism)
        except DiagnosticError as exc:
            self.linkage, self.reason = None, str(exc).split(": ", 1)[-1]
            return
        names = list(sweep.drivers.names)
        self.dyads = find_dyads(self.linkage, names)
        self.outputs = find_outputs(self.linkage, names)
        self.k = names.index(sweep.driver)
        inputs = input_links(self.linkage, [sweep.driver])
        self.input_link = self.linkage.names[inputs[0]] if inputs else None
        self.solver = LoopSolver(sweep.mechanism, names, **sweep.scene.solver_options())
        self.finder = LimitFinder(self.solver, self.linkage, self.k, sweep.drivers.q, self.dyads)
        self.unit = np.eye(len(names))[self.k]
        self.angles = AngleWatch(self.linkage, self.dyads, self._place_at)
        self.branches = BranchWatch(self.linkage)
        self.branch_notes: list[str] = []  # every change of branch the sweep made, in order
        self._branch_due = False  # name the branch at the next pose solved (after a change point's own pose)
        self._previous: float | None = None  # the last solved pose's driver value
        self._step: float | None = None  # the driver's last step between solved poses [rad or m]
        self._folds: list[float] = []
        self._fold_from: list[tuple[float, np.ndarray, float]] = []  # (fold, closed q, its driver value)
        self._fold_at: list[tuple[float, np.ndarray]] = []  # (fold, closed q at it), located
        self._ended: list[float] = []  # Sweep.fold_end values counted
        self._previous_q: np.ndarray | None = None
        self.advantages = [_Extreme() for _ in self.outputs]
        size = sweep.mechanism.length_scale
        self.watches = [RateWatch(1.0 if o.kind == "pin" else size) for o in self.outputs]

    @property
    def applicable(self) -> bool:
        return self.linkage is not None

    # ------------------------------------------------------------------ per pose
    def evaluate(self, pose) -> dict:
        """{"angles": [(mu, acute, pressure) deg per dyad], "advantage": [per output]} at a
        pose (empty where it failed); statistics and limit brackets updated once."""
        if self._cache[0] == pose.index:
            return self._cache[1]
        out: dict = {}
        if self.applicable:
            self._fold(pose)
        if self.applicable and pose.motion is None:
            self._previous, self._previous_q = None, None
            if "is a change point" in pose.note:  # a sweep's first or last pose: name the branch
                self._branch_due = True
                out["notes"] = [f"loop {n} ends on its change point, arriving on its {f} branch"
                                for (n, *_), f in zip(self.branches.loops, self.branches.last) if f is not None]
        if self.applicable and pose.motion is not None:
            q = self._q(pose.motion)
            v, _, _ = self.solver.rates(q, self.unit, np.zeros(len(self.unit)), closed=not pose.interpolated)
            self.linkage.place(q, v)
            rates = [output_rate(self.linkage, o) for o in self.outputs]
            angles = [dyad_angles(self.linkage, d) for d in self.dyads]
            out = {"angles": [(a.mu, a.mu_acute, a.pressure) for a in angles],
                   "advantage": [advantage_of(r, o, self.sweep.mechanism.length_scale) for r, o in zip(rates, self.outputs)], "qv": (q, v)}
            self._record(pose, q, rates, angles, out)
            self.linkage.place(q)
            changes = self.branches.add(self._driver(pose.value))
            self.branch_notes += changes
            out["notes"] = changes
            if "passed a change point" in pose.note or self._branch_due:  # the engine's note: name the branch it kept
                self._branch_due = False
                out["notes"] += [f"loop {n} after the change point: on its {f} branch" for n, f in self.branches.forms()]
        self._cache = (pose.index, out)
        return out

    def _q(self, motion) -> np.ndarray:
        mech = self.sweep.mechanism
        q = mech.neutral()
        for name, joint in motion.joints.items():
            mech.set_coordinate(q, name, joint.q)
        return q

    def _fold(self, pose) -> None:
        """A fold met before this pose: the DriverLimitError's value, or, crossed with
        `--through-folds` (the driver turns back there, the values past it mirrored), the
        point p with p - x0 + p - x1 = the step (x0, x1 the driver values either side)."""
        if pose.fold is not None:
            self._add_fold(pose.fold)
            self.angles.cut()
        if "crossed a fold" not in pose.note:
            return
        if self._previous is not None and self._step is not None and pose.motion is not None:
            self._add_fold(0.5 * (self._previous + pose.value + self._step))
        self._step = None if self._step is None else -self._step

    def _add_fold(self, fold: float) -> None:
        """A fold of the driver met after the last pose (estimated at `fold`): located to
        rounding from that pose (fold_pose.py), and its angles counted among the extremes,
        the driver's end of travel being part of its range of motion."""
        if any(abs(fold - x) <= 1e-9 for x in self._folds):
            return
        self._folds.append(fold)
        if self._previous_q is None:
            return
        try:
            x, q = fold_pose(self.solver, self.k, self.finder.x, self._previous_q, self._previous, fold)
        except PinmechError:  # not located better than the engine's estimate: no pose at it
            self._fold_from.append((fold, self._previous_q, self._previous))
            return
        if self.sweep.is_angular:
            x = fold + math.remainder(x - fold, 2 * math.pi)
        self._folds[-1] = x
        self._fold_at.append((x, q))
        self._fold_from.append((x, self._previous_q, self._previous))
        self.linkage.place(q)
        self.angles.add(x, q, self._previous, [dyad_angles(self.linkage, d) for d in self.dyads],
                        origin=(self._previous, self._previous_q))

    def _end_fold(self) -> None:
        """The sweep ended at a fold of the driver (`Sweep.fold_end`): counted once."""
        end = getattr(self.sweep, "fold_end", None)
        if self.applicable and end is not None and end not in self._ended:
            self._ended.append(end)
            self._add_fold(end)

    def _record(self, pose, q: np.ndarray, rates: list[float], angles: list, out: dict) -> None:
        if not self.count:
            self._first = pose.value
        self.count += 1
        if "crossed a fold" in pose.note:
            self.angles.cut()
        self.angles.add(pose.value, q, self._previous, angles, bracket=not pose.interpolated)
        if self._previous is not None and "crossed a fold" not in pose.note:
            self._step = pose.value - self._previous
        self._previous, self._previous_q = pose.value, q
        for stat, value, watch, rate in zip(self.advantages, out["advantage"], self.watches, rates):
            if math.isfinite(value):
                stat.add(abs(value), pose.value)
            if pose.note or pose.interpolated:  # no limit bracketed across a fold crossed or an interpolation
                watch.end()
            if not pose.interpolated:
                watch.add(pose.value, q, rate)

    def add(self, pose) -> None:
        """A pose of the sweep (the recorder interface of `Outputs`)."""
        self.evaluate(pose)

    def save(self, path) -> None:  # a recorder with no figure
        return None

    # ------------------------------------------------------------------ tables
    def columns(self) -> list[str]:
        """CSV columns: per dyad (named by its pin B) mu and the pressure angle, per output
        its mechanical advantage, with units."""
        if not self.applicable:
            return []
        cols = []
        for d in self.dyads:
            b = d.joint.name
            cols += [f"{b}.transmission_angle [deg]", f"{b}.pressure_angle [deg]"]
        for o in self.outputs:
            cols.append(f"{self.linkage.names[o.output]}.mechanical_advantage [{self._unit(o)}]")
        return cols

    def cells(self, pose) -> list[object]:
        """One CSV row of `columns` (blank where the pose failed)."""
        out = self.evaluate(pose)
        if not out:
            return [""] * len(self.columns())
        cells: list[object] = []
        for mu, _, phi in out["angles"]:
            cells += [mu, phi]
        return cells + [x if math.isfinite(x) else "inf" for x in out["advantage"]]

    def entry(self, pose) -> dict | None:
        """The pose's `design` object of the JSON lines (SI: angles [rad], places [m]): the
        dyads' angles, the outputs' mechanical advantage, every instant centre."""
        out = self.evaluate(pose)
        if not out:
            return None
        names = self.linkage.names
        self.linkage.place(*out["qv"])  # rates per unit driver rate: the centres do not depend on the speed
        centres = instant_centres(self.linkage, velocities=True).values()
        return {
            "instant_centres": [_centre_dict(self.linkage, c) for c in centres],
            "dyads": {d.joint.name: {"transmission_angle": math.radians(mu), "transmission_angle_acute":
                                     math.radians(acute), "pressure_angle": math.radians(phi)}
                      for d, (mu, acute, phi) in zip(self.dyads, out["angles"])},
            "mechanical_advantage": {names[o.output]: (x if math.isfinite(x) else None)
                                     for o, x in zip(self.outputs, out["advantage"])},
            "notes": out["notes"],
        }

    def notes(self, pose) -> list[str]:
        """What the pose's diagnostics noticed: a change of branch at a change point."""
        return self.evaluate(pose).get("notes", [])

    def _unit(self, output) -> str:
        return advantage_unit(self.sweep.is_angular, output)

    # ------------------------------------------------------------------ summary
    def limits(self) -> list[list[LimitPosition]]:
        """Each output's limit positions, bisected between the poses that bracket them."""
        return [[limit for limit, _ in found] for found in self.limit_poses()]

    def limit_poses(self) -> list[list[tuple[LimitPosition, np.ndarray]]]:
        """Each output's limit positions and the closed configuration at each (bisected
        once for the poses seen so far: the summary and the figures share them)."""
        if self._limits[0] == self.count:
            return self._limits[1]
        out = []
        for output, watch in zip(self.outputs, self.watches):
            found = []
            brackets, at_poses = watch.limits()
            for b in brackets:
                try:
                    x, q = self.finder.bisect(output, b.q0, b.x0, b.x1, b.r0)
                except PinmechError:  # a pose between that does not close: no limit stated there
                    continue
                found.append((self.finder.limit(output, q, x, extreme_label(b.r0, b.x1 - b.x0)), q))
            found += [(self.finder.limit(output, e.q, e.x, e.label), e.q) for e in at_poses]
            along = sorted(found, key=lambda f: abs(f[0].driver - self._first))  # in the sweep's order
            out.append(once_a_turn(along, self.sweep.is_angular))
        self._limits = (self.count, out)
        return out

    def angle_extremes(self) -> list[AngleExtremes]:
        """Each dyad's least and largest transmission angle [0, 180] deg and largest pressure
        angle over the sweep's range, toggles, change points and folds included (angle_watch.py)."""
        self._end_fold()
        if self._extremes[0] != self.count + len(self._ended):
            self._extremes = (self.count + len(self._ended), self.angles.extremes())
        return self._extremes[1]

    def _place_at(self, q0: np.ndarray, x0: float, x: float) -> None:
        """The linkage at driver value x, the pose followed from the closed q0 at x0."""
        self.linkage.place(self.finder.pose(q0, x0, x))

    def folds(self) -> list[float]:
        """The driver values of the folds the sweep met [rad or m]: where it stopped
        (DriverLimitError) or, with `--through-folds`, where the driver turned back."""
        self._end_fold()
        return list(self._folds)

    def fold_poses(self) -> list[tuple[float, np.ndarray]]:
        """(driver value [rad or m], closed q) at each fold, followed from the last pose
        before it; where the step onto the fold itself does not close (the loop's Jacobian
        is singular there), the nearest of 1e-12 .. 1e-6 of the step short of it."""
        self._end_fold()
        located = {x for x, _ in self._fold_at}
        out = list(self._fold_at)
        for fold, q0, x0 in self._fold_from:
            if fold in located:
                continue
            for short in (0.0, 1e-12, 1e-9, 1e-6):
                try:
                    out.append((fold, self.finder.pose(q0, x0, fold - short * (fold - x0))))
                    break
                except PinmechError:
                    continue
        return out

    def summary(self, span: float | None = None) -> list[str]:
        """Lines for the end of a sweep; `span`: the driver's travel [rad] when it was one
        whole turn (then the time ratio of each output with two limit positions)."""
        if not self.applicable:
            return [f"design: planar diagnostics: not applicable ({self.reason})"]
        if not self.count:
            return []
        lines = [f"design: loop {'-'.join(x.links)}: {x.kind}, {x.label}{barker_words(x, self.input_link)} "
                 f"({x.condition})" for x in loop_classes(self.linkage)]
        fmt = self._driver
        for d, x in zip(self.dyads, self.angle_extremes()):
            what = "transmission angle mu" if d.kind == "pin" else "transmission angle mu = 90 deg - pressure angle"
            where = "located between" if x.refined else "over"
            if x.constant:  # an inverted slider's block square to its rod, say
                mu = round(0.5 * (x.low + x.high), 9)  # to the constancy asked: 90.0, not 90 - 3e-14
                lines.append(f"design: {d.name(self.linkage)}: transmission angle mu = {mu:.6g} deg at every pose, "
                             f"pressure angle |90 deg - mu| = {abs(90.0 - mu):.6g} deg (constant to "
                             f"{CONSTANT_ANGLE_DEG:g} deg over the {self.count} poses)")
                continue
            lines.append(f"design: {d.name(self.linkage)}: {what} from {x.low:.6g} deg at {fmt(x.low_at)} to "
                         f"{x.high:.6g} deg at {fmt(x.high_at)}; pressure angle |90 deg - mu| up to {x.pressure:.6g} "
                         f"deg at {fmt(x.pressure_at)} (acute mu least {x.acute_low:.6g} deg) ({where} the "
                         f"{self.count} poses)")
            lines += [f"design: {d.name(self.linkage)}: coupler and output in line (mu = 0 or 180 deg) at {fmt(y)}"
                      for y in x.in_line]
        lines += [f"design: {self.sweep.driver}: fold (limit position of the driver) at {fmt(x)}"
                  for x in self.folds()]
        lines += [f"design: {note}" for note in self.branch_notes]
        for output, found, stat in zip(self.outputs, self.limits(), self.advantages):
            name = self.linkage.names[output.output]
            lines += self._travel_lines(name, found, span)
            infinite = " (infinite at its limit positions)" if found else ""
            if stat.constant:
                lines.append(f"design: {name}: mechanical advantage |driver rate / {name}'s rate| "
                             f"{stat.low:.6g} [{self._unit(output)}] at every pose (constant to {CONSTANT_RELATIVE:g} "
                             f"of it over the {self.count} poses){infinite}")
            elif math.isfinite(stat.low):
                lines.append(f"design: {name}: mechanical advantage |driver rate / {name}'s rate| least "
                             f"{stat.low:.6g} [{self._unit(output)}] at {self._driver(stat.low_at)} over the poses"
                             f"{infinite}")
        return lines

    def _travel_lines(self, name: str, found: list[LimitPosition], span: float | None) -> list[str]:
        if not found:
            return []
        t = travel(found, span)
        fmt, lines = self._driver, []
        for x in t.limits:
            value = f"{position_text(math.degrees(x.value))} deg" if x.kind == "rocker extreme" else f"{x.value:.6g} m along the slide"
            if x.slide is not None:
                value += f" (slide coordinate s = {x.slide:.6g} m, as the CSV)"
            lay = f", driving link and coupler {x.toggle} (toggle)" if x.toggle else ""
            lines.append(f"design: {name}: {x.kind} ({x.label}) {value} at {fmt(x.driver)}{lay}")
        if t.travel is not None:
            word = (f"swing {math.degrees(t.travel):.6g} deg" if t.kind == "rocker extreme"
                    else f"stroke {t.travel:.6g} m")
            lines.append(f"design: {name}: {word}")
        if t.ratio is not None:
            lines.append(f"design: {name}: time ratio Q = {t.ratio:.6g} (strokes over {math.degrees(t.alpha):.6g} "
                         f"and {math.degrees(t.beta):.6g} deg of the driver)")
        return lines

    def _driver(self, value: float) -> str:
        """A driver position as the summary prints it: an angle in [0, 360) deg (angles.py)."""
        unit = f"{position_text(math.degrees(value))} deg" if self.sweep.is_angular else f"{value:.6g} m"
        return f"{self.sweep.driver} = {unit}"


def once_a_turn(found: list[tuple], angular: bool) -> list[tuple]:
    """The limits, each once: a sweep of a whole turn that begins on a limit ends on it too
    (the same pose of the mechanism, the driver a turn on: the same limit)."""
    out: list[tuple] = []
    for limit, q in found:
        if not any(angular and x.label == limit.label and abs(math.remainder(limit.driver - x.driver, 2 * math.pi))
                   <= 1e-9 for x, _ in out):
            out.append((limit, q))
    return out


def design_of(sweep) -> DesignSweep:
    """The sweep's one `DesignSweep` (made on first use), shared by its tables and summary."""
    design = sweep.__dict__.get("_design")
    if design is None:
        design = sweep.__dict__["_design"] = DesignSweep(sweep)
    return design
