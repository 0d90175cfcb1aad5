"""Regenerate the pictures of the docs (and the README) of the bundled mechanisms: each pose drawn by
`pinmech.draw` as an offline meshcat page, then photographed by headless chromium, the same
route as the browser tests (tests/browser.py).

- `docs/images/r_rtr.png`: the R-RTR of Problem Chapter I.9 at crank angle 30 deg, crank
  at -50 rpm without angular acceleration: velocity (blue) and acceleration (orange) of D.
- `docs/images/planar_arm.png`: the 3R arm of text 17.110 at (50, -65, -75) deg, D moving
  at 1 m/s along x while CD does not turn: velocities of B, C and D (one scale).

- `docs/images/four_bar.png`, `docs/images/slider_crank.png`: the bundled scenes as
  `pinmech snapshot` draws them; `docs/images/four_bar_bare.png`: the four-bar with every
  `<visual>` taken out (a user's model), and `docs/images/jansen_leg.png`, a model written
  without any: their links sketched from their joints and points.
- `docs/images/sweep_r_rtr.png`, `sweep_four_bar.png`, `docs/images/paths_four_bar.png`
  (with `--timing-marks`), `paths_jansen_leg.png`, `paths_four_bar_drawn.png` (the drawn
  four-bar): `pinmech sweep --plot` and `--paths`;
  `docs/images/animate_four_bar.gif` and `.png`: `pinmech animate --gif`, and its page with
  the slider moved to frame 30; `docs/images/path_planar_arm.png`: `pinmech path --plot`; `docs/images/torque_slider_crank.png`: `--torque-plot`; `docs/images/polygon_v_r_rtr.png`,
  `polygon_a_r_rtr.png`, `polygon_a_four_bar.png`: `pinmech polygon`;
  `docs/images/report_r_rtr_page1.png`: the first page of `pinmech report`, printed to PDF by
  chromium (poppler's `pdftoppm` makes the picture).
- `docs/images/study_four_bar_histogram.png`, `study_four_bar_sensitivity.png`,
  `study_four_bar_grid.png`: `pinmech study --out --plot` of models/studies/four_bar_tolerance.toml
  and four_bar_grid.toml.

Poses and rates of the first two come from the independent closed forms in
scripts/closed_form.py; the models are built from the URDF files directly. The others run
pinmech's own commands on the bundled scenes.

Run: python scripts/render_snapshots.py   (needs pinmech[viz] and Debian's chromium)
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"
MODELS = ROOT / "models"
SCENES = {"r_rtr": ["v_D", "a_D"], "planar_arm": ["v_B", "v_C", "v_D"]}  # picture: arrows drawn
BLUE, ORANGE = (0.1, 0.2, 0.9), (0.9, 0.5, 0.0)
Z = np.array([0.0, 0.0, 1.0])


def _xyz(v: np.ndarray) -> np.ndarray:
    """A planar vector (x, y) as a spatial one (x, y, 0)."""
    return np.array([v[0], v[1], 0.0])


def r_rtr_drawing() -> tuple[np.ndarray, dict, list]:
    """The R-RTR's configuration, named points [m] and arrows at crank angle 30 deg."""
    from closed_form import r_rtr

    from pinmech.draw import Arrow

    theta = math.radians(30.0)
    r = r_rtr(theta, -50.0 * math.pi / 30.0, 0.0)  # -50 rpm, no crank acceleration
    q_B = float(r.phi3) - theta
    q = np.array([math.cos(theta), math.sin(theta), math.cos(q_B), math.sin(q_B), -float(r.s)])
    points = {"A": np.zeros(3), "B": _xyz(r.B), "C": np.array([0.05, 0.0, 0.0]), "D": _xyz(r.D)}
    arrows = [
        Arrow(points["D"], _xyz(r.vD), BLUE, "v_D", "m/s"),
        Arrow(points["D"], _xyz(r.aD), ORANGE, "a_D", "m/s^2"),
    ]
    return q, points, arrows


