"""The design page tutorial's pictures (docs/tutorials/design_page.md), taken in headless
chromium through its DevTools protocol from the page's own server: the bundled four-bar as
opened, with B dragged, B dragged at crank 90 deg, a drag the linkage cannot follow,
instant centres and arrows on, targets clicked with a synthesis's answers, poses placed
for a motion synthesis, and a six-bar.

Run: python scripts/design_page_pictures.py [--out docs/images]   (Debian's chromium, pinmech[page])
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LINKAGES = ROOT / "models" / "linkages"
IDLE = "window.pinmechPage && window.pinmechPage.frame !== null && !window.pinmechPage.pending"
DIAGNOSED = "document.getElementById('diagnostics').className.indexOf('stale') < 0"


def _open(file: Path, folder: Path):
    from pinmech.draw.design_page.messages import Saving
    from pinmech.draw.design_page.session import Session, read_design_file
    from pinmech.draw.design_page.server import PageServer

    copy = folder / file.name
    shutil.copy(file, copy)
    spec, source, driver, speed = read_design_file(copy)
    return PageServer(Session(spec, source, driver=driver, speed=speed), Saving(copy, "")).start()


def _screen(page, x: float, y: float) -> tuple[float, float]:
    return tuple(page.evaluate(
        f"(() => {{ const s = document.getElementById('drawing'); const p = s.createSVGPoint(); "
        f"p.x = {x * 1000}; p.y = {-y * 1000}; const q = p.matrixTransform(s.getScreenCTM()); return [q.x, q.y]; }})()"))


def _joint(page, name: str) -> tuple[float, float]:
    """Where joint `name`'s circle is on the screen [CSS pixels]."""
    return tuple(page.evaluate(
        f"(() => {{ const r = document.querySelector('circle[data-joint=\"{name}\"]').getBoundingClientRect(); "
        "return [r.x + r.width / 2, r.y + r.height / 2]; })()"))


def _pose(page, index: int) -> None:
    """Move the crank slider to pose `index` (degrees from the drawn pose)."""
    page.evaluate(f"document.getElementById('pose').value = {index};"
                  "document.getElementById('pose').dispatchEvent(new Event('input'))")


def _focus_synthesis(page) -> None:
    """Fold the panel's other sections so that the synthesis box is in the picture."""
    page.evaluate("for (const d of document.querySelectorAll('#panel details')) d.open = d.id === 'synthesis-box';")


def _settled(page) -> None:
    page.wait_for(IDLE)
    page.wait_for(DIAGNOSED)


def four_bar_pictures(chromium: str, out: Path, folder: Path) -> None:
    from pinmech.draw.devtools import DevToolsPage

    server = _open(LINKAGES / "four_bar.toml", folder)
    try:
        with DevToolsPage(chromium, server.url) as page:
            _settled(page)
            page.screenshot(out / "design_page_open.png")
            page.drag(_joint(page, "B"), _screen(page, 0.115, 0.125), steps=6, settle=IDLE)
            _settled(page)
            page.screenshot(out / "design_page_dragged.png")
            _pose(page, 90)
            b = page.evaluate("window.pinmechPage.frame.paths.B.slice(180, 182)")
            page.drag(_joint(page, "B"), _screen(page, b[0] + 0.012, b[1] + 0.006), steps=5, settle=IDLE)
            _settled(page)
            page.screenshot(out / "design_page_posed.png")
            _pose(page, 0)
            page.evaluate("document.getElementById('show-centres').click(); document.getElementById('show-arrows').click();"
                          "document.getElementById('pose').value = 60;"
                          "document.getElementById('pose').dispatchEvent(new Event('input'))")
            page.wait_for("window.pinmechPage.motion && window.pinmechPage.centres")
            page.screenshot(out / "design_page_centres.png")
            page.evaluate("document.getElementById('show-centres').click(); document.getElementById('show-arrows').click();"
                          "document.getElementById('pose').value = 0;"
                          "document.getElementById('pose').dispatchEvent(new Event('input'))")
            page.drag(_joint(page, "A"), _screen(page, 0.4, 0.0), steps=4, settle=IDLE)  # |A O4| past |A B| + |B O4|
            page.wait_for(IDLE)
            page.screenshot(out / "design_page_cannot.png")
    finally:
        server.stop()
    server = _open(LINKAGES / "four_bar.toml", folder)
    try:
        with DevToolsPage(chromium, server.url) as page:
            _settled(page)
            _synthesis(page, out)
            page.evaluate("document.getElementById('targets-on').click(); document.getElementById('targets-clear').click()")
            _motion(page, out)
    finally:
        server.stop()


def _synthesis(page, out: Path) -> None:
    import numpy as np

    curve = np.array(page.evaluate("window.pinmechPage.frame.paths.P")).reshape(-1, 2)[::36][:8]
    _focus_synthesis(page)
    page.evaluate("document.getElementById('targets-on').click()")
    for x, y in curve:
        sx, sy = _screen(page, x, y)
        page.mouse("mousePressed", sx, sy)
        page.mouse("mouseReleased", sx, sy)
    page.evaluate("document.getElementById('synth-generations').value = 300")
    page.evaluate("document.getElementById('synth-run').click()")
    page.wait_for("window.pinmechPage.answers.length > 0 || document.getElementById('synth-progress')"
                  ".textContent.indexOf('pinmech synth') >= 0", timeout=300, every=0.5)
    page.evaluate("document.querySelector('#answers li').click()")
    page.screenshot(out / "design_page_synthesis.png")


def _motion(page, out: Path) -> None:
    """Five poses placed by mouse (press at the place, drag towards the angle), the bounds proposed."""
    import math

    _focus_synthesis(page)
    page.evaluate("const t = document.getElementById('synth-task'); t.value = 'motion';"
                  "t.dispatchEvent(new Event('change')); document.getElementById('targets-on').click()")
    for k in range(5):
        t = 0.5 + 0.45 * k
        x, y = 0.05 + 0.05 * math.cos(t), 0.05 + 0.05 * math.sin(t)
        start, end = _screen(page, x, y), _screen(page, x + 0.02 * math.cos(t + 1.2), y + 0.02 * math.sin(t + 1.2))
        page.drag(start, end, steps=4)
    page.evaluate("document.getElementById('bounds-propose').click()")
    page.wait_for("document.getElementById('bounds').value.length > 0")
    page.screenshot(out / "design_page_motion.png")


def six_bar_picture(chromium: str, out: Path, folder: Path) -> None:
    from pinmech.draw.devtools import DevToolsPage

    server = _open(LINKAGES / "watt.toml", folder)
    try:
        with DevToolsPage(chromium, server.url) as page:
            _settled(page)
            page.screenshot(out / "design_page_watt.png")
    finally:
        server.stop()


def main(argv: list[str] | None = None) -> None:
    from pinmech.draw.browser import find_chromium

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "images"), help="folder of the pictures")
    args = parser.parse_args(argv)
    chromium = find_chromium()
    if chromium is None:
        print("needs Debian's chromium (apt-get install chromium): no pictures taken")
        return
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as folder:
        four_bar_pictures(chromium, out, Path(folder))
        six_bar_picture(chromium, out, Path(folder))
    print(f"wrote the design page's pictures in {out}")


if __name__ == "__main__":
    main()
