"""The one-page report, links sketched where a URDF has no visuals, and notebook display.

The page is opened in headless chromium as the drawing tests do: it draws (pixels that are
not the white page), the meshcat frame is framed (its drawing spans most of the frame), and
nothing is fetched (no script, link or image points off the page).
"""

from __future__ import annotations

import html
import math
import re

import numpy as np
import pytest

from pinmech import Scene, analyse, snapshot
from pinmech.cli import main
from pinmech.draw import load_visuals
from pinmech.draw.sketch import sketch_visuals
from pinmech.model.link_nodes import sketch_links
from tests.browser import colour_mask, screenshot, span_share
from tests.conftest import MODELS, SCENES
from tests.tolerance import rounding

CRANK_RED, GUIDE_GREEN = (0.85, 0.15, 0.15), (0.15, 0.65, 0.25)  # the R-RTR's link1 and link3
FRAME_HEIGHT = 520  # the drawing's frame on the page [CSS pixels]
OFF_PAGE = r"""<script[^>]*\ssrc=|<link[^>]*href=|(src|href)=["']?(https?:)?//|src=["']?file:"""


def bare_scene(tmp_path, name: str) -> Scene:
    """A bundled scene on a copy of its URDF with every <visual> taken out: a user's model."""
    text = (MODELS / f"{name}.urdf").read_text(encoding="utf-8")
    text = re.sub(r"<visual>.*?</visual>", "", text, flags=re.DOTALL)
    (tmp_path / f"{name}.urdf").write_text(text, encoding="utf-8")
    scene = (SCENES / f"{name}.toml").read_text(encoding="utf-8")
    scene = re.sub(r'urdf = ".*"', f'urdf = "{name}.urdf"', scene)
    (tmp_path / f"{name}.toml").write_text(scene, encoding="utf-8")
    return Scene.load(tmp_path / f"{name}.toml")


@pytest.mark.parametrize("name", ["four_bar", "slider_crank", "r_rtr"])
def test_every_link_without_visuals_is_sketched(tmp_path, name):
    """Each moving link gets geometry on its own joint; a bar is as long as the link (plus
    its width, the rounded ends); the ground gets a triangle per fixed pivot."""
    analysis = analyse(bare_scene(tmp_path, name))
    mech = analysis.mechanism
    visuals = sketch_visuals(mech, load_visuals(mech.source, mech.model))
    assert len(load_visuals(mech.source, mech.model).geometryObjects) == 0
    drawn = {g.parentJoint for g in visuals.geometryObjects}
    links = sketch_links(mech)
    assert {link.joint for link in links.values()} <= drawn
    pivots = [n for n in links["ground"].nodes if n.kind == "revolute"]
    assert sum(g.parentJoint == 0 and g.name.startswith("sketch_ground") for g in visuals.geometryObjects) >= len(pivots)
    for link in links.values():
        if len(link.nodes) == 2 and not link.is_ground:
            length = np.linalg.norm(link.nodes[0].position - link.nodes[1].position)
            boxes = [g.geometry for g in visuals.geometryObjects if g.parentJoint == link.joint
                     and type(g.geometry).__name__ == "Box"]
            widths = [2 * b.halfSide[1] for b in boxes]
            assert any(abs(2 * b.halfSide[0] - length - w) < rounding(length + w) for b, w in zip(boxes, widths))


def test_a_slider_block_and_the_pivots_of_a_bare_slider_crank():
    mech = analyse(Scene.load(SCENES / "slider_crank.toml")).mechanism
    links = sketch_links(mech)
    assert links["piston"].slide_axis is not None  # the block
    assert links["ground"].guides  # the guide it runs on
    assert {n.kind for n in links["ground"].nodes} == {"revolute", "prismatic"}


@pytest.mark.browser
def test_a_bare_four_bar_is_drawn_and_framed(tmp_path):
    analysis = analyse(bare_scene(tmp_path, "four_bar"))
    page = tmp_path / "bare.html"
    snapshot(analysis).save(page)
    assert span_share(screenshot(page, tmp_path / "bare.png")) > 0.6