def planar_arm_drawing() -> tuple[np.ndarray, dict, list]:
    """The 3R arm's configuration, named points [m] and point velocities of text 17.110."""
    from closed_form import planar_arm_rates

    from pinmech.draw import Arrow

    q = np.radians([50.0, -65.0, -75.0])
    th1, th_BC, th_CD = np.cumsum(q)
    rates = planar_arm_rates(th1, th_BC, th_CD, 0.30, 0.30, 0.17, vD=[1.0, 0.0], aD=[0.0, 0.0])
    e1, e2 = np.array([math.cos(th1), math.sin(th1)]), np.array([math.cos(th_BC), math.sin(th_BC)])
    B, C = 0.30 * e1, 0.30 * e1 + 0.30 * e2
    vB = float(rates.omega_AB) * 0.30 * np.array([-e1[1], e1[0]])
    vC = vB + float(rates.omega_BC) * 0.30 * np.array([-e2[1], e2[0]])
    points = {"A": np.zeros(3), "B": _xyz(B), "C": _xyz(C), "D": _xyz(rates.D)}
    arrows = [
        Arrow(points["B"], _xyz(vB), BLUE, "v_B", "m/s"),
        Arrow(points["C"], _xyz(vC), BLUE, "v_C", "m/s"),
        Arrow(points["D"], np.array([1.0, 0.0, 0.0]), BLUE, "v_D", "m/s"),
    ]
    return q, points, arrows


DRAWINGS = {"r_rtr": r_rtr_drawing, "planar_arm": planar_arm_drawing}


def page(name: str, arrow_labels: list[str]) -> str:
    """The offline page of one bundled mechanism, with the arrows named in `arrow_labels`."""
    import pinocchio as pin

    from pinmech.draw import load_visuals, snapshot_html

    urdf = MODELS / f"{name}.urdf"
    model = pin.buildModelFromUrdf(str(urdf))
    q, points, arrows = DRAWINGS[name]()
    arrows = [a for a in arrows if a.label in arrow_labels]
    return snapshot_html(
        model,
        load_visuals(urdf, model),
        q,
        points=points,
        arrows=arrows,
        plane_normal=Z,
        title=name,
    )


def cli_pictures(chromium: str, tmp: Path) -> None:
    """The pictures pinmech's own commands make in a browser: snapshots, a bare model, polygons."""
    import re

    from pinmech.cli import main as pinmech
    from pinmech.draw.browser import photograph

    scenes = MODELS / "scenes"
    bare = tmp / "four_bar_bare.urdf"
    bare.write_text(re.sub(r"<visual>.*?</visual>", "", (MODELS / "four_bar.urdf").read_text(), flags=re.DOTALL))
    scene = (scenes / "four_bar.toml").read_text()
    (tmp / "four_bar_bare.toml").write_text(re.sub(r'urdf = ".*"', 'urdf = "four_bar_bare.urdf"', scene))
    for name, scene_file in (("four_bar", scenes / "four_bar.toml"), ("slider_crank", scenes / "slider_crank.toml"),
                             ("four_bar_bare", tmp / "four_bar_bare.toml"), ("jansen_leg", scenes / "jansen_leg.toml")):
        html = tmp / f"{name}.html"
        pinmech(["snapshot", str(scene_file), "-o", str(html), "--no-grid"])
        photograph(chromium, html, IMAGES / f"{name}.png")
    page = tmp / "animate_four_bar.html"
    pinmech(["animate", str(scenes / "four_bar.toml"), "-o", str(page), "--steps", "91"])
    photograph(chromium, page, IMAGES / "animate_four_bar.png", fragment="slider=30")
    for kind in ("v", "a"):
        svg = tmp / f"polygon_{kind}.svg"
        pinmech(["polygon", str(scenes / "r_rtr.toml"), "-o", str(svg)] + (["--acceleration"] if kind == "a" else []))
        photograph(chromium, svg, IMAGES / f"polygon_{kind}_r_rtr.png", window=_svg_pixels(svg))
    svg = tmp / "polygon_a_four_bar.svg"
    pinmech(["polygon", str(scenes / "four_bar.toml"), "-o", str(svg), "--acceleration"])
    photograph(chromium, svg, IMAGES / "polygon_a_four_bar.png", window=_svg_pixels(svg))
    report_picture(chromium, tmp)


def report_picture(chromium: str, tmp: Path) -> None:
    """The R-RTR's report as it prints (one A4 page, PDF, then a PNG of it)."""
    import shutil
    import subprocess

    from pinmech.cli import main as pinmech
    from pinmech.draw.browser import run_chromium

    if shutil.which("pdftoppm") is None:
        print("the report's picture needs poppler-utils: apt-get install poppler-utils")
        return
    page, pdf = tmp / "report.html", tmp / "report.pdf"
    import os

    here = os.getcwd()
    os.chdir(ROOT)  # the page names the scene as a user types it: models/scenes/r_rtr.toml
    try:
        pinmech(["report", "models/scenes/r_rtr.toml", "-o", str(page)])
        page.write_text(page.read_text(encoding="utf-8").replace("</style>", "@page {size: A4}</style>", 1),
                        encoding="utf-8")  # the reader's paper
    finally:
        os.chdir(here)
    run_chromium([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--no-pdf-header-footer",
                  f"--user-data-dir={tmp / 'profile'}", f"--print-to-pdf={pdf}", page.resolve().as_uri()],
                 timeout_s=120)
    subprocess.run(["pdftoppm", "-png", "-r", "90", "-f", "1", "-l", "1", "-singlefile", str(pdf),
                    str(IMAGES / "report_r_rtr_page1")], check=True)


