"""`pinmech snapshot SCENE -o FILE.html`: the solved pose as an offline meshcat page."""

from __future__ import annotations

import argparse

from pinmech.cli.arguments import add_scene_arguments
from pinmech.cli.files import check_page, write_page
from pinmech.cli.scene_args import scene_from_args
from pinmech.cli.visuals import visuals
from pinmech.exceptions import PinmechError

_ARROW_COLOURS = {"velocity": (0.1, 0.2, 0.9), "acceleration": (0.9, 0.5, 0.0)}
_ARROW_UNITS = {"velocity": "m/s", "acceleration": "m/s^2"}


def add_parser(sub) -> None:
    snap = sub.add_parser("snapshot", help="save the solved pose as an offline meshcat HTML page (pinmech[viz])")
    add_scene_arguments(snap)
    snap.add_argument("-o", "--output", required=True, help="the HTML file to write")
    snap.add_argument("--arrows", nargs="*", default=[], metavar="POINT.QUANTITY",
                      help="vectors to draw, e.g. D.velocity D.acceleration (scaled to fit)")
    snap.add_argument("--no-grid", action="store_true", help="hide meshcat's grid and axes")
    snap.set_defaults(func=cmd_snapshot)


def cmd_snapshot(args: argparse.Namespace) -> int:
    """`pinmech snapshot SCENE -o FILE.html`: the solved pose, framed, with points and arrows."""
    from pinmech.io.analysis import analyse
    from pinmech.draw import Arrow, snapshot_html

    scene = scene_from_args(args)
    check_page(args, scene)
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
    html = snapshot_html(mechanism.model, visuals(mechanism), analysis.solution.q, points=points, arrows=arrows,
                         plane_normal=mechanism.plane_normal, show_grid=not args.no_grid)
    write_page(args.output, html)
    return 0


#: Most frames `pinmech animate` puts in one page (each frame keeps every link's placement).
_MAX_FRAMES = 20_000