@pytest.mark.browser
def test_the_report_page_draws_offline(tmp_path):
    out = tmp_path / "page.html"
    assert main(["report", str(SCENES / "r_rtr.toml"), "-o", str(out), "--steps", "25",
                 "--hand", str(SCENES / "r_rtr.hand.toml")]) == 0
    page = out.read_text(encoding="utf-8")
    assert not re.search(OFF_PAGE, html.unescape(page))
    for part in ("Velocity polygon", "Acceleration polygon", '<img alt="sweep"', '<img alt="paths"', "<iframe", "MISMATCH"
                 if "MISMATCH" in page else "OK"):
        assert part in page
    pixels = screenshot(out, tmp_path / "page.png", window=(1000, 1400))
    assert span_share(pixels) > 0.8
    crank, guide = (colour_mask(pixels, rgb) for rgb in (CRANK_RED, GUIDE_GREEN))
    # the R-RTR's crank and guide, drawn in the space diagram (half the page's width: the design
    # table beside it; the crank alone is about 900 pixels there)
    assert crank.sum() > 500 and guide.sum() > 500
    rows = np.nonzero(crank | guide)[0]
    assert rows.max() - rows.min() > 0.5 * FRAME_HEIGHT  # the mechanism fills its drawing


def test_the_report_page_of_a_bare_model(tmp_path):
    scene = bare_scene(tmp_path, "slider_crank")
    out = tmp_path / "bare_page.html"
    assert main(["report", str(scene.path), "-o", str(out), "--steps", "13"]) == 0
    page = out.read_text(encoding="utf-8")
    assert "paths" in page and "Velocity polygon" in page and not re.search(OFF_PAGE, html.unescape(page))


@pytest.mark.parametrize("name", ["four_bar_drawn.toml", "jansen.toml", "leg_mjcf.toml"])
def test_the_report_page_of_a_drawn_linkage_or_an_mjcf_scene(tmp_path, name):
    """The page took its visuals from the scene's model file as a URDF: every drawn linkage
    and MJCF scene ended in 'cannot build its visual geometry' (exit 9), while snapshot
    drew them. Now the page draws what snapshot draws, offline."""
    out = tmp_path / "page.html"
    assert main(["report", str(SCENES / name), "-o", str(out), "--steps", "0"]) == 0
    page = out.read_text(encoding="utf-8")
    assert "<iframe" in page and not re.search(OFF_PAGE, html.unescape(page))


def test_notebooks_show_tables_and_the_drawing():
    analysis = analyse(Scene.load(SCENES / "r_rtr.toml"))
    table = analysis._repr_html_()
    assert table.count("<table>") == 2 and "<td>D</td>" in table and "10.3803" in table  # |a_D|
    frame = snapshot(analysis)._repr_html_()
    assert frame.startswith("<iframe") and "srcdoc=" in frame


def test_report_steps_must_be_sensible(tmp_path, capsys):
    assert main(["report", str(SCENES / "r_rtr.toml"), "-o", str(tmp_path / "x.html"), "--steps", "1"]) == 2
    assert "--steps" in capsys.readouterr().err and not (tmp_path / "x.html").exists()


def test_snapshot_html_unchanged_for_models_with_visuals():
    """A model with its own visuals keeps exactly them (nothing sketched on top)."""
    mech = analyse(Scene.load(SCENES / "r_rtr.toml")).mechanism
    own = load_visuals(mech.source, mech.model)
    assert len(sketch_visuals(mech, own).geometryObjects) == len(own.geometryObjects)


def test_points_at_one_place_share_one_label():
    """B (crank pin) and B3 (guide point under it) coincide: one label "B, B3"; D apart."""
    from pinmech.draw.scene import coincident_groups

    points = {"B": np.array([0.1, 0.05, 0.0]), "D": np.array([0.2, 0.1, 0.0]), "B3": np.array([0.1, 0.05, 1e-9])}
    assert coincident_groups(points, 1e-6) == [["B", "B3"], ["D"]]
    assert coincident_groups(points, 1e-12) == [["B"], ["D"], ["B3"]]


