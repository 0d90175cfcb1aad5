"""Names and colours every figure shares (pinmech/model/display.py), the paths figure's labels and
arrows of motion, and a sweep figure past folds: spikes clipped, assemblies styled apart,
the folds marked where the closed form puts the limit positions."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import closed_form as cf
import numpy as np
import pytest

from pinmech.cli import main
from pinmech.model.display import display_name
from tests.conftest import MODELS, SCENES
from tests.tolerance import rounding

pytest.importorskip("matplotlib", reason='plots need pip install "pinmech[plot]"')



def _urdf_colours(urdf) -> dict[str, tuple[float, ...]]:
    """Link name -> the RGB of its <visual>'s material, read from the URDF itself."""
    root = ET.parse(urdf).getroot()
    materials = {m.get("name"): tuple(float(c) for c in m.find("color").get("rgba").split()[:3])
                 for m in root.findall("material")}
    return {link.get("name"): materials[link.find("visual/material").get("name")]
            for link in root.findall("link") if link.find("visual/material") is not None}


def _rgb(colour) -> tuple[float, ...]:
    from matplotlib.colors import to_rgb

    return tuple(to_rgb(colour))


def test_a_pin_point_is_named_as_the_textbook_letters_it():
    assert display_name("A_pin") == "A" and display_name("P") == "P"
    assert display_name("B_pin", {"B"}) == "B_pin"  # another point is already B: kept apart


def test_the_four_bar_has_one_colour_a_link_in_the_curves_the_paths_and_its_urdf(figures, tmp_path):
    """The URDF paints the crank red, the coupler blue, the rocker green: the links' sweep
    curves and the sketched links take the same colours (to the 8-bit rounding of a hex
    colour, 1/255); the points B and P each take a colour of their own."""
    urdf = _urdf_colours(MODELS / "four_bar.urdf")
    assert main(["sweep", str(SCENES / "four_bar.toml"), "--steps", "19", "--plot", str(tmp_path / "f.png"),
                 "--links", "crank", "coupler", "rocker", "--points", "P", "B_pin"]) == 0
    fig = figures[0]
    omega = next(ax for ax in fig.axes if ax.get_title().startswith("angular velocity"))
    for line in omega.get_lines():
        if line.get_label() in urdf:
            np.testing.assert_allclose(_rgb(line.get_color()), urdf[line.get_label()], atol=1 / 255)
    paths = fig.axes[-1] if fig.axes[-1].get_title().startswith("paths") else \
        next(ax for ax in fig.axes if ax.get_title().startswith("paths"))
    (p,) = [x for x in paths.get_lines() if x.get_label() == "path of P"]
    speed = next(ax for ax in fig.axes if ax.get_title().startswith("speed"))
    assert {x.get_label() for x in speed.get_lines()} >= {"B", "P"}  # B_pin is the textbook's B
    # a point has a colour of its own (not its link's: B and P were both drawn the coupler's
    # or the rocker's), the same in the panels and the paths
    by_name = {x.get_label(): _rgb(x.get_color()) for x in speed.get_lines() if x.get_label() in ("B", "P")}
    np.testing.assert_allclose(_rgb(p.get_color()), by_name["P"], atol=1 / 255)
    assert np.max(np.abs(np.subtract(by_name["B"], by_name["P"]))) > 0.2
    labels = {t.get_text() for t in paths.texts}
    assert {"O2", "A", "B", "O4", "P"} <= labels  # every joint and named point, once


def test_the_sketched_links_take_the_figures_colours(figures, tmp_path):
    """A model without <visual>: the 3-D sketch colours each link as the figures do."""
    from pinmech.model.display import joint_colours
    from pinmech.draw.sketch import sketch_visuals
    from pinmech.io.scene import Scene
    from pinmech.io.scene_model import load_mechanism

    mechanism = load_mechanism(Scene.load(SCENES / "four_bar.toml"))
    urdf = _urdf_colours(MODELS / "four_bar.urdf")
    colours = joint_colours(mechanism)
    for obj in sketch_visuals(mechanism).geometryObjects:
        link = obj.name.removeprefix("sketch_").rsplit("_", 1)[0]
        np.testing.assert_allclose(obj.meshColor[:3], colours[obj.parentJoint], atol=rounding(1.0))
        if link in urdf:
            np.testing.assert_allclose(obj.meshColor[:3], urdf[link], atol=rounding(1.0))


