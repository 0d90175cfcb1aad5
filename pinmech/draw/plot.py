"""Figures of sweeps and arm paths (matplotlib, extra `plot`): what a report shows.

A sweep's figure: link angles, angular velocities and accelerations, the sliders'
position, velocity and acceleration along their guide, and the speed and acceleration
magnitudes of chosen points, against the driver (0 to 360 deg for a whole turn, whatever
angle it starts at), with the scene's own pose marked (dashed line, dots, and its values in
a panel), the driver's rates in the title, constant quantities named instead of drawn, and
a last panel with the points' paths (`pinmech.draw.plot_paths`). A task's figure against time
is `pinmech.draw.plot_task`.

The recorders (`SweepPlot`, `PathPlot`) take poses one at a time while a sweep streams
and keep at most `max_points` of them (every n-th), so memory stays bounded.
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pinmech.exceptions import FrameNotFound, PinmechError
from pinmech.model.display import colour_of, display_names, hex_colour
from pinmech.draw.plot_centrodes import CentrodeTrace
from pinmech.draw.plot_curves import driver_axis as _driver_axis
from pinmech.draw.plot_curves import draw_markers, legend_beside, length_unit
from pinmech.draw.label_place import settle
from pinmech.draw.plot_design import DesignTrace, mark_least, transmission_band
from pinmech.draw.plot_paths import PathRecorder
from pinmech.draw.sweep_panels import SweepPanels

if TYPE_CHECKING:
    from pinmech.io.sweep import Sweep, SweepPose

MAX_POINTS = 20_000
#: The panel of the transmission angles (0..180 deg, 90 best) of a planar linkage's dyads.
TRANSMISSION = "transmission angle, μ [deg]"


def _mu(name: str) -> str:
    """The transmission panel's key of a dyad (its joint may also be a slider drawn elsewhere)."""
    return f"μ {name}"
ANGLE_STYLES = ("continuous", "wrapped")


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise ImportError('plots need matplotlib: pip install "pinmech[plot]"') from exc
    return plt


def _check_names(sweep: Sweep, what: str, names: list[str] | None, known, where: str) -> None:
    """Before the sweep runs: every name asked for the figure is a link (point) of the model."""
    for name in names or ():
        if name not in known:
            raise FrameNotFound(f"{what} (in {where})", name, list(known), path=str(sweep.scene.path))


