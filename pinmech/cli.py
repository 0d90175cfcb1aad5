"""The `pinmech` command: one plain function per subcommand, `main(argv)` for tests.

Exit codes: 0 success; 1 hand values mismatch (`check`); 2 usage or other pinmech error;
3 bad URDF; 4 bad scene or hand file (unknown name, unit, key); 5 drivers do not match
the mobility; 6 a loop cannot close; 7 singular pose, or forces not determined; 8 inconsistent
task; 9 a drawing input out of range; 10 another assembly than the scene's (or none reachable
on it); 11 the drivers cannot go further (a fold: limit angle, extreme, stroke); 12 a joint
beyond its limits (URDF <limit>, MJCF range; with --limits error); 13 forces that fail their own power balance; 14 a planar design diagnostic asked of a spatial mechanism.
An output file that cannot be written is 2.
Stopped by a signal: 128 + its number (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP), outputs kept
as NAME.partial.
"""

from __future__ import annotations

import argparse
import signal
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

from pinmech import __version__
from pinmech.counts import checked_count
from pinmech.exceptions import PinmechError, SceneError
from pinmech.interrupts import SIGNALS
from pinmech.design.study_cli import add_parser as add_study_parser
from pinmech.design.synthesis_cli import add_parser as add_synth_parser

if TYPE_CHECKING:
    from pinmech.outputs import Outputs


def _add_scene_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene file (TOML), e.g. models/scenes/r_rtr.toml")
    parser.add_argument(
        "--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
        help="override a scene value, e.g. --set 'drivers.A.angle=\"45 deg\"' (repeatable)",
    )
    parser.add_argument("--angle", help="shortcut: the (single) driver's angle or position, e.g. '45 deg'")
    parser.add_argument("--speed", help="shortcut: the driver's speed, e.g. '-50 rpm' or '2 rad/s'")
    parser.add_argument("--acceleration", help="shortcut: the driver's acceleration, e.g. '1 rad/s^2'")


def _add_output_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--csv", dest="csv_path", help="write the CSV here (default: standard output)")
    parser.add_argument("--json", dest="json_path", help="also write the rows as JSON lines here")
    parser.add_argument("--plot", dest="plot_path", help="also draw a figure here (PNG, PDF, SVG; pinmech[plot])")


def _add_path_arguments(parser: argparse.ArgumentParser, *, required: bool) -> None:
    parser.add_argument("--duration", required=required,
                        help="task scenes: how long to follow the task, e.g. '0.08 s' ([sweep] duration)")
    parser.add_argument("--step", help="task scenes: integration time step (default '1 ms')")
    parser.add_argument("--scheme", choices=("euler", "taylor", "rk4"),
                        help="task scenes: integration scheme (default taylor, second order)")
    parser.add_argument("--gain", type=float, help="task scenes: feedback on the drift [1/s] (default 0: open loop)")


def _add_force_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--static", action="store_true",
                        help="statics: forces with zero speeds and accelerations ([forces] static = true)")
    parser.add_argument("--minimum-norm", dest="minimum_norm", action="store_true",
                        help="forces not determined: the minimum-norm reactions instead of an error "
                             "(a scene's redundant loops are refused before; see README, Forces)")


def _add_limits_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--limits", choices=("warn", "error"),
                        help="a joint beyond its limits (URDF <limit>, MJCF range): a warning (default) or an error (exit 12)")