def test_the_arrows_along_ds_path_point_the_way_d_moves_at_minus_50_rpm(figures, tmp_path):
    """The R-RTR's crank turns clockwise at -50 rpm: each arrowhead on D's path points along
    the closed form's v_D there (a positive dot product; the arrows used to show the sense
    of a growing crank angle, the opposite)."""
    assert main(["sweep", str(SCENES / "r_rtr.toml"), "--steps", "73", "--paths", str(tmp_path / "p.png")]) == 0
    ax = figures[0].axes[0]
    arrows = [a for a in ax.texts if getattr(a, "arrow_patch", None) is not None]
    assert len(arrows) >= 3
    theta = np.radians(np.linspace(0, 360, 3601))
    closed = cf.r_rtr(theta, -50 * math.pi / 30, 0.0)
    for arrow in arrows:
        head, tail = np.array(arrow.xy), np.array(arrow.xyann)
        i = int(np.argmin(np.linalg.norm(1000 * closed.D - head, axis=1)))
        assert float((head - tail) @ closed.vD[i]) > 0
    assert "-50 rpm" in ax.get_title()


FOLD_SCENE = """title = "four-bar driven at its rocker"
urdf = "{urdf}"
[drivers.O4]
angle = "100 deg"
speed = "60 rpm"
[guess]
O2 = "60 deg"
A = "-30 deg"
[sweep]
points = ["P"]
"""


def test_a_sweep_through_folds_marks_them_clips_their_spikes_and_styles_each_assembly(figures, tmp_path):
    """The four-bar (ground g = 100, crank a = 40, coupler b = 120, rocker c = 80 mm) driven
    at its rocker folds where crank and coupler line up, |O2 B| = b + a or b - a:
    cos ψ = (d² - g² - c²) / (2 g c), ψ = 54.90° and 128.68°. The fold lines are drawn there
    (within one 0.5° step of the sweep); the angular acceleration, which spikes to ~1e6 rad/s²
    at the folds, is clipped with its peak said; each assembly has its own line style."""
    scene = tmp_path / "fold.toml"
    scene.write_text(FOLD_SCENE.format(urdf=MODELS / "four_bar.urdf"))
    assert main(["sweep", str(scene), "--through-folds", "--steps", "721", "--plot", str(tmp_path / "f.png")]) == 0
    fig = figures[0]
    g, a, b, c = 0.10, 0.04, 0.12, 0.08
    limits = sorted(math.degrees(math.acos((d * d - g * g - c * c) / (2 * g * c))) for d in (b + a, b - a))
    np.testing.assert_allclose(limits, [54.9003678, 128.6821875], atol=1e-6)  # as the engine names them
    alpha = next(ax for ax in fig.axes if ax.get_title().startswith("angular acceleration"))
    folds = {round(x.get_xdata()[0], 6) for x in alpha.get_lines() if x.get_gid() == "marker" and
             len(set(x.get_xdata())) == 1}
    assert folds and all(min(abs(f - lim) for lim in limits) <= 0.5 for f in folds)
    peak = float(re.search(r"reaches ([0-9.e+]+)", alpha.get_title()).group(1))
    low, high = alpha.get_ylim()
    assert peak > 10 * max(abs(low), abs(high))  # clipped: the spike does not set the scale
    styles = {x.get_linestyle() for x in alpha.get_lines() if str(x.get_label()).startswith("coupler, assembly")}
    assert styles == {"-", "--"}


def test_the_snapshot_names_every_joint_and_point_where_the_four_bar_puts_them():
    """The four-bar at O2 = 60 deg (crank a = 40, coupler b = 120, rocker c = 80, ground
    g = 100 mm): O2 at the origin, O4 at (g, 0), A = a (cos 60°, sin 60°), and B where
    |AB| = b and |O4 B| = c (the loop's own equations). Each place named once, by the
    textbook's letter (A, not A_pin). Tolerance 1e-12 m: loops closed to 1e-13 of 0.1 m."""
    from pinmech.io.analysis import analyse
    from pinmech.model.display import labelled_places
    from pinmech.io.scene import Scene

    analysis = analyse(Scene.load(SCENES / "four_bar.toml"))
    places = labelled_places(analysis.mechanism, analysis.solution.q)
    assert set(places) == {"O2", "A", "B", "O4", "P"}
    np.testing.assert_allclose(places["O2"], [0.0, 0.0, 0.0], atol=rounding(0.2))
    np.testing.assert_allclose(places["O4"], [0.1, 0.0, 0.0], atol=rounding(0.2))
    np.testing.assert_allclose(places["A"], [0.04 * math.cos(math.pi / 3), 0.04 * math.sin(math.pi / 3), 0.0],
                               atol=rounding(0.2))
    assert np.linalg.norm(places["B"] - places["A"]) == pytest.approx(0.12, abs=rounding(0.2))
    assert np.linalg.norm(places["B"] - places["O4"]) == pytest.approx(0.08, abs=rounding(0.2))
