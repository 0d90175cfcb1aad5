"""Argument groups several subcommands share: a scene and its overrides, outputs, a task's
timing, force options, joint limits."""

from __future__ import annotations

import argparse

from pinmech.solve.kernels import KERNELS


def add_scene_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene file (TOML), e.g. models/scenes/r_rtr.toml")
    parser.add_argument(
        "--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
        help="override a scene value, e.g. --set 'drivers.A.angle=\"45 deg\"' (repeatable)",
    )
    parser.add_argument("--angle", help="shortcut: the (single) driver's angle or position, e.g. '45 deg'")
    parser.add_argument("--speed", help="shortcut: the driver's speed, e.g. '-50 rpm' or '2 rad/s'")
    parser.add_argument("--acceleration", help="shortcut: the driver's acceleration, e.g. '1 rad/s^2'")
    parser.add_argument("--kernel", choices=KERNELS,
                        help="kinematic passes: Pinocchio's generic algorithms, or the same algorithms generated "
                        "for the model, compiled once and cached (needs a compiler and pinmech[fast]; "
                        "[solver] kernel)")


def add_certify_argument(parser: argparse.ArgumentParser) -> None:
    """--certify, for the commands that follow ranges of poses (a single pose is always certified)."""
    parser.add_argument("--certify", metavar="LEVEL",
                        help="poses of a range given the exact condition number: every-pose "
                        "(default), every-K (e.g. every-10: every K-th pose and a range's last), ends, or none "
                        "(no condition number); every pose keeps its residual and assembly checks ([solver] certify)")


def add_output_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--csv", dest="csv_path", help="write the CSV here (default: standard output)")
    parser.add_argument("--json", dest="json_path", help="also write the rows as JSON lines here")
    parser.add_argument("--plot", dest="plot_path", help="also draw a figure here (PNG, PDF, SVG; pinmech[plot])")


def add_path_arguments(parser: argparse.ArgumentParser, *, required: bool) -> None:
    parser.add_argument("--duration", required=required,
                        help="task scenes: how long to follow the task, e.g. '0.08 s' ([sweep] duration)")
    parser.add_argument("--step", help="task scenes: integration time step (default '1 ms')")
    parser.add_argument("--scheme", choices=("euler", "taylor", "rk4"),
                        help="task scenes: integration scheme (default taylor, second order)")
    parser.add_argument("--gain", type=float, help="task scenes: feedback on the drift [1/s] (default 0: open loop)")


def add_force_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--static", action="store_true",
                        help="statics: forces with zero speeds and accelerations ([forces] static = true)")
    parser.add_argument("--minimum-norm", dest="minimum_norm", action="store_true",
                        help="forces not determined: the minimum-norm reactions instead of an error "
                             "(a scene's redundant loops are refused before; see docs/howto/forces.md)")


def add_limits_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--limits", choices=("warn", "error"),
                        help="a joint beyond its limits (URDF <limit>, MJCF range): a warning (default) or an error (exit 12)")