def build_parser(command: str | None = None, *, parser_class: type[argparse.ArgumentParser] = argparse.ArgumentParser
                 ) -> argparse.ArgumentParser:
    """The argument parser, with one sub-parser per subcommand (only `command`'s when given:
    `main` parses a subcommand's arguments with its parser alone, see `parse_args`)."""
    parser = parser_class(
        prog="pinmech",
        description="Kinematics of mechanisms and robot arms from URDF, on Pinocchio.",
        epilog="Exit codes: 0 ok, 1 check mismatch, 2 error, 3 URDF, 4 scene, 5 mobility, "
        "6 loop cannot close, 7 singular pose (or undetermined forces), 8 task, 9 drawing, 10 assembly, "
        "11 driver limit, 12 joint limit (--limits error), 13 forces off their balance, 14 design diagnostic (spatial), "
        "130 Ctrl-C (128 + signal).",
    )
    parser.add_argument("--version", action="version", version=f"pinmech {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, add in _SUBCOMMANDS.items():
        if command is None or name == command:
            add(sub)
    return parser


def _solve_parser(sub) -> None:
    solve = sub.add_parser("solve", help="solve a scene and print the report (or JSON)")
    _add_scene_arguments(solve)
    solve.add_argument("--json", action="store_true", help="print one JSON object (SI units) instead of text")
    _add_limits_argument(solve)
    solve.set_defaults(func=cmd_solve)


def _forces_parser(sub) -> None:
    forces = sub.add_parser("forces", help="driver torques and joint reactions at the scene's pose (inverse dynamics)")
    _add_scene_arguments(forces)
    _add_force_arguments(forces)
    forces.add_argument("--json", action="store_true", help="print one JSON object (SI units) instead of text")
    forces.set_defaults(func=cmd_forces)


def _sweep_parser(sub) -> None:
    sweep = sub.add_parser("sweep", help="sweep a driver through a cycle (or follow an arm's task in time): "
                           "CSV, JSON lines and a figure")
    _add_scene_arguments(sweep)
    sweep.add_argument("--driver", help="the driver to sweep (default: the scene's first)")
    sweep.add_argument("--from", dest="first", help="first value, e.g. '0 deg' (default: the scene's)")
    sweep.add_argument("--to", dest="last", help="last value, e.g. '360 deg' (default: one turn on)")
    sweep.add_argument("--steps", type=int, help="number of poses, both ends included (default 361)")
    _add_output_arguments(sweep)
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
    _add_limits_argument(sweep)
    sweep.add_argument("--skip-failures", action="store_true",
                       help="report a pose that cannot close as a row with its error instead of stopping")
    sweep.add_argument("--start", dest="start_mode", choices=("predictor", "warm", "cold"),
                       help="where each pose's Newton iterations start: the previous pose moved along its "
                       "path (predictor, default), the previous pose (warm), the scene's guess (cold)")
    sweep.add_argument("--no-predictor", action="store_true", help="same as --start warm")
    sweep.add_argument("--cold-start", action="store_true", help="same as --start cold")
    sweep.add_argument("--no-batch", action="store_true",
                       help="with the compiled core ruled out (PINMECH_CORE=0), solve every pose on its own "
                       "(default there: dense sweeps solve the poses between exactly solved ones together); "
                       "no effect with the core")
    sweep.add_argument("--interpolate", type=int, metavar="N",
                       help="solve every N-th pose and interpolate the others (quintic Hermite): less "
                       "accurate, accuracy measured; with the compiled core no faster than the default "
                       "(README: Speed and accuracy)")
    sweep.add_argument("--tol", type=float, help="closure tolerance, relative to each loop's size "
                       "(default 1e-13; 1e-6 gives about 1e-6 and, with the compiled core, saves little)")
    sweep.add_argument("--max-iterations", type=int, help="Newton iteration cap per pose (default 50)")
    sweep.add_argument("--through-folds", action="store_true",
                       help="at a fold of the driver (a limit angle), go on onto the other branch with the "
                       "driver turning back (a whole coupler curve); default: stop there, naming the limit")
    _add_path_arguments(sweep, required=False)
    sweep.add_argument("--forces", action="store_true",
                       help="add driver torque and joint reaction columns (on by default when the scene has "
                       "[forces], [gravity] or [[load]])")
    _add_force_arguments(sweep)
    sweep.add_argument("--flywheel", help="flywheel inertia for the coefficient of speed fluctuation, e.g. "
                       "'0.01 kg*m^2' ([forces] flywheel)")
    sweep.add_argument("--torque-plot", dest="torque_plot", help="draw the driver's torque curve here (pinmech[plot])")
    sweep.set_defaults(func=cmd_sweep)


def _path_parser(sub) -> None:
    path = sub.add_parser("path", help="integrate an arm's task over time: joint trajectory and drift")
    path.add_argument("scene", help="a task scene, e.g. models/scenes/planar_arm.toml")
    path.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                      help="override a scene value (repeatable)")
    _add_path_arguments(path, required=False)
    _add_limits_argument(path)
    _add_output_arguments(path)
    path.set_defaults(func=cmd_path)


def _snapshot_parser(sub) -> None:
    snap = sub.add_parser("snapshot", help="save the solved pose as an offline meshcat HTML page (pinmech[viz])")
    _add_scene_arguments(snap)
    snap.add_argument("-o", "--output", required=True, help="the HTML file to write")
    snap.add_argument("--arrows", nargs="*", default=[], metavar="POINT.QUANTITY",
                      help="vectors to draw, e.g. D.velocity D.acceleration (scaled to fit)")
    snap.add_argument("--no-grid", action="store_true", help="hide meshcat's grid and axes")
    snap.set_defaults(func=cmd_snapshot)


def _animate_parser(sub) -> None:
    anim = sub.add_parser("animate", help="save a driver cycle (or a task in time) as an offline meshcat "
                          "animation (pinmech[viz]), a GIF or an MP4")
    _add_scene_arguments(anim)
    anim.add_argument("-o", "--output", help="the HTML page to write (play/pause, a driver slider, traced paths)")
    anim.add_argument("--gif", help="also write a GIF for slides (Pillow: pinmech[plot])")
    anim.add_argument("--mp4", help="also write an MP4 for slides (needs ffmpeg installed)")
    anim.add_argument("--from", dest="start", help="first driver value (default: the scene's)")
    anim.add_argument("--to", dest="stop", help="last driver value (default: one turn on)")
    anim.add_argument("--duration", help="task scenes: how long to follow the task, e.g. '0.5 s' "
                      "(default: the scene's [sweep] duration)")
    anim.add_argument("--steps", type=int, default=91, help="frames (default 91)")
    anim.add_argument("--fps", type=int, default=30, help="frames per second (default 30)")
    anim.add_argument("--skip-failures", action="store_true", help="leave out poses that cannot close")
    anim.add_argument("--no-grid", action="store_true", help="hide meshcat's grid and axes")
    anim.set_defaults(func=cmd_animate)


