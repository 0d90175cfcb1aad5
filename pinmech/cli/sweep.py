"""`pinmech sweep SCENE`: every pose of a driver's cycle, streamed as CSV, JSON lines and figures."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from pinmech.cli.arguments import (
    add_certify_argument,
    add_force_arguments,
    add_limits_argument,
    add_output_arguments,
    add_path_arguments,
    add_scene_arguments,
)
from pinmech.cli.files import check_outputs
from pinmech.cli.path import follow_task
from pinmech.cli.progress import LimitWatch, progress
from pinmech.cli.scene_args import option_or_scene, scene_from_args
from pinmech.counts import checked_count
from pinmech.exceptions import PinmechError
from pinmech.solve.certify import dial_note

if TYPE_CHECKING:
    from pinmech.outputs import Outputs


def add_parser(sub) -> None:
    sweep = sub.add_parser("sweep", help="sweep a driver through a cycle (or follow an arm's task in time): "
                           "CSV, JSON lines and a figure")
    add_scene_arguments(sweep)
    add_certify_argument(sweep)
    sweep.add_argument("--driver", help="the driver to sweep (default: the scene's first)")
    sweep.add_argument("--from", dest="first", help="first value, e.g. '0 deg' (default: the scene's)")
    sweep.add_argument("--to", dest="last", help="last value, e.g. '360 deg' (default: one turn on)")
    sweep.add_argument("--steps", type=int, help="number of poses, both ends included (default 361)")
    add_output_arguments(sweep)
    sweep.add_argument("--links", nargs="*", help="links to plot (default: all moving but the driver's)")
    sweep.add_argument("--points", nargs="*", help="points to plot (default: all moving points)")
    sweep.add_argument("--paths", dest="paths_path",
                       help="also draw the points' paths, with the mechanism at the scene's pose, here (PNG, PDF, SVG)")
    sweep.add_argument("--timing-marks", dest="timing_marks", nargs="?", const="30 deg", metavar="STEP",
                       help="mark the paths every STEP of the driver (default 30 deg; a slide's driver: a "
                            "length, e.g. '10 mm'), each mark solved at that driver value")
    sweep.add_argument("--centrodes", metavar="LINK",
                       help="draw LINK's fixed centrode (its instant centre's path in the plane) and moving "
                            "centrode (seen from LINK, drawn on it at the scene's pose) on the paths")
    sweep.add_argument("--angles", choices=("continuous", "wrapped"), default="continuous",
                       help="link angles in the figure: continuous (default, no jump at 180 deg) or wrapped "
                       "to (-180, 180] deg")
    sweep.add_argument("--path-plane", choices=("xy", "yz", "zx", "3d"),
                       help="a spatial mechanism's paths projected on this world plane (default xy), or 3d")
    add_limits_argument(sweep)
    sweep.add_argument("--summary-json", dest="summary_json", metavar="FILE",
                       help="also write the design summary (Grashof and Barker class, transmission and pressure "
                       "angle extremes, folds, limit positions, swing or stroke, Q) here as JSON, SI, full precision")
    sweep.add_argument("--skip-failures", action="store_true",
                       help="report a pose that cannot close as a row with its error instead of stopping")
    sweep.add_argument("--start", dest="start_mode", choices=("predictor", "warm", "cold"),
                       help="where each pose's Newton iterations start: the previous pose moved along its "
                       "path (predictor, default), the previous pose (warm), the scene's guess (cold)")
    sweep.add_argument("--no-predictor", action="store_true", help="same as --start warm")
    sweep.add_argument("--cold-start", action="store_true", help="same as --start cold")
    sweep.add_argument("--no-batch", action="store_true",
                       help="accepted for old scripts; no effect (the compiled core follows every pose)")
    sweep.add_argument("--interpolate", type=int, metavar="N",
                       help="solve every N-th pose and interpolate the others (quintic Hermite): less "
                       "accurate, accuracy measured; no faster than the default (the compiled core follows "
                       "every pose) "
                       "(docs/explanation/speed.md)")
    sweep.add_argument("--tol", type=float, help="closure tolerance, relative to each loop's size "
                       "(default 1e-13; 1e-6 gives about 1e-6 and saves little)")
    sweep.add_argument("--max-iterations", type=int, help="Newton iteration cap per pose (default 50)")
    sweep.add_argument("--through-folds", action="store_true",
                       help="at a fold of the driver (a limit angle), go on onto the other branch with the "
                       "driver turning back (a whole coupler curve); default: stop there, naming the limit")
    add_path_arguments(sweep, required=False)
    sweep.add_argument("--forces", action="store_true",
                       help="add driver torque and joint reaction columns (on by default when the scene has "
                       "[forces], [gravity] or [[load]])")
    add_force_arguments(sweep)
    sweep.add_argument("--flywheel", help="flywheel inertia for the coefficient of speed fluctuation, e.g. "
                       "'0.01 kg*m^2' ([forces] flywheel)")
    sweep.add_argument("--torque-plot", dest="torque_plot", help="draw the driver's torque curve here (pinmech[plot])")
    sweep.set_defaults(func=cmd_sweep)


def _sweep_forces(args: argparse.Namespace, scene, sweep):
    """The forces of a sweep when asked (flags or the scene's force tables), else None."""
    from pinmech.io.scene import wants_forces

    asked = args.forces or args.static or args.minimum_norm or args.flywheel or args.torque_plot
    if not (asked or wants_forces(scene)):
        return None
    from pinmech.draw.forces_sweep import SweepForces

    flywheel = option_or_scene(args.flywheel, "--flywheel", scene, {}, "").quantity("moment_of_inertia") if args.flywheel else None
    if flywheel is not None and not flywheel > 0:
        raise PinmechError(f"--flywheel must be positive, got {args.flywheel}")
    forces = SweepForces(sweep, static=args.static, minimum_norm=args.minimum_norm, flywheel=flywheel)
    if forces.static and flywheel is not None:  # the scene's [forces] static = true
        from pinmech.exceptions import OptionRefused

        raise OptionRefused("--flywheel: a flywheel is sized from the energy a moving cycle stores, and the "
                            "scene's [forces] static = true has no motion", options=["--flywheel"],
                            scene=str(scene.path))
    return forces


def cmd_sweep(args: argparse.Namespace) -> int:
    """`pinmech sweep SCENE`: every pose of a cycle, streamed as CSV (and JSON lines, a plot);
    a task scene is followed in time instead (as `pinmech path`)."""
    from pinmech.solve.limits import limit_violations
    from pinmech.io.scene_model import limit_mode
    from pinmech.io.sweep import DriverValues, Sweep, sweep_options
    from pinmech.solve.diagnostics_sweep import design_of

    from pinmech.io.unused_options import refuse_sweep_options

    scene = scene_from_args(args)
    refuse_sweep_options(args, str(scene.path), task=scene.is_task)
    if scene.is_task:
        return follow_task(args, scene)
    figure = check_outputs(args, scene)
    options = sweep_options(scene)  # the scene's values checked there, naming the file and key
    given_steps = option_or_scene(args.steps, "--steps", scene, options, "steps", 361)
    steps = given_steps.value
    if steps < 2:
        raise given_steps.error(f"must be at least 2, got {steps}")
    checked_count(steps, given_steps.where, f"steps = {steps}")
    sweep = Sweep.from_scene(scene, args.driver)
    kind = "angle" if sweep.is_angular else "length"
    first = option_or_scene(args.first, "--from", scene, options, "from")
    last = option_or_scene(args.last, "--to", scene, options, "to")
    start = first.quantity(kind) if first.value else sweep.start
    stop = last.quantity(kind) if last.value else start + (sweep.default_values(2)[1] - sweep.start)
    if args.tol is not None:
        from pinmech.io.scene import SOLVER_RANGES

        low, high = SOLVER_RANGES["tol"]
        if not low <= args.tol <= high:
            raise PinmechError(f"--tol must be between {low:g} and {high:g} (relative to each loop's size), "
                               f"got {args.tol}")
        sweep.solver.tol = args.tol
    if args.max_iterations is not None:
        if args.max_iterations < 1:
            raise PinmechError(f"--max-iterations must be at least 1, got {args.max_iterations}")
        sweep.solver.max_iterations = args.max_iterations
    mode = "cold" if args.cold_start else "warm" if args.no_predictor else args.start_mode or options.get("start")
    interpolating = option_or_scene(args.interpolate, "--interpolate", scene, options, "interpolate", 1)
    if interpolating.value < 1:
        raise interpolating.error(f"must be at least 1 (1: every pose solved), got {interpolating.value}")
    interpolate = interpolating.value
    poses = sweep.poses(DriverValues(start, stop, steps), skip_failures=args.skip_failures,
                        start=mode or "predictor", batch=not args.no_batch and options.get("batch", True),
                        interpolate=interpolate, through_folds=args.through_folds, to_fold=not args.through_folds,
                        past_change_points=True)
    forces = _sweep_forces(args, scene, sweep)
    if forces is not None and interpolate and interpolate > 1:  # before any pose is computed
        raise interpolating.error(f"{interpolate}: forces need solved poses, and interpolated ones' rates miss the "
                                  "loops' equations by the interpolation error (the power balance fails); sweep "
                                  f"without {interpolating.name} for forces")
    limits = LimitWatch(limit_mode(scene, args.limits), "poses")
    args.timing_step = _timing_step(args, scene, kind)
    sinks = _sweep_sinks(args, sweep, steps, figure, forces)
    with sinks:
        for pose in progress(poses, steps):
            if pose.note:
                print(f"pinmech: at pose {pose.index}: {pose.note}", file=sys.stderr)
            if pose.motion is not None:
                limits.check(limit_violations(sweep.mechanism, pose.motion),
                             f"at {sweep.driver} = {sweep._format(pose.value)}")
            sinks.add(pose)
            for note in design_of(sweep).notes(pose) if design_of(sweep).applicable else []:
                print(f"pinmech: at pose {pose.index}: {note}", file=sys.stderr)
    dial = dial_note(sweep.solver.certify)
    if dial:
        print(f"pinmech: {dial}", file=sys.stderr)
    if sweep.fold_end is not None:
        print(f"pinmech: {sweep.driver} cannot go past {sweep._format(sweep.fold_end)} (a fold: a toggle, the end of "
              "its range of motion on this assembly): the sweep ends at the pose before it (--through-folds goes on "
              "onto the other branch, the driver turning back)", file=sys.stderr)
    for line in forces.summary() if forces else []:
        print(line, file=sys.stderr)
    for line in _design_summary(sweep, stop - start, args.through_folds):
        print(line, file=sys.stderr)
    if args.summary_json:
        _write_summary(args.summary_json, sweep, stop - start, args.through_folds)
    limits.summary(steps)
    if not args.through_folds and sweep.fold_end is None:  # past a fold the driver turns back: no whole turns
        _say_return(sweep, stop - start)
    return 0


def _timing_step(args: argparse.Namespace, scene, kind: str) -> float | None:
    """--timing-marks' spacing [rad or m], checked before the sweep runs."""
    if args.timing_marks is None:
        return None
    step = scene.quantity(args.timing_marks, kind, "--timing-marks")
    if not step > 0:
        raise PinmechError(f"--timing-marks must be a positive {kind}, got {args.timing_marks!r}")
    return step


def _design_summary(sweep, span: float, through_folds: bool) -> list[str]:
    """The sweep's design diagnostics (docs/howto/diagnostics.md); the time ratio when the
    driver made exactly one turn."""
    from pinmech.solve.diagnostics_sweep import design_of

    return design_of(sweep).summary(_one_turn(sweep, span, through_folds))


def _one_turn(sweep, span: float, through_folds: bool) -> float | None:
    """2 pi when the sweep was one whole turn of an angular driver (then Q), else None."""
    import math

    turn = sweep.is_angular and not through_folds and sweep.fold_end is None and abs(abs(span) - 2 * math.pi) <= 1e-9
    return 2 * math.pi if turn else None


def _write_summary(path: str, sweep, span: float, through_folds: bool) -> None:
    """--summary-json: the design summary, whole (design_summary.py)."""
    import json

    from pinmech.cli.files import write_text
    from pinmech.solve.design_summary import design_summary

    text = json.dumps(design_summary(sweep, _one_turn(sweep, span, through_folds)), indent=1, allow_nan=False)
    write_text(path, text + "\n", "design summary")


def _say_return(sweep, span: float) -> None:
    """After whole turns of an angular driver, say whether the mechanism came back."""
    import math

    turns = span / (2 * math.pi)
    if not sweep.is_angular or abs(turns) < 0.5 or abs(turns - round(turns)) > 1e-12:
        return
    gap = sweep.return_gap()
    if math.isnan(gap):  # the first or the last pose failed
        return
    if gap <= max(1e-9, 10 * sweep.solver.tol):  # each end closed to tol
        print(f"pinmech: after {round(abs(turns))} turn(s) the mechanism is back where it began "
              f"(largest joint gap {gap:.1e})", file=sys.stderr)
    else:
        print(f"pinmech: after {round(abs(turns))} turn(s) the mechanism is NOT back where it began "
              f"(largest joint gap {gap:.3g} rad or sizes): it returns after more turns", file=sys.stderr)


def _sweep_sinks(args: argparse.Namespace, sweep, steps: int, figure: Path | None, forces=None) -> Outputs:
    from pinmech.outputs import Outputs, plot_path
    from pinmech.io.tables import SweepCsv, SweepJsonLines

    csv_kind, json_kind, source = SweepCsv, SweepJsonLines, sweep
    sinks = Outputs()
    from pinmech.solve.diagnostics_sweep import design_of

    sinks.plot(design_of(sweep), None)  # every pose, for the design summary, whatever is written
    if forces is not None:
        from pinmech.draw.forces_sweep import ForceCsv, ForceJsonLines, TorquePlot

        csv_kind, json_kind, source = ForceCsv, ForceJsonLines, forces
        torque = plot_path(args.torque_plot, "--torque-plot") if args.torque_plot else None
        sinks.plot(TorquePlot(forces), torque)  # collects every pose's forces; drawn if a path is given
    if figure is not None or args.paths_path:
        from pinmech.draw.plot import SweepPlot

        recorder = SweepPlot(sweep, links=args.links, points=args.points, total=steps, angles=args.angles,
                             plane=args.path_plane, timing=args.timing_step, centrodes=args.centrodes)
        if figure is not None:
            sinks.plot(recorder, figure)
        if args.paths_path:
            sinks.plot(_PathsFigure(recorder, feed=figure is None), args.paths_path)
    only_figures = args.plot_path or args.json_path or args.paths_path or (forces is not None and args.torque_plot)
    if args.csv_path or not only_figures:
        sinks.table(csv_kind, source, args.csv_path, "poses")
    if args.json_path:
        sinks.table(json_kind, source, args.json_path, None)
    return sinks


class _PathsFigure:
    """The paths figure of a sweep's recorder (fed once, whoever feeds it)."""

    def __init__(self, recorder, *, feed: bool) -> None:
        self.recorder, self.feed = recorder, feed

    def add(self, pose) -> None:
        if self.feed:
            self.recorder.add(pose)

    def save(self, path: str):
        return self.recorder.save_paths(path)
