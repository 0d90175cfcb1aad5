"""The complete argument parser of the `pinmech` command: `build_parser()` (the docs' CLI
reference is generated from it). Each subcommand adds its own sub-parser (its module's
`add_parser`); a new subcommand is one line in `SUBCOMMANDS`."""

from __future__ import annotations

import argparse

from pinmech import __version__
from pinmech.cli.animate import add_parser as add_animate_parser
from pinmech.cli.build import add_parser as add_build_parser
from pinmech.cli.check import add_parser as add_check_parser
from pinmech.cli.forces import add_parser as add_forces_parser
from pinmech.cli.path import add_parser as add_path_parser
from pinmech.cli.polygon import add_parser as add_polygon_parser
from pinmech.cli.report import add_parser as add_report_parser
from pinmech.cli.snapshot import add_parser as add_snapshot_parser
from pinmech.cli.solve import add_parser as add_solve_parser
from pinmech.cli.sweep import add_parser as add_sweep_parser
from pinmech.cli.view import add_parser as add_view_parser
from pinmech.design.study_cli import add_parser as add_study_parser
from pinmech.design.synthesis_cli import add_parser as add_synth_parser


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
        "15 synthesis found no linkage, "
        "130 Ctrl-C (128 + signal).",
    )
    parser.add_argument("--version", action="version", version=f"pinmech {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, add in SUBCOMMANDS.items():
        if command is None or name == command:
            add(sub)
    return parser


#: Each subcommand's parser, in the order `pinmech --help` lists them.
SUBCOMMANDS = {
    "solve": add_solve_parser,
    "forces": add_forces_parser,
    "sweep": add_sweep_parser,
    "path": add_path_parser,
    "snapshot": add_snapshot_parser,
    "animate": add_animate_parser,
    "polygon": add_polygon_parser,
    "report": add_report_parser,
    "view": add_view_parser,
    "build": add_build_parser,
    "check": add_check_parser,
    "study": add_study_parser,
    "synth": add_synth_parser,
}