def _polygon_parser(sub) -> None:
    poly = sub.add_parser("polygon", help="draw the velocity (or acceleration) polygon of a planar pose as SVG")
    poly.add_argument("scene", help="scene file (TOML), e.g. models/scenes/r_rtr.toml")
    poly.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                      help="override a scene value, e.g. --set 'drivers.A.acceleration=\"2 rad/s^2\"' (repeatable)")
    poly.add_argument("--angle", help="shortcut: the (single) driver's angle or position, e.g. '45 deg'")
    poly.add_argument("--speed", help="shortcut: the driver's speed, e.g. '-50 rpm'")
    poly.add_argument("-o", "--output", required=True, help="the SVG file to write")
    poly.add_argument("--acceleration", dest="acceleration_polygon", action="store_true",
                      help="the acceleration polygon (normal, tangential and Coriolis parts) instead; the "
                      "driver's acceleration comes from the scene or --set")
    poly.set_defaults(func=cmd_polygon)


def _report_parser(sub) -> None:
    page = sub.add_parser("report", help="write one offline HTML page: drawing, tables, polygons, sweep figures")
    _add_scene_arguments(page)
    page.add_argument("-o", "--output", required=True, help="the HTML file to write")
    page.add_argument("--hand", help="a hand-value file to check on the page (as pinmech check)")
    page.add_argument("--steps", type=int, default=121, help="poses of the sweep drawn (default 121; 0: none)")
    page.set_defaults(func=cmd_report)


def _view_parser(sub) -> None:
    live = sub.add_parser("view", help="show the solved pose in a live meshcat server (a browser tab)")
    _add_scene_arguments(live)
    live.set_defaults(func=cmd_view)


def _build_parser(sub) -> None:
    build = sub.add_parser("build", help="write the URDF (with <constraint> loop cuts) of a linkage drawn in TOML")
    build.add_argument("linkage", help="linkage file (TOML), e.g. models/linkages/jansen.toml")
    build.add_argument("-o", "--output", required=True, help="the URDF file to write")
    build.set_defaults(func=cmd_build)


def _check_parser(sub) -> None:
    check = sub.add_parser("check", help="compare hand-calculated values with pinmech")
    check.add_argument("hand_file", help="hand-value file (TOML), e.g. models/scenes/r_rtr.hand.toml")
    check.add_argument("--slack", type=float, default=None,
                       help="units of the last printed digit still called rounding (default 2)")
    check.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                       help="override a value of the hand file's scene")
    check.set_defaults(func=cmd_check)


#: Each subcommand's parser, in the order `pinmech --help` lists them.
_SUBCOMMANDS = {
    "solve": _solve_parser,
    "forces": _forces_parser,
    "sweep": _sweep_parser,
    "path": _path_parser,
    "snapshot": _snapshot_parser,
    "animate": _animate_parser,
    "polygon": _polygon_parser,
    "report": _report_parser,
    "view": _view_parser,
    "build": _build_parser,
    "check": _check_parser,
    "study": add_study_parser,
    "synth": add_synth_parser,
}


def _given(value: str | None, option: str) -> str | None:
    """An option's text, None where it was not given; an empty one (an unset shell
    variable) is an error, never the scene's own value in silence."""
    if value is not None and not value.strip():
        from pinmech.exceptions import UnitError

        raise UnitError(f"{option} is empty: give a quantity such as '30 deg' (or leave the option out)")
    return value


class _Option(NamedTuple):
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


def _option(given: Any, flag: str, scene, options: dict[str, Any], key: str, default: Any = None) -> _Option:
    """A flag's value if given, else the scene's `[sweep] key`, else `default`."""
    if given is not None:
        return _Option(given, flag, None, scene)
    if key in options:
        return _Option(options[key], flag, f"sweep.{key}", scene)
    return _Option(default, flag, None, scene)


def _scene(args: argparse.Namespace):
    from pinmech.io.scene import Scene

    overrides = list(args.overrides)
    shortcuts = {"angle": args.angle, "speed": args.speed, "acceleration": args.acceleration}
    for key, value in shortcuts.items():
        _given(value, f"--{key}")
    if any(shortcuts.values()):
        scene = Scene.load(args.scene)
        drivers = list(scene.section("drivers"))
        if len(drivers) != 1:
            raise PinmechError(f"--angle/--speed/--acceleration need a single driver; {args.scene} has "
                               f"{len(drivers)}: use --set drivers.NAME.angle=...")
        name = drivers[0]
        spec = scene.section("drivers")[name]
        keys = {"angle": "position" if "position" in spec else "angle",
                "speed": "velocity" if "velocity" in spec else "speed", "acceleration": "acceleration"}
        overrides += [f'drivers.{name}.{keys[k]}="{v}"' for k, v in shortcuts.items() if v]
    return Scene.load(args.scene, overrides)


