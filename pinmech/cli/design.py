"""`pinmech design FILE`: the design page of a drawn linkage, in the browser."""

from __future__ import annotations

import argparse
from pathlib import Path

from pinmech.exceptions import PinmechError


def add_parser(sub) -> None:
    page = sub.add_parser("design", help="design a drawn linkage in the browser: drag its joints and see its "
                          "curves and diagnostics redrawn (pinmech[page])")
    page.add_argument("file", help="a drawn-linkage TOML file, a scene that names one (linkage = ...), or a "
                      "synthesis file (its search run first; its best answer opened, the others listed)")
    page.add_argument("--driver", help="the driven joint (default: the scene's driver, or the linkage's first joint)")
    page.add_argument("--speed", help="the driver's speed for velocities and accelerations (default: the "
                      "scene's, or '60 rpm')")
    page.add_argument("-o", "--output", help="where the page saves the linkage (default: FILE's linkage "
                      "itself); the scene and figures are written beside it")
    page.add_argument("--port", type=int, default=0, help="the port on 127.0.0.1 (default: any free one)")
    page.add_argument("--no-browser", action="store_true", help="print the page's address, open no browser")
    page.set_defaults(func=cmd_design)


def cmd_design(args: argparse.Namespace) -> int:
    """Serve the page until Ctrl-C; its address (with its token) printed."""
    try:
        import starlette  # noqa: F401
        import uvicorn  # noqa: F401
    except ImportError as exc:
        raise PinmechError(f"pinmech design needs the page extra: pip install 'pinmech[page]' ({exc})") from None
    from pinmech.draw.design_page.messages import Saving
    from pinmech.draw.design_page.save import leading_comments
    from pinmech.draw.design_page.server import PageServer
    from pinmech.draw.design_page.session import Session, is_synthesis_file, read_design_file

    if not 0 <= args.port <= 65535:
        raise PinmechError(f"--port must be between 0 and 65535, got {args.port}")
    run = None
    if is_synthesis_file(args.file):
        from pinmech.draw.design_page.synthesis import open_synthesis

        print(f"pinmech design: running pinmech synth {args.file} first ...", flush=True)
        run, answer = open_synthesis(Path(args.file))
        print(f"pinmech design: {answer['progress']}", flush=True)
        spec, source, driver, speed = run.specs[0], str(Path(args.file).with_suffix("")) + "_design.toml", None, None
    else:
        spec, source, driver, speed = read_design_file(args.file)
    session = Session(spec, source, driver=args.driver or driver, speed=args.speed or speed or "60 rpm")
    if run is not None:
        from pinmech.draw.design_page.synthesis import adopt_run

        adopt_run(session, run)
    target = Path(args.output) if args.output else Path(source)
    header = leading_comments(run.folder / "answer_1.toml" if run is not None else Path(source))
    server = PageServer(session, Saving(target, header), args.port)
    print(f"pinmech design: {server.url}  (Ctrl-C stops)", flush=True)
    if not args.no_browser:
        import webbrowser

        webbrowser.open(server.url)
    try:
        server.serve()
    finally:
        session.close()
    return 0
