"""`pinmech polygon SCENE -o v.svg`: the velocity or acceleration polygon of a planar pose."""

from __future__ import annotations

import argparse
from pathlib import Path

from pinmech.cli.files import check_page, write_text
from pinmech.cli.scene_args import scene_from_args
from pinmech.exceptions import PinmechError


def add_parser(sub) -> None:
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


def cmd_polygon(args: argparse.Namespace) -> int:
    """`pinmech polygon SCENE -o v.svg [--acceleration]`: the graphical method's polygon."""
    from pinmech.io.analysis import analyse
    from pinmech.draw.polygon_svg import polygon_svg
    from pinmech.draw.polygon import acceleration_polygon, velocity_polygon

    args.acceleration = None  # the flag names the polygon here, not the driver's acceleration
    scene = scene_from_args(args)
    check_page(args, scene)
    if Path(args.output).suffix.lower() != ".svg":  # SVG text under p.png was written and called done
        raise PinmechError(f"-o {args.output}: the polygon is an SVG drawing; name the file *.svg")
    analysis = analyse(scene)
    polygon = (acceleration_polygon if args.acceleration_polygon else velocity_polygon)(analysis)
    write_text(args.output, polygon_svg(polygon, analysis), "SVG drawing")
    return 0