def cmd_solve(args: argparse.Namespace) -> int:
    """`pinmech solve SCENE`: the textbook-ordered report, or `--json`."""
    from pinmech.io.analysis import analyse
    from pinmech.solve.limits import enforce, limit_violations
    from pinmech.io.report import to_json, to_text
    from pinmech.io.scene_model import limit_mode

    scene = _scene(args)
    mode = limit_mode(scene, args.limits)
    analysis = analyse(scene)
    violations = limit_violations(analysis.mechanism, analysis.motion)
    enforce(violations, mode, str(scene.path))
    print(to_json(analysis) if args.json else to_text(analysis), end="" if not args.json else "\n")
    for v in violations:
        print(f"pinmech: warning: {v.describe()}", file=sys.stderr)
    return 0


def cmd_forces(args: argparse.Namespace) -> int:
    """`pinmech forces SCENE`: the report with driver efforts and joint reactions (or `--json`)."""
    from pinmech.io.analysis import analyse
    from pinmech.io.report import to_json, to_text

    analysis = analyse(_scene(args), forces=True, static=args.static, minimum_norm=args.minimum_norm)
    print(to_json(analysis) if args.json else to_text(analysis), end="" if not args.json else "\n")
    return 0


def _sweep_forces(args: argparse.Namespace, scene, sweep):
    """The forces of a sweep when asked (flags or the scene's force tables), else None."""
    from pinmech.io.scene import wants_forces

    asked = args.forces or args.static or args.minimum_norm or args.flywheel or args.torque_plot
    if not (asked or wants_forces(scene)):
        return None
    from pinmech.draw.forces_sweep import SweepForces

    flywheel = _option(args.flywheel, "--flywheel", scene, {}, "").quantity("moment_of_inertia") if args.flywheel else None
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

    from pinmech.io.unused_options import refuse_sweep_options

    scene = _scene(args)
    refuse_sweep_options(args, str(scene.path), task="task" in scene.raw)
    if "task" in scene.raw:
        return _follow(args, scene)
    figure = _check_outputs(args, scene)
    options = sweep_options(scene)  # the scene's values checked there, naming the file and key
    given_steps = _option(args.steps, "--steps", scene, options, "steps", 361)
    steps = given_steps.value
    if steps < 2:
        raise given_steps.error(f"must be at least 2, got {steps}")
    checked_count(steps, given_steps.where, f"steps = {steps}")
    sweep = Sweep.from_scene(scene, args.driver)
    kind = "angle" if sweep.is_angular else "length"
    first = _option(_given(args.first, "--from"), "--from", scene, options, "from")
    last = _option(_given(args.last, "--to"), "--to", scene, options, "to")
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
    interpolating = _option(args.interpolate, "--interpolate", scene, options, "interpolate", 1)
    if interpolating.value < 1:
        raise interpolating.error(f"must be at least 1 (1: every pose solved), got {interpolating.value}")
    interpolate = interpolating.value
    poses = sweep.poses(DriverValues(start, stop, steps), skip_failures=args.skip_failures,
                        start=mode or "predictor", batch=not args.no_batch and options.get("batch", True),
                        interpolate=interpolate, through_folds=args.through_folds)
    forces = _sweep_forces(args, scene, sweep)
    if forces is not None and interpolate and interpolate > 1:  # before any pose is computed
        raise interpolating.error(f"{interpolate}: forces need solved poses, and interpolated ones' rates miss the "
                                  "loops' equations by the interpolation error (the power balance fails); sweep "
                                  f"without {interpolating.name} for forces")
    limits = _LimitWatch(limit_mode(scene, args.limits), "poses")
    args.timing_step = _timing_step(args, scene, kind)
    sinks = _sweep_sinks(args, sweep, steps, figure, forces)
    with sinks:
        for pose in _progress(poses, steps):
            if pose.note:
                print(f"pinmech: at pose {pose.index}: {pose.note}", file=sys.stderr)
            if pose.motion is not None:
                limits.check(limit_violations(sweep.mechanism, pose.motion),
                             f"at {sweep.driver} = {sweep._format(pose.value)}")
            sinks.add(pose)
    for line in forces.summary() if forces else []:
        print(line, file=sys.stderr)
    for line in _design_summary(sweep, stop - start, args.through_folds):
        print(line, file=sys.stderr)
    limits.summary(steps)
    if not args.through_folds:  # past a fold the driver turns back: no whole turns to speak of
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
    """The sweep's design diagnostics (README: Design diagnostics); the time ratio when the
    driver made exactly one turn."""
    import math

    from pinmech.solve.diagnostics_sweep import design_of

    turn = sweep.is_angular and not through_folds and abs(abs(span) - 2 * math.pi) <= 1e-9
    return design_of(sweep).summary(2 * math.pi if turn else None)


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