def figure_pictures(tmp: Path) -> None:
    """The matplotlib figures of the README (no browser needed): a sweep, two paths figures,
    the torque and flywheel-energy figure, an arm's path in time."""
    from pinmech.cli import main as pinmech

    scenes = MODELS / "scenes"
    pinmech(["sweep", str(scenes / "r_rtr.toml"), "--plot", str(IMAGES / "sweep_r_rtr.png"), "--csv", str(tmp / "s.csv")])
    pinmech(["sweep", str(scenes / "four_bar.toml"), "--plot", str(IMAGES / "sweep_four_bar.png"),
             "--csv", str(tmp / "f.csv")])
    pinmech(["sweep", str(scenes / "four_bar.toml"), "--paths", str(IMAGES / "paths_four_bar.png"), "--timing-marks"])
    pinmech(["sweep", str(scenes / "jansen_leg.toml"), "--paths", str(IMAGES / "paths_jansen_leg.png")])
    pinmech(["sweep", str(scenes / "four_bar_drawn.toml"), "--steps", "73", "--csv", str(tmp / "d.csv"),
             "--paths", str(IMAGES / "paths_four_bar_drawn.png")])  # the drawn-linkage tutorial's
    pinmech(["animate", str(scenes / "four_bar.toml"), "--steps", "37", "--fps", "12",
             "--gif", str(IMAGES / "animate_four_bar.gif")])
    pinmech(["sweep", str(scenes / "slider_crank_dynamic.toml"), "--torque-plot",
             str(IMAGES / "torque_slider_crank.png"), "--csv", str(tmp / "t.csv")])
    pinmech(["path", str(scenes / "planar_arm.toml"), "--csv", str(tmp / "arm.csv"),
             "--plot", str(IMAGES / "path_planar_arm.png")])
    study_pictures(tmp)


def study_pictures(tmp: Path) -> None:
    """The design studies' figures (`pinmech study --out --plot`, in this process): the
    four-bar's tolerance histograms and sensitivity bars, and its 2-D grid map."""
    import shutil

    from pinmech.cli import main as pinmech

    studies = MODELS / "studies"
    for study, figures in (("four_bar_tolerance", ("histogram", "sensitivity")), ("four_bar_grid", ("grid",))):
        pinmech(["study", str(studies / f"{study}.toml"), "--workers", "0", "--out", str(tmp / study), "--plot"])
        for figure in figures:
            shutil.copyfile(tmp / f"{study}_{figure}.png", IMAGES / f"study_four_bar_{figure}.png")


def _svg_pixels(svg: Path) -> tuple[int, int]:
    """The size of an SVG drawing given in millimetres, in CSS pixels (96 per inch)."""
    import xml.etree.ElementTree as ET

    root = ET.parse(svg).getroot()
    return tuple(round(float(root.get(k).removesuffix("mm")) * 96 / 25.4) + 1 for k in ("width", "height"))


def main() -> None:
    """Write every picture of the README under docs/images (the browser's only with chromium)."""
    from pinmech.draw.browser import find_chromium, photograph

    sys.path.insert(0, str(Path(__file__).resolve().parent))  # closed_form.py, beside this file
    IMAGES.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            print('the figures need matplotlib: pip install "pinmech[plot]"')
        else:
            figure_pictures(Path(tmp))
        chromium = find_chromium()
        if chromium is None:
            print("the snapshots and polygons: this script needs Debian's chromium: apt-get install chromium")
            return
        try:
            import meshcat  # noqa: F401
        except ImportError:
            print('the snapshots need meshcat: pip install "pinmech[viz]"')
            return
        for name, arrow_labels in SCENES.items():
            html = Path(tmp) / f"{name}.html"
            html.write_text(page(name, arrow_labels), encoding="utf-8")
            photograph(chromium, html, IMAGES / f"{name}.png")
            print(f"wrote {IMAGES / f'{name}.png'}")
        cli_pictures(chromium, Path(tmp))


if __name__ == "__main__":
    main()