class SweepPlot(SweepPanels):
    """Records a sweep's plotted quantities pose by pose, then draws them (`save`).

    Args:
        links, points: what to draw (default: the scene's `[sweep] links/points`, else
            every moving link but the driver's, and every moving point).
        total: the number of poses to come, to keep every n-th when there are more
            than `max_points`.
        angles: "continuous" (no jump where a link passes 180 deg) or "wrapped" to
            (-180, 180] deg, with a gap where an angle wraps.
        plane: the world plane ("xy", "yz", "zx") a spatial mechanism's paths are
            projected on (None: the mechanism's own plane, or xy), or "3d": a 3-D view.
        timing: marks on the paths every `timing` of the driver [rad or m] (None: none).
        centrodes: a link whose fixed and moving centrodes the paths panel draws (None: none).

    Lengths are drawn in one unit a figure, mm or m from the mechanism's size
    (`plot_curves.length_unit`); a planar linkage's figure has a panel of transmission
    angles (least marked) and its limit positions as vertical lines (`plot_design`).
    """

    def __init__(self, sweep: Sweep, *, links: list[str] | None = None, points: list[str] | None = None,
                 total: int | None = None, max_points: int = MAX_POINTS, angles: str = "continuous",
                 plane: str | None = None, timing: float | None = None, centrodes: str | None = None) -> None:
        _pyplot()  # fail early, before the sweep runs, when matplotlib is missing
        if angles not in ANGLE_STYLES:
            raise PinmechError(f"angles must be one of {', '.join(ANGLE_STYLES)}, got {angles!r}")
        chosen = sweep.scene.file.sweep
        self.sweep, self.angles = sweep, angles
        self.length = length_unit(sweep.mechanism.length_scale)  # (scale from m, unit): one a figure
        self.paths = PathRecorder(sweep.mechanism, plane, length=self.length)
        self.design, self.timing_step, self.timing = DesignTrace(sweep), timing, None
        self.centrodes = None if centrodes is None else CentrodeTrace(self.design.design, centrodes)
        self._mus: list[float] = []
        self.mark_q = None  # configuration of the pose nearest the scene's (drawn under the paths)
        self.links, self.points = links or chosen.links, points or chosen.points
        _check_names(sweep, "link", self.links, sweep.mechanism.links, "--links" if links else "[sweep] links")
        named = [n for n in self.points or () if sweep.mechanism.model.existFrame(n)]  # a drawn linkage's pins
        _check_names(sweep, "point", self.points, [*sweep.mechanism.points, *named],
                     "--points" if points else "[sweep] points")
        sweep.need_points(n for n in named if n not in sweep.mechanism.points)  # evaluated at every pose
        self.every = max(1, math.ceil(total / max_points)) if total else 1
        self.last = total - 1 if total else None  # drawn whatever every is: a turn ends where it ends
        self.normal = sweep.mechanism.plane_normal
        self.x = array("d")
        self.branch = array("i")  # the branch of the assembly each kept pose is on (a fold starts one)
        self._branch, self._folded = 0, False
        #: (driver value as drawn, label): vertical lines in every panel (folds; limit positions)
        self.markers: list[tuple[float, str]] = []
        self.names = display_names(sweep.mechanism)
        self.series: dict[str, dict[str, array]] = {}
        self.failed: list[float] = []
        self.mark: tuple[float, dict[str, dict[str, float]]] | None = None  # nearest pose to the scene's

    def _x(self, value: float) -> float:
        return math.degrees(value) if self.sweep.is_angular else value * self.length[0]

    def add(self, pose: SweepPose) -> None:
        if "fold" in pose.note:  # the engine crossed a limit position: the driver turns back there,
            self._branch = 1 - self._branch  # and the assembly changes (two of them, in turn)
            self._folded = True
            self.markers.append((self._x(pose.value), f"fold ({self.sweep.driver} limit)"))
        q = None if pose.motion is None or self.sweep.last_q is None else self.sweep.last_q
        self._mus = self.design.add(pose, q)  # every pose: the least angle is looked for among them all
        if self.timing is not None:
            self.timing.add(pose.value, q)
        if self.centrodes is not None:
            self.centrodes.add(q)
        if pose.motion is None:
            self.failed.append(self._x(pose.value))
            if self.series:
                self.x.append(self._x(pose.value))  # a gap in every curve
                self.branch.append(self._branch)
                self.paths.add({p: np.full(3, math.nan) for p in self.points})
                for panel in self.series.values():
                    for values in panel.values():
                        values.append(math.nan)
            return
        if not self.series:
            self._choose(pose)
        nearer = self.mark is None or abs(pose.value - self.sweep.start) < abs(self.mark[0] - self.sweep.start)
        kept = pose.index % self.every == 0 or pose.index == self.last
        if not (nearer or kept):
            return
        values = self._values(pose, q)
        if nearer:
            self.mark = (pose.value, values)
            self.mark_q = None if self.sweep.last_q is None else self.sweep.last_q.copy()
        if not kept:
            return
        self.paths.add({p: pose.motion.points[p].position for p in self.points})
        self.x.append(self._x(pose.value))
        self.branch.append(self._branch)
        for title, panel in values.items():
            for name, value in panel.items():
                self.series[title][name].append(value)

    def _choose(self, pose: SweepPose) -> None:
        mech, motion = self.sweep.mechanism, pose.motion
        model = mech.model
        driver_link = mech.joint(self.sweep.driver).child_link
        if not self.links:
            self.links = [n for n in motion.links if n != driver_link]
        if not self.points:
            self.points = [n for n, p in motion.points.items()
                           if p.link in mech.links and model.frames[mech.links[p.link]].parentJoint != 0]
        self.sliders = list(motion.sliders)
        from pinmech.draw.figure_style import point_styles

        self.colours = {n: hex_colour(colour_of(mech, n)) for n in self.links}
        styles = point_styles(self.points)  # each point its own colour and marker (figure_style.py)
        self.colours.update({n: colour for n, (colour, _) in styles.items()})
        self.point_markers = {n: marker for n, (_, marker) in styles.items()}
        # a slider in the colour of its moving side (a tree joint's child, a loop cut's child link)
        self.colours.update({n: hex_colour(colour_of(mech, s.child)) for n, s in motion.sliders.items()})
        for dyad, name in zip(self.design.dyads, self.design.names):  # a dyad in its output's colour
            coupler, output = (self.design.design.linkage.names[k] for k in (dyad.coupler, dyad.output))
            self.colours[_mu(name)] = hex_colour(colour_of(mech, output)) if output in mech.links else "#111111"
            self.names[_mu(name)] = f"{self.names.get(name, name)} ({coupler}-{output})"
        if self.timing_step is not None and self.points:
            from pinmech.draw.plot_timing import TimingMarks

            self.timing = TimingMarks(self.sweep, self.points, self.timing_step)
            self.timing.add(pose.value, self.sweep.last_q)
        # raw doubles, not lists of floats: the kept values would pin memory pools freed by the rest
        self.series = {title: {name: array("d") for name in names} for title, names in self._panels().items()}

    def _panels(self) -> dict[str, list[str]]:
        """Panel title ("quantity, symbol [unit]") -> the names drawn in it."""
        planar = self.normal is not None
        panels = {}
        if planar:
            panels["angle, φ [deg]"] = self.links
        panels["angular velocity, ω [rad/s]" if planar else "angular speed, |ω| [rad/s]"] = self.links
        panels["angular acceleration, α [rad/s²]" if planar else "angular acceleration, |α| [rad/s²]"] = self.links
        if self.design.dyads:
            panels[TRANSMISSION] = [_mu(n) for n in self.design.names]
        if self.sliders:
            panels["position along its guide, s [m]"] = self.sliders
            panels["velocity along its guide, v_rel [m/s]"] = self.sliders
            panels["acceleration along its guide, a_rel [m/s²]"] = self.sliders
        if self.points:
            panels["speed, |v| [m/s]"] = self.points
            panels["acceleration, |a| [m/s²]"] = self.points
        return panels

    def _values(self, pose: SweepPose, q: np.ndarray) -> dict[str, dict[str, float]]:
        m, n = pose.motion, self.normal
        links = [m.links[name] for name in self.links]
        if n is not None:
            w = [float(n @ link.angular_velocity) for link in links]
            alpha = [float(n @ link.angular_acceleration) for link in links]
        else:
            w = [float(np.linalg.norm(link.angular_velocity)) for link in links]
            alpha = [float(np.linalg.norm(link.angular_acceleration)) for link in links]
        out, titles = {}, list(self.series)
        columns = []
        if n is not None:
            columns.append([math.degrees(link.angle) for link in links])
        columns += [w, alpha]
        if self.design.dyads:
            columns.append(self._mus)
        if self.sliders:
            sliders = [m.sliders[name] for name in self.sliders]  # tree joints and cuts alike
            columns += [[s.s for s in sliders], [s.s_dot for s in sliders], [s.s_ddot for s in sliders]]
        if self.points:
            columns += [[float(np.linalg.norm(m.points[p].velocity)) for p in self.points],
                        [float(np.linalg.norm(m.points[p].acceleration)) for p in self.points]]
        for title, column in zip(titles, columns):
            out[title] = dict(zip(self.series[title], column))
        return out

    def save(self, path: str | Path) -> Path:
        """Draw and save the figure (PNG, PDF or SVG, from the suffix): one panel per
        quantity against the driver, and the paths of the points with the mechanism."""
        if not self.series:
            raise PinmechError(f"no pose of the sweep could be solved: nothing to plot in {path}")
        plt = _pyplot()
        unit = "deg" if self.sweep.is_angular else self.length[1]
        x, order, turn = _driver_axis(np.array(self.x), self.sweep.is_angular and self._comes_back())
        mark_x = self._x(self.mark[0]) % 360.0 if turn else self._x(self.mark[0])
        lo, hi = np.nanmin(x), np.nanmax(x)
        marked = lo - 1e-9 * abs(lo) <= mark_x <= hi + 1e-9 * abs(hi)  # the scene's pose is swept
        panels = list(self.series.items())
        drawn_paths = bool(self.points) and self.paths.count > 0
        cols = 2
        rows = math.ceil((len(panels) + drawn_paths) / cols)
        fig, axes = plt.subplots(rows, cols, figsize=(13, 3.2 * rows), squeeze=False)
        for ax, (title, series) in zip(axes.flat, panels):
            self._panel(ax, title, series, x, order, mark_x if marked else None)
            if title == TRANSMISSION:
                transmission_band(ax)
                self._mark_least(ax, turn)  # its legend names the band and the least angle
            ax.set_xlim(lo, hi)
            if turn:
                ax.set_xticks(np.arange(0, 361, 60))
            ax.set_xlabel(self._driver_label(), fontsize=9)
            if self.failed:
                failed = np.mod(self.failed, 360.0) if turn else self.failed
                ax.plot(failed, np.zeros(len(failed)), "x", color="red", markersize=6,
                        transform=ax.get_xaxis_transform(), clip_on=False)
        limits = [(self._x(at), label) for label, at, _ in self.design.limits()]
        markers = [(m % 360.0 if turn else m, label) for m, label in self.markers + limits]
        draw_markers(list(axes.flat[:len(panels)]), markers)
        if drawn_paths:
            ax = axes.flat[len(panels)]
            if self.paths.is_3d:  # a 3-D panel in the same place
                ax.remove()
                ax = fig.add_subplot(rows, cols, len(panels) + 1, projection="3d")
            self._draw_paths(ax)
        spare = list(axes.flat[len(panels) + drawn_paths:])
        for ax in spare:
            ax.set_visible(False)
        if spare and marked:  # the scene's pose, as numbers, where a panel is missing
            spare[0].set_visible(True)
            spare[0].axis("off")
            spare[0].text(0.02, 0.95, self._summary(mark_x, unit), va="top", ha="left", family="monospace",
                          fontsize=8.5, transform=spare[0].transAxes)
        fig.suptitle(self._title(marked, mark_x, unit), fontsize=11)
        fig.tight_layout()
        settle(fig)  # labels placed apart once the layout is final
        return _save(plt, fig, path)

    def _driver_label(self) -> str:
        """The driver axis' label, with the sense its angle is counted in (planar mechanisms)."""
        sweep, mech = self.sweep, self.sweep.mechanism
        if not sweep.is_angular:
            return f"driver {sweep.driver}: s [{self.length[1]}] along its guide"
        if self.normal is None:
            return f"driver {sweep.driver}: θ [deg]"
        import pinocchio as pin

        joint = mech.joint(sweep.driver)
        data = mech.model.createData()
        pin.forwardKinematics(mech.model, data, mech.neutral())
        axis = data.oMi[joint.id].rotation @ np.asarray(joint.axis, float)
        sense = "counter-clockwise" if float(axis @ self.normal) > 0 else "clockwise"
        return f"driver {sweep.driver}: θ [deg], {sense} (joint coordinate)"

    def _comes_back(self) -> bool:
        """Whether every drawn quantity ends where it began (angles modulo 360 deg): only
        then is a whole turn drawn from 0 to 360 deg without a jump where it began."""
        for title, panel in self.series.items():
            for values in panel.values():
                y = np.array(values)
                y = y[np.isfinite(y)]
                if y.size < 2:
                    continue
                gap = abs(y[-1] - y[0])
                if title.startswith("angle"):
                    gap = abs((gap + 180.0) % 360.0 - 180.0)
                if gap > 1e-6 * max(float(np.max(np.abs(y))), 1e-9):
                    return False
        return True

    def save_paths(self, path: str | Path) -> Path:
        """Only the paths of the points, with the mechanism at the scene's pose, in a figure."""
        if not self.points or self.paths.count == 0:
            raise PinmechError(f"no point to trace: nothing to draw in {path} (name points with --points)")
        plt = _pyplot()
        fig = plt.figure(figsize=(8, 6.5))
        ax = fig.add_subplot(projection="3d" if self.paths.is_3d else None)
        self._draw_paths(ax)
        if not self.paths.is_3d:  # the figure as tall as the drawing needs: no empty band above it
            aspect = np.diff(ax.get_ylim())[0] / np.diff(ax.get_xlim())[0]
            fig.set_figheight(min(6.5, max(3.6, 5.6 * aspect + 1.4)))
        fig.suptitle(f"{self.sweep.scene.title}: paths over the sweep", fontsize=11)
        fig.tight_layout()
        settle(fig)  # labels placed apart once the layout is final
        return _save(plt, fig, path)

    def _draw_paths(self, ax) -> None:
        """The paths, the mechanism at the scene's pose, ghost outlines at the limit
        positions and folds, and the timing marks asked for."""
        ghosts = [(q, label) for label, _, q in self.design.limits()]
        folds = [q for _, q in self.design.design.fold_poses()] if self.design.design.applicable else []
        self.paths.draw(ax, self.mark_q, self._travel(), backwards=self._backwards(), ghosts=ghosts, folds=folds,
                        timing=self.timing, targets=self.sweep.scene.file.sweep.targets)
        if self.centrodes is not None and not self.paths.is_3d:
            self.centrodes.draw(ax, self.paths.axes, self.paths._unit()[0], self.mark_q)
            legend_beside(ax)

    def _mark_least(self, ax, turn: bool) -> None:
        """The least transmission angle of each dyad, refined between the poses, on its panel."""
        for least in self.design.least():
            x = self._x(least.at) % 360.0 if turn else self._x(least.at)
            mark_least(ax, least, x, self.colours.get(_mu(least.name), "k"), self.names.get(_mu(least.name), least.name),
                       "°" if self.sweep.is_angular else f" {self.length[1]}")
        legend_beside(ax)

    def _speed(self) -> float:
        """The swept driver's speed in the scene [rad/s or m/s]."""
        drivers = self.sweep.drivers
        return float(drivers.v[drivers.names.index(self.sweep.driver)])

    def _increasing(self) -> bool:
        x = np.array(self.x)
        return bool(np.nanmean(np.diff(x)) > 0) if len(x) > 1 else True

    def _backwards(self) -> bool:
        """The points move against the order of the poses: the driver's speed and the sweep's
        direction have opposite signs (a crank at -50 rpm swept from 30 to 390 deg)."""
        return self._speed() != 0 and (self._speed() > 0) != self._increasing()

    def _travel(self) -> str:
        unit = "deg" if self.sweep.is_angular else self.length[1]
        if self._speed() == 0:
            return f"arrows: travel as {self.sweep.driver} {'grows' if self._increasing() else 'falls'} [{unit}]"
        spec = self.sweep.scene.file.drivers.get(self.sweep.driver)
        speed = spec.rate if spec is not None and spec.rate is not None else f"{self._speed():.4g}"
        return f"arrows: the motion, {self.sweep.driver} at {speed}"


def plot_sweep(sweep: Sweep, poses: Iterable[SweepPose], path: str | Path, *,
               links: list[str] | None = None, points: list[str] | None = None) -> Path:
    """Draw a sweep's poses and save the figure (PNG, PDF, SVG)."""
    recorder = SweepPlot(sweep, links=links, points=points)
    for pose in poses:
        recorder.add(pose)
    return recorder.save(path)



def _save(plt, fig, path: str | Path) -> Path:
    """Every sweep figure's way to its file: whole, through outputs.write_with."""
    from pinmech.draw.figure_style import FIGURE_RC
    from pinmech.outputs import write_with

    try:
        with plt.rc_context(FIGURE_RC):
            settle(fig)  # labels placed apart once the layout is final
            return write_with(path, lambda temporary: fig.savefig(temporary, dpi=130, bbox_inches="tight",
                                                                  pad_inches=0.08))
    finally:
        plt.close(fig)