class _LimitWatch:
    """Poses (or path points) that put a joint beyond its limits: counted and summed
    up in a warning, or the run stopped at the first (LimitError) in mode "error"."""

    def __init__(self, mode: str, what: str, column: str = "; see the beyond_limits column") -> None:
        self.mode, self.what, self.column = mode, what, column
        self.count, self.first = 0, ""

    def check(self, violations: list, at: str) -> None:
        from pinmech.solve.limits import enforce

        if violations:
            enforce(violations, self.mode, f"stopped {at}")
            self.count += 1
            self.first = self.first or f"{at}: " + "; ".join(v.describe() for v in violations)

    def summary(self, total: int) -> None:
        if self.count:
            print(f"pinmech: warning: {self.count} of {total} {self.what} put joints beyond their limits "
                  f"(first {self.first}){self.column}", file=sys.stderr)


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


def _check_outputs(args: argparse.Namespace, scene) -> Path | None:
    """Before computing: the figure's format, one file per output, no output over an input.
    Returns the figure's path (".png" added to a name without suffix)."""
    from pinmech.outputs import check_distinct, plot_path

    figure = plot_path(args.plot_path) if args.plot_path else None
    if getattr(args, "paths_path", None):
        args.paths_path = plot_path(args.paths_path, "--paths")
    torque = getattr(args, "torque_plot", None)
    check_distinct({"--csv": args.csv_path, "--json": args.json_path, "--plot": figure,
                    "--paths": getattr(args, "paths_path", None),
                    "--torque-plot": plot_path(torque, "--torque-plot") if torque else None},
                   _inputs(scene))
    return figure


#: What each kind of model file is called in messages.
_MODEL_FILES = {"urdf": "the URDF", "robot": "the URDF", "linkage": "the linkage file", "mjcf": "the MJCF file"}


def _inputs(scene, hand: str | None = None) -> dict[str, Path]:
    """What a run reads, which no output may overwrite: the scene, its model file, a
    sidecar (robot.yaml) and a hand file."""
    out = {"the scene file": scene.path, _MODEL_FILES.get(getattr(scene, "model_kind", ""), "the model file"):
           _urdf_path(scene)}
    if "sidecar" in scene.raw:
        out["the sidecar (robot.yaml)"] = scene.model_file("sidecar")
    if hand:
        out["the hand file"] = Path(hand)
    return out


def _urdf_path(scene) -> Path:
    """The model file the scene names (a URDF, a drawn linkage, an MJCF file): an input
    that no output may overwrite."""
    try:
        kind = scene.model_kind
        return scene.urdf if kind in ("urdf", "robot") else scene.model_file(kind)
    except (PinmechError, StopIteration):
        return scene.path


def _progress(items, total: int):
    """A progress bar on a terminal (tqdm, if installed); nothing when piped."""
    if not sys.stderr.isatty():
        return items
    try:
        from tqdm import tqdm
    except ImportError:
        return items
    return tqdm(items, total=total, unit="pose", file=sys.stderr, mininterval=0.5)


def cmd_path(args: argparse.Namespace) -> int:
    """`pinmech path SCENE --duration T`: the task integrated in time, with its drift."""
    from pinmech.io.scene import Scene

    return _follow(args, Scene.load(args.scene, args.overrides))


def _follow(args: argparse.Namespace, scene) -> int:
    """A task scene followed in time: CSV (JSON lines, a figure) of the joint trajectory."""
    from pinmech.io.analysis_task import scene_pose, scene_tasks
    from pinmech.solve.limits import limits_at
    from pinmech.outputs import Outputs
    from pinmech.solve.path import follow_path, step_count
    from pinmech.io.scene_model import limit_mode, load_mechanism
    from pinmech.io.sweep import sweep_options
    from pinmech.io.tables import PathCsv

    if "task" not in scene.raw:
        raise PinmechError(f"{scene.path}: no [[task]] to follow; a scene with [drivers] is swept: "
                           "pinmech sweep SCENE")
    figure = _check_outputs(args, scene)
    options = sweep_options(scene)  # the scene's scheme and gain checked there, naming the file and key
    duration, step, gain = _timing(args, scene, options)
    scheme = args.scheme or options.get("scheme", "taylor")
    mechanism = load_mechanism(scene)
    q0, _, _ = scene_pose(scene, mechanism)
    total = step_count(duration, step) + 1
    sinks = Outputs()
    if args.plot_path:
        from pinmech.draw.plot_task import PathPlot

        note = f" ({scheme}, step {step:g} s" + (f", feedback {gain:g}/s)" if gain else ")")
        sinks.plot(PathPlot(mechanism, scene.title, note=note, total=total), figure)
    if args.csv_path or not (args.plot_path or args.json_path):
        sinks.table(PathCsv, mechanism, args.csv_path, "path points")
    if args.json_path:
        sinks.table(_PathJsonLines, mechanism, args.json_path, None)
    worst = 0.0
    limits = _LimitWatch(limit_mode(scene, getattr(args, "limits", None)), "path points", "")
    with sinks:
        for point in _progress(follow_path(mechanism, scene_tasks(scene), q0, duration=duration, step=step,
                                           gain=gain, scheme=scheme), total):
            limits.check(limits_at(mechanism, point.q), f"at t = {point.time:.6g} s")
            sinks.add(point)
            worst = max(worst, point.drift)
    limits.summary(total)
    print(f"largest drift of the path from the one asked: {worst:.3e} m", file=sys.stderr)
    return 0


