"""`pinmech forces SCENE`: driver efforts and joint reactions at the scene's pose."""

from __future__ import annotations

import argparse

from pinmech.cli.arguments import add_force_arguments, add_scene_arguments
from pinmech.cli.scene_args import scene_from_args


def add_parser(sub) -> None:
    forces = sub.add_parser("forces", help="driver torques and joint reactions at the scene's pose (inverse dynamics)")
    add_scene_arguments(forces)
    add_force_arguments(forces)
    forces.add_argument("--json", action="store_true", help="print one JSON object (SI units) instead of text")
    forces.set_defaults(func=cmd_forces)


def cmd_forces(args: argparse.Namespace) -> int:
    """`pinmech forces SCENE`: the report with driver efforts and joint reactions (or `--json`)."""
    from pinmech.io.analysis import analyse
    from pinmech.io.report import to_json, to_text

    analysis = analyse(scene_from_args(args), forces=True, static=args.static, minimum_norm=args.minimum_norm)
    print(to_json(analysis) if args.json else to_text(analysis), end="" if not args.json else "\n")
    return 0
