"""The complete argument parser of the `pinmech` command: `build_parser()` (the docs' CLI
reference is generated from it). Each subcommand adds its own sub-parser (its module's
`add_parser`), and its module is imported only when its parser is built: `pinmech solve`
imports none of the other subcommands. A new subcommand is one line in `SUBCOMMANDS`."""

from __future__ import annotations

import argparse
import importlib

from pinmech import __version__


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
    for name, module in SUBCOMMANDS.items():
        if command is None or name == command:
            importlib.import_module(module).add_parser(sub)
    return parser


#: Each subcommand's module (its `add_parser` adds its sub-parser), in the order
#: `pinmech --help` lists them.
SUBCOMMANDS = {
    "solve": "pinmech.cli.solve",
    "forces": "pinmech.cli.forces",
    "sweep": "pinmech.cli.sweep",
    "path": "pinmech.cli.path",
    "snapshot": "pinmech.cli.snapshot",
    "animate": "pinmech.cli.animate",
    "polygon": "pinmech.cli.polygon",
    "report": "pinmech.cli.report",
    "view": "pinmech.cli.view",
    "build": "pinmech.cli.build",
    "check": "pinmech.cli.check",
    "study": "pinmech.design.study.cli",
    "synth": "pinmech.design.synthesis.cli",
    "design": "pinmech.cli.design",
}