def _timing(args: argparse.Namespace, scene, options: dict[str, Any]) -> tuple[float, float, float]:
    """A path's duration and step [s] and feedback gain [1/s], each error blaming the flag
    or the scene's key it came from."""
    from pinmech.solve.path import check_timing

    duration = _option(_given(args.duration, "--duration"), "--duration", scene, options, "duration")
    if not duration.value:
        raise PinmechError(f"{scene.path}: say how long to follow the task: --duration '0.08 s' "
                           "(or [sweep] duration = \"0.08 s\")")
    step = _option(_given(args.step, "--step"), "--step", scene, options, "step", "1 ms")
    gain = _option(args.gain, "--gain", scene, options, "gain", 0.0)
    values = {}
    for option in (duration, step):
        values[option.flag] = option.quantity("time")
        if not values[option.flag] > 0:
            raise option.error(f"must be a positive time, got {option.value!r}")
    T, h = values["--duration"], values["--step"]
    if h > T:
        blamed = duration if step.key and not duration.key else step  # the flag just typed, else the step
        raise blamed.error(f"the step ({step.name} = {h:g} s) must not be longer than the duration "
                           f"({duration.name} = {T:g} s)")
    if not 0 <= gain.value <= 1 / h:
        raise gain.error(f"must be a number from 0 to 1/step = {1 / h:.6g} [1/s] (a larger feedback overshoots "
                         f"within one step), got {gain.value!r}")
    check_timing(T, h, float(gain.value), names=(duration.where, step.where, gain.where))
    return T, h, float(gain.value)


_ARROW_COLOURS = {"velocity": (0.1, 0.2, 0.9), "acceleration": (0.9, 0.5, 0.0)}
_ARROW_UNITS = {"velocity": "m/s", "acceleration": "m/s^2"}


def _visuals(mechanism):
    """The mechanism's visual geometry, built only when drawing: meshes of the model's own
    package only (the others named on stderr), links without visuals sketched."""
    from pinmech.draw.pages import mechanism_visuals

    visuals, skipped = mechanism_visuals(mechanism)
    for mesh in skipped:
        print(f"pinmech: warning: mesh {mesh} left out of the drawing: it is outside the model's package",
              file=sys.stderr)
    return visuals


def cmd_snapshot(args: argparse.Namespace) -> int:
    """`pinmech snapshot SCENE -o FILE.html`: the solved pose, framed, with points and arrows."""
    from pinmech.io.analysis import analyse
    from pinmech.draw import Arrow, snapshot_html

    scene = _scene(args)
    _check_page(args, scene)
    analysis = analyse(scene)
    from pinmech.model.display import labelled_places

    points = labelled_places(analysis.mechanism, analysis.solution.q)  # joints and points, as the textbook names them
    arrows = []
    for spec in args.arrows:
        name, _, quantity = spec.rpartition(".")
        if name not in analysis.motion.points or quantity not in _ARROW_COLOURS:
            raise PinmechError(f"--arrows {spec}: expected POINT.velocity or POINT.acceleration with a reported "
                               f"point ({', '.join(analysis.motion.points)})")
        point = analysis.motion.points[name]
        arrows.append(Arrow(point.position, getattr(point, quantity), _ARROW_COLOURS[quantity], spec,
                            _ARROW_UNITS[quantity]))
    mechanism = analysis.mechanism
    html = snapshot_html(mechanism.model, _visuals(mechanism), analysis.solution.q, points=points, arrows=arrows,
                         plane_normal=mechanism.plane_normal, show_grid=not args.no_grid)
    _write(args.output, html)
    return 0


#: Most frames `pinmech animate` puts in one page (each frame keeps every link's placement).
_MAX_FRAMES = 20_000


def cmd_animate(args: argparse.Namespace) -> int:
    """`pinmech animate SCENE -o FILE.html [--gif FILE] [--mp4 FILE]`: a driver cycle (a task
    scene: its task followed in time), each frame a solved, closed pose."""
    from pinmech.draw.animation import driver_frames, task_frames

    outputs = {"-o": args.output, "--gif": args.gif, "--mp4": args.mp4}
    if not any(outputs.values()):
        raise PinmechError("animate writes -o PAGE.html, --gif FILE.gif or --mp4 FILE.mp4: give at least one")
    scene = _scene(args)
    _check_animation(args, scene)
    if not 2 <= args.steps <= _MAX_FRAMES:
        raise PinmechError(f"--steps must be between 2 and {_MAX_FRAMES} frames (each is kept in the page), "
                           f"got {args.steps}")
    if not args.fps > 0:
        raise PinmechError(f"--fps must be positive, got {args.fps}")
    if "task" in scene.raw:
        frames = task_frames(scene, _given(args.duration, "--duration"), args.steps)
    else:
        frames = driver_frames(scene, _given(args.start, "--from"), _given(args.stop, "--to"), args.steps,
                               skip_failures=args.skip_failures)
    if args.output:
        from pinmech.draw import animation_html

        mechanism = frames.mechanism
        _write(args.output, animation_html(mechanism.model, _visuals(mechanism), frames.qs, fps=args.fps,
                                           points_per_frame=frames.places, plane_normal=mechanism.plane_normal,
                                           show_grid=not args.no_grid, title=frames.title,
                                           readouts=frames.readouts, traces=frames.traces()))
    if args.gif:
        from pinmech.draw.animation_export import write_gif

        print(f"wrote {write_gif(frames, args.gif, args.fps)} ({len(frames.qs)} frames)", file=sys.stderr)
    if args.mp4:
        from pinmech.draw.animation_export import write_mp4

        print(f"wrote {write_mp4(frames, args.mp4, args.fps)} ({len(frames.qs)} frames)", file=sys.stderr)
    return 0


