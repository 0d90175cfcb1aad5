"""`pinmech view SCENE`: the solved pose in a live meshcat server."""

from __future__ import annotations

import argparse

from pinmech.cli.arguments import add_scene_arguments
from pinmech.cli.scene_args import scene_from_args
from pinmech.cli.visuals import visuals


def add_parser(sub) -> None:
    live = sub.add_parser("view", help="show the solved pose in a live meshcat server (a browser tab)")
    add_scene_arguments(live)
    live.set_defaults(func=cmd_view)


def cmd_view(args: argparse.Namespace) -> int:
    """`pinmech view SCENE`: the solved pose in a live meshcat server; prints its URL."""
    from pinmech.io.analysis import analyse
    from pinmech.draw import live_viewer

    analysis = analyse(scene_from_args(args))
    mechanism = analysis.mechanism
    points = {n: p.position for n, p in analysis.motion.points.items()}
    with live_viewer(mechanism.model, visuals(mechanism), analysis.solution.q, points=points,
                     plane_normal=mechanism.plane_normal) as view:
        print(view.url)
        try:
            input("press Enter to stop the viewer\n")
        except (EOFError, KeyboardInterrupt):  # no terminal, or Ctrl-C: stop quietly
            pass
    return 0