@pytest.fixture
def rsur(tmp_path):
    """A user's spatial RSUR loop with a point M on its coupler, no visuals (its scene file)."""
    from tests._mechanisms import spatial_rsur_urdf

    urdf = spatial_rsur_urdf().replace("</robot>", '<link name="M"/><joint name="pM" type="fixed"><parent '
                                       'link="coupler"/><child link="M"/><origin xyz="0.075 0 0"/></joint></robot>')
    (tmp_path / "rsur.urdf").write_text(urdf, encoding="utf-8")
    scene = tmp_path / "rsur.toml"
    scene.write_text('title = "RSUR"\nurdf = "rsur.urdf"\n[drivers.R1]\nangle = "20 deg"\nspeed = "60 rpm"\n',
                     encoding="utf-8")
    return scene


def _sweep_m(scene, plane: str, monkeypatch) -> tuple[np.ndarray, object]:
    """M's places from the CSV [mm], and the paths figure pinmech drew, kept open."""
    import pinmech.draw.plot

    kept = []
    monkeypatch.setattr(pinmech.draw.plot, "_save", lambda plt, fig, path: kept.append(fig) or path)
    csv = scene.parent / f"{plane}.csv"
    assert main(["sweep", str(scene), "--from", "0 deg", "--to", "120 deg", "--steps", "25", "--csv", str(csv),
                 "--paths", str(scene.parent / f"{plane}.png"), "--path-plane", plane]) == 0
    lines = csv.read_text(encoding="utf-8").splitlines()
    header, rows = lines[0].split(","), np.array([r.split(",") for r in lines[1:]])
    xyz = 1000 * rows[:, [header.index(f"M.{c} [m]") for c in "xyz"]].astype(float)
    return xyz, kept[0]


def test_a_spatial_mechanisms_paths_projected_or_in_3d(rsur, monkeypatch):
    """Projected on zx, the path drawn is (M.z, M.x) of the CSV; in 3-D it is (x, y, z).
    Tolerance 1e-6 mm: the CSV keeps 12 significant digits of metres."""
    xyz, fig = _sweep_m(rsur, "zx", monkeypatch)
    (path,) = [x for x in fig.axes[0].get_lines() if x.get_label() == "path of M"]
    np.testing.assert_allclose(np.asarray(path.get_xydata(), dtype=float), xyz[:, [2, 0]], atol=1e-6)
    assert "projected on the world zx plane" in fig.axes[0].get_title()
    xyz, fig = _sweep_m(rsur, "3d", monkeypatch)
    (path,) = [x for x in fig.axes[0].get_lines() if x.get_label() == "path of M"]
    np.testing.assert_allclose(np.column_stack(path.get_data_3d()), xyz, atol=1e-6)


def test_a_spatial_users_mechanism_without_visuals(rsur, tmp_path, capsys):
    """Every link of the spatial loop is sketched; a polygon is refused by name (exit 9)."""
    mech = analyse(Scene.load(rsur)).mechanism
    visuals = sketch_visuals(mech, load_visuals(mech.source, mech.model))
    assert {link.joint for link in sketch_links(mech).values()} <= {g.parentJoint for g in visuals.geometryObjects}
    assert main(["polygon", str(rsur), "-o", str(tmp_path / "v.svg")]) == 9
    assert "planar" in capsys.readouterr().err and not (tmp_path / "v.svg").exists()


@pytest.mark.parametrize("name", ["four_bar", "slider_crank", "planar_arm", "r_rtr_task", "jansen_leg"])
def test_every_bundled_planar_scene_makes_a_page(tmp_path, name):
    """Drawing, tables and report on every page; polygons for each planar scene; the sweep
    figure where there is a driver to sweep (task scenes are followed in time instead)."""
    out = tmp_path / f"{name}.html"
    assert main(["report", str(SCENES / f"{name}.toml"), "-o", str(out), "--steps", "9"]) == 0
    page = out.read_text(encoding="utf-8")
    assert "<iframe" in page and "<table>" in page and "Velocity polygon" in page
    assert ('<img alt="sweep"' in page) == (not Scene.load(SCENES / f"{name}.toml").is_task)
    assert not re.search(OFF_PAGE, html.unescape(page))


def test_an_animation_joins_labels_only_of_points_together_in_every_frame():
    from pinmech.draw.pages import _together

    frames = [{"B": np.zeros(3), "B3": np.zeros(3), "P": np.zeros(3)},
              {"B": np.ones(3), "B3": np.ones(3), "P": np.zeros(3)}]
    assert _together(frames, 1e-9) == [["B", "B3"], ["P"]]