def _check_animation(args: argparse.Namespace, scene) -> None:
    """Before solving: the outputs are distinct and writable in kind, ffmpeg is there for
    --mp4, and the range options fit the scene (a driver's range, or a task's duration)."""
    from pinmech.exceptions import OptionRefused
    from pinmech.outputs import check_distinct

    for option, path, suffix in (("--gif", args.gif, ".gif"), ("--mp4", args.mp4, ".mp4")):
        if path and Path(path).suffix.lower() != suffix:
            raise PinmechError(f"{option} {path}: the file must end in {suffix}")
    check_distinct({"-o": args.output, "--gif": args.gif, "--mp4": args.mp4}, _inputs(scene))
    if args.mp4:
        from pinmech.draw.animation_export import check_mp4

        check_mp4(args.mp4)
    task = "task" in scene.raw
    wrong = ["--from"] * bool(task and args.start) + ["--to"] * bool(task and args.stop)
    wrong += ["--duration"] * bool(not task and args.duration)
    if wrong:
        kind = "a task ([[task]]) followed in time: give --duration" if task else "a driver's cycle: give --from/--to"
        raise OptionRefused(f"{', '.join(wrong)}: this scene animates {kind}", options=wrong, scene=str(scene.path))


def cmd_polygon(args: argparse.Namespace) -> int:
    """`pinmech polygon SCENE -o v.svg [--acceleration]`: the graphical method's polygon."""
    from pinmech.io.analysis import analyse
    from pinmech.draw.polygon_svg import polygon_svg
    from pinmech.draw.polygon import acceleration_polygon, velocity_polygon

    args.acceleration = None  # the flag names the polygon here, not the driver's acceleration
    scene = _scene(args)
    _check_page(args, scene)
    if Path(args.output).suffix.lower() != ".svg":  # SVG text under p.png was written and called done
        raise PinmechError(f"-o {args.output}: the polygon is an SVG drawing; name the file *.svg")
    analysis = analyse(scene)
    polygon = (acceleration_polygon if args.acceleration_polygon else velocity_polygon)(analysis)
    _write_text(args.output, polygon_svg(polygon, analysis), "SVG drawing")
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    """`pinmech report SCENE -o page.html [--hand FILE]`: everything about the scene on one offline page."""
    from pinmech.io.analysis import analyse
    from pinmech.draw.report_page import report_html

    if args.steps < 0 or args.steps == 1:
        raise PinmechError(f"--steps must be 0 (no sweep) or at least 2, got {args.steps}")
    checked_count(args.steps, "--steps", f"steps = {args.steps}")
    hand_text = None
    scene = _scene(args)
    _check_page(args, scene, hand=args.hand)
    analysis = analyse(scene)
    if args.hand:
        from pinmech.io.check import DEFAULT_SLACK, compare, format_verdicts, load_hand_file
        from pinmech.io.report import to_dict
        from pinmech.io.scene import Scene

        hand = load_hand_file(args.hand)
        checked = analyse(Scene.load(hand.scene))
        verdicts = compare(to_dict(checked), hand.values, DEFAULT_SLACK)
        hand_text = f"{hand.source or hand.path}  vs  pinmech on {hand.scene.name}\n" + format_verdicts(verdicts)
    _write_text(args.output, report_html(analysis, steps=args.steps, hand_text=hand_text), "offline page")
    return 0


def cmd_build(args: argparse.Namespace) -> int:
    """`pinmech build LINKAGE -o FILE.urdf`: the URDF of a drawn linkage, written whole or not at all."""
    from pinmech.model.linkage_model import build_urdf
    from pinmech.model.linkage_urdf import spanning_tree
    from pinmech.outputs import check_distinct

    check_distinct({"-o": args.output}, {"the linkage file": args.linkage})
    try:
        linkage = build_urdf(args.linkage, args.output)
    except OSError as exc:
        raise PinmechError(f"cannot write {args.output}: {exc.strerror or exc}") from exc
    cuts = [edge.name for edge in spanning_tree(linkage).cuts]
    print(f"{args.output} written: {len(linkage.links) - 1} links, {len(linkage.edges) - len(cuts)} tree joints, "
          f"loop cuts: {', '.join(cuts) or 'none'}")
    return 0


def cmd_view(args: argparse.Namespace) -> int:
    """`pinmech view SCENE`: the solved pose in a live meshcat server; prints its URL."""
    from pinmech.io.analysis import analyse
    from pinmech.draw import live_viewer

    analysis = analyse(_scene(args))
    mechanism = analysis.mechanism
    points = {n: p.position for n, p in analysis.motion.points.items()}
    with live_viewer(mechanism.model, _visuals(mechanism), analysis.solution.q, points=points,
                     plane_normal=mechanism.plane_normal) as view:
        print(view.url)
        try:
            input("press Enter to stop the viewer\n")
        except (EOFError, KeyboardInterrupt):  # no terminal, or Ctrl-C: stop quietly
            pass
    return 0


def _write_text(path: str, text: str, what: str) -> None:
    """Write a whole file at once (a failed write leaves no half file behind) and say so."""
    from pinmech.outputs import write_whole

    write_whole(path, text)
    print(f"wrote {path} ({what}, {max(1, len(text) // 1024)} KB)", file=sys.stderr)


def _check_page(args: argparse.Namespace, scene, hand: str | None = None) -> None:
    """Before computing: the output file can be made and is not an input."""
    from pinmech.outputs import check_distinct

    check_distinct({"-o": args.output}, _inputs(scene, hand))


def _write(path: str, html: str) -> None:
    from pinmech.outputs import write_whole

    write_whole(path, html)
    print(f"wrote {path} ({len(html) // 1024} KB, offline: open it in any browser)", file=sys.stderr)


class _PathJsonLines:
    """One JSON object per path point (SI): t, q, v, a, drift, condition number."""

    def __init__(self, mechanism, stream) -> None:
        self.stream = stream

    def add(self, point) -> None:
        import json

        self.stream.write(json.dumps({"t": point.time, "q": point.q.tolist(), "v": point.v.tolist(),
                                      "a": point.a.tolist(), "drift": point.drift,
                                      "angular_drift": point.angular_drift, "condition_number": point.condition})
                          + "\n")

    def close(self) -> None:
        self.stream.flush()


def cmd_check(args: argparse.Namespace) -> int:
    """`pinmech check HAND_FILE`: hand values against pinmech, non-zero exit on a mismatch."""
    from pinmech.io.analysis import analyse
    from pinmech.io.check import DEFAULT_SLACK, check_slack, compare, format_verdicts, load_hand_file
    from pinmech.io.report import to_dict
    from pinmech.io.scene import Scene

    slack = args.slack if args.slack is not None else DEFAULT_SLACK
    try:
        check_slack(slack, "--slack")
    except PinmechError as exc:  # a usage error (2), not a hand file's (4)
        raise PinmechError(str(exc)) from None
    hand = load_hand_file(args.hand_file)
    analysis = analyse(Scene.load(hand.scene, args.overrides))
    verdicts = compare(to_dict(analysis), hand.values, slack)
    print(f"{hand.source or hand.path}  vs  pinmech on {hand.scene.name}")
    print(format_verdicts(verdicts))
    return 1 if any(v.verdict == "MISMATCH" for v in verdicts) else 0


class _ParseAgain(Exception):
    """A command line the one-subcommand parser cannot take."""


class _SubcommandOnly(argparse.ArgumentParser):
    """A parser that stops at an error instead of printing it: `parse_args` then parses
    again with every subcommand's parser, which says what is wrong as it always has."""

    def error(self, message: str):
        raise _ParseAgain(message)


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The command line parsed, building only the parser of the subcommand it names
    (all eleven, with their help texts, take about 10 ms to build). Any error, and
    `pinmech --help`, go through the full parser: the messages are the same."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in _SUBCOMMANDS:
        try:
            return build_parser(argv[0], parser_class=_SubcommandOnly).parse_args(argv)
        except _ParseAgain:
            pass
    return build_parser().parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; every pinmech error becomes one line on stderr and its exit code."""
    args = parse_args(argv)
    try:
        with SIGNALS.installed():
            return args.func(args)
    except KeyboardInterrupt as exc:  # Ctrl-C, SIGTERM, SIGHUP: one line, 128 + the signal's number
        signum = getattr(exc, "signum", signal.SIGINT)
        print(f"pinmech: interrupted by {signal.Signals(signum).name}: stopped{_kept(exc)}", file=sys.stderr)
        return 128 + int(signum)
    except PinmechError as exc:
        print(f"pinmech: error: {_one_line(exc)}{_kept(exc)}", file=sys.stderr)
        return exc.exit_code
    except ImportError as exc:
        print(f"pinmech: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # `pinmech sweep ... | head`
        return 0
    except OSError as exc:  # an output file that cannot be written (no such folder, no permission)
        print(f"pinmech: error: {_one_line(exc)}{_kept(exc)}", file=sys.stderr)
        return 2


def _one_line(error: BaseException) -> str:
    """The error's message on one line (a library's message may run over several)."""
    return " ".join(part.strip() for part in str(error).splitlines() if part.strip())


def _kept(error: BaseException) -> str:
    """The partial output files a failed run kept (outputs.py), for its one line."""
    kept = getattr(error, "kept", [])
    return f"; incomplete output kept in {', '.join(kept)}" if kept else ""


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