def _pdf_words(pdf) -> tuple[list[tuple[float, float, str]], float]:
    """Every word of the PDF with its left and right edge [pt], and the page width [pt]
    (`pdftotext -bbox`, poppler-utils)."""
    import os
    import shutil
    import subprocess

    if shutil.which("pdftotext") is None:  # as tests/browser.py does for chromium
        if os.environ.get("PINMECH_REQUIRE_BROWSER"):
            pytest.fail("PINMECH_REQUIRE_BROWSER is set but pdftotext is not installed (apt-get install poppler-utils)")
        pytest.skip("pdftotext is not installed (apt-get install poppler-utils)")
    out = subprocess.run(["pdftotext", "-bbox", str(pdf), "-"], check=True, capture_output=True, text=True).stdout
    width = float(re.search(r'<page width="([0-9.]+)"', out).group(1))
    words = [(float(a), float(b), html.unescape(w)) for a, b, w in
             re.findall(r'<word xMin="([0-9.]+)" yMin="[0-9.]+" xMax="([0-9.]+)" yMax="[0-9.]+">([^<]*)</word>', out)]
    return words, width


@pytest.mark.browser
def test_the_report_prints_the_drawing_and_the_polygons(tmp_path):
    """Printed to PDF by chromium: the pose is on paper (the WebGL view printed blank: the
    R-RTR's red crank and green guide are found in the page's pixels), every word lies on the
    page, and the acceleration polygon's a_D is |a_D| of the closed form (scripts/closed_form.py)
    at the 4 significant digits the polygon writes. The motion tables stay on the screen
    (the sheet is one page: tests/test_report_sheet.py)."""
    import subprocess

    import closed_form as cf

    from tests.browser import print_pdf, read_png

    out = tmp_path / "page.html"
    assert main(["report", str(SCENES / "r_rtr.toml"), "-o", str(out), "--steps", "0"]) == 0
    pdf = print_pdf(out, tmp_path / "page.pdf")
    words, width = _pdf_words(pdf)
    assert words and max(right for _, right, _ in words) <= width
    text = " ".join(w for *_, w in words)
    a_D = np.linalg.norm(cf.r_rtr(math.radians(30.0), -50.0 * math.pi / 30.0, 0.0).aD)
    assert f"= {a_D:.4g} m/s²" in text
    for part in ("Given", "Design", "Figure 1.", "Figure 2.", "Figure 3.", "pinmech 0.", "r_rtr.toml", "motion tables"):
        assert part in text
    subprocess.run(["pdftoppm", "-png", "-r", "60", "-f", "1", "-l", "1", str(pdf), str(tmp_path / "p")], check=True)
    pixels = read_png(next(tmp_path.glob("p*.png")))
    assert colour_mask(pixels, CRANK_RED).sum() > 100 and colour_mask(pixels, GUIDE_GREEN).sum() > 100


def test_the_page_is_a_lab_report(tmp_path):
    """Given first, then figures numbered 1, 2, ... each once with a caption, the design table (the pose, the two
    polygons, the sweep, the paths), the full text folded under <details>, and the version,
    the date and the scene file on top."""
    import datetime

    from pinmech import __version__

    out = tmp_path / "page.html"
    assert main(["report", str(SCENES / "four_bar.toml"), "-o", str(out), "--steps", "9"]) == 0
    page = out.read_text(encoding="utf-8")
    numbers = [int(n) for n in re.findall(r"<b>Figure (\d+)\.</b>", page)]
    assert numbers == list(range(1, 6))  # pose, velocity, acceleration, sweep, paths
    assert page.index("<h2>Given</h2>") < page.index("<h2>Design</h2>") < page.index("<h2>Results</h2>")
    assert page.count('data-quantity="velocity"') == 1 and page.count('data-quantity="acceleration"') == 1
    assert page.count('class="pose"') == 1 and page.count('class="space-diagram"') == 1  # the mechanism once
    assert re.search(r"<details><summary>[^<]*<code>pinmech solve</code>[^<]*</summary><pre>", page)
    assert f"pinmech {__version__}" in page and str(SCENES / "four_bar.toml") in page
    assert datetime.date.today().isoformat() in page
    assert "@media print" in page and "O2O4 = 100 mm" in page
