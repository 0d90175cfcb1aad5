"""Velocity and acceleration polygons, read back from the SVG drawing as a teacher would
measure it: each vector's ends on paper [mm] times the scale written on the drawing, against
the R-RTR's closed form (scripts/closed_form.py, derived apart from Pinocchio) and against
pinmech's own numbers for the four-bar and the slider-crank.

Tolerance: the SVG writes coordinates to 1e-4 mm, so a vector read back is off by at most
2e-4 mm on paper per axis; 1e-3 mm (a micrometre) times the scale covers it and is still a
millionth of a 150 mm drawing.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import closed_form as cf
import numpy as np
import pytest

from pinmech import Scene, analyse
from pinmech.cli import main
from pinmech.draw import DrawError
from pinmech.draw.polygon_svg import PAPER, polygon_svg
from pinmech.polygon import acceleration_polygon, velocity_polygon
from tests.conftest import SCENES

SVG = "{http://www.w3.org/2000/svg}"
READ_MM = 1e-3  # read-back tolerance on paper [mm] (see the module's docstring)


def read_svg(text: str) -> tuple[float, dict[str, np.ndarray], list[str], ET.Element]:
    """(scale per mm as written, label -> vector read back, the point labels, the root)."""
    root = ET.fromstring(text)
    scale = next(t.text for t in root.iter(f"{SVG}text") if t.get("id") == "scale")
    per_mm = float(re.fullmatch(r"scale: 1 mm = ([0-9.e+-]+) \S+", scale).group(1))
    vectors = {}
    for line in root.iter(f"{SVG}line"):
        if line.get("class") == "vector":
            x1, y1, x2, y2 = (float(line.get(k)) for k in ("x1", "y1", "x2", "y2"))
            vectors[line.get("data-label")] = per_mm * np.array([x2 - x1, y1 - y2])  # paper y points down
    labels = [t.text for t in root.iter(f"{SVG}text") if t.get("class") == "label"]
    return per_mm, vectors, labels, root


def r_rtr(overrides=()):
    return analyse(Scene.load(SCENES / "r_rtr.toml", list(overrides)))


CASES = [((), 30.0, -50.0 * math.pi / 30.0, 0.0),
         (('drivers.A.angle="110 deg"', 'drivers.A.acceleration="20 rad/s^2"'), 110.0, -50.0 * math.pi / 30.0, 20.0),
         (('report.links=["link1"]',), 30.0, -50.0 * math.pi / 30.0, 0.0)]  # link 3's rates not reported


@pytest.mark.parametrize(("overrides", "theta", "omega", "alpha"), CASES)
def test_r_rtr_velocity_polygon_measures_the_closed_form(overrides, theta, omega, alpha):
    """o->b is v_B, o->d is v_D, o->b3 is v_B3 = w3 x CB, b3->d is v_DB3 = w3 x B3D, and b3->b
    is the sliding velocity v_B - v_B3 (minus the closed form's v_rel, B3's on the block)."""
    ref = cf.r_rtr(math.radians(theta), omega, alpha)
    per_mm, v, labels, _ = read_svg(polygon_svg(velocity_polygon(r_rtr(overrides))))
    atol = READ_MM * per_mm
    np.testing.assert_allclose(v["v_B"], ref.vB, atol=atol)
    np.testing.assert_allclose(v["v_D"], ref.vD, atol=atol)
    np.testing.assert_allclose(v["v_B3"], ref.vB3, atol=atol)
    B3D = ref.D - ref.B
    np.testing.assert_allclose(v["v_DB3"], ref.omega3 * np.array([-B3D[1], B3D[0]]), atol=atol)
    np.testing.assert_allclose(v["v_BB3"], -ref.v_rel, atol=atol)
    assert "o, a, c" in labels  # the fixed pivots' images at the pole share its label


@pytest.mark.parametrize(("overrides", "theta", "omega", "alpha"), CASES)
def test_r_rtr_acceleration_polygon_measures_the_closed_form(overrides, theta, omega, alpha):
    """o'->d' is a_D; B3 about C, D about B3: normal parts w3^2 r towards the base point,
    tangential parts alpha3 k x r; B about B3: the Coriolis part 2 w3 k x (v_B - v_B3), then
    the sliding acceleration along the guide (minus the closed form's, B3's on the block)."""
    ref = cf.r_rtr(math.radians(theta), omega, alpha)
    per_mm, a, _, _ = read_svg(polygon_svg(acceleration_polygon(r_rtr(overrides))))
    atol = READ_MM * per_mm
    CD = ref.D - np.array([0.05, 0.0])
    np.testing.assert_allclose(a["a_D"], ref.aD, atol=atol)
    np.testing.assert_allclose(a["a_B"], ref.aB, atol=atol)
    for name, r in (("B3C", ref.B - np.array([0.05, 0.0])), ("DB3", ref.D - ref.B)):
        np.testing.assert_allclose(a[f"a^n_{name}"], -ref.omega3**2 * r, atol=atol)
        np.testing.assert_allclose(a[f"a^t_{name}"], ref.alpha3 * np.array([-r[1], r[0]]), atol=atol)
    np.testing.assert_allclose(a["a^c_BB3"], -ref.coriolis, atol=atol)
    np.testing.assert_allclose(a["a^r_BB3"], -ref.a_rel, atol=atol)
    u = CD / np.linalg.norm(CD)
    assert abs(u[0] * a["a^r_BB3"][1] - u[1] * a["a^r_BB3"][0]) <= atol  # the sliding part runs along the guide


@pytest.mark.parametrize("scene", ["four_bar", "slider_crank", "r_rtr", "jansen_leg"])
@pytest.mark.parametrize("make", [velocity_polygon, acceleration_polygon])
def test_every_point_drawn_from_the_pole_as_pinmech_computes_it(scene, make):
    """Each o->p read back is pinmech's velocity (acceleration) of P; the chains of relative
    parts land on the images they should (rigid-body formulas against Pinocchio's points)."""
    analysis = analyse(Scene.load(SCENES / f"{scene}.toml"))
    polygon = make(analysis)
    per_mm, vectors, _, _ = read_svg(polygon_svg(polygon))
    letter = polygon.quantity[0]
    for name, p in analysis.motion.points.items():
        value = polygon.axes @ (p.velocity if letter == "v" else p.acceleration)
        if np.linalg.norm(value) > 0:
            np.testing.assert_allclose(vectors[f"{letter}_{name}"], value, atol=READ_MM * per_mm)
    largest = max(np.linalg.norm(x) for x in polygon.images.values())
    assert polygon.closure_error <= 1e-12 * largest
    assert any(v.kind != "absolute" for v in polygon.vectors)  # relative motion is drawn too


def test_four_bar_relative_velocity_is_perpendicular_to_the_coupler():
    """v_BA = w3 x AB: perpendicular to AB, of length |w3| |AB| (pinmech's w3)."""
    analysis = analyse(Scene.load(SCENES / "four_bar.toml"))
    per_mm, v, _, _ = read_svg(polygon_svg(velocity_polygon(analysis)))
    points = analysis.motion.points
    AB = (points["B_pin"].position - points["A_pin"].position)[:2]
    w3 = analysis.motion.links["coupler"].angular_velocity[2]
    relative = v["v_B_pinA_pin"]
    assert abs(relative @ AB) <= READ_MM * per_mm * np.linalg.norm(AB)
    assert np.linalg.norm(relative) == pytest.approx(abs(w3) * np.linalg.norm(AB), abs=READ_MM * per_mm)


@pytest.mark.parametrize("make", [velocity_polygon, acceleration_polygon])
def test_the_scale_is_round_and_the_drawing_fits_the_paper(make):
    """1, 2 or 5 times a power of ten per millimetre; the polygon spans 30 to 150 mm."""
    polygon = make(r_rtr())
    per_mm, _, _, root = read_svg(polygon_svg(polygon))
    mantissa = per_mm / 10 ** math.floor(math.log10(per_mm))
    assert min(abs(mantissa - m) for m in (1, 2, 5)) < 1e-9
    ends = np.array([[float(c.get("cx")), float(c.get("cy"))] for c in root.iter(f"{SVG}circle")])
    span = float(np.max(np.ptp(ends, axis=0)))
    assert PAPER / 5 - 1e-6 <= span <= PAPER + 1e-6


def test_a_spatial_mechanism_is_a_named_error():
    analysis = r_rtr()
    analysis.mechanism.plane_normal = None  # as a spatial mechanism reports it
    with pytest.raises(DrawError, match="planar"):
        velocity_polygon(analysis)


def test_cli_writes_the_svg_and_a_failed_write_leaves_nothing(tmp_path, capsys):
    out = tmp_path / "a.svg"
    assert main(["polygon", str(SCENES / "r_rtr.toml"), "-o", str(out), "--acceleration"]) == 0
    assert "Acceleration polygon" in out.read_text(encoding="utf-8")
    missing = tmp_path / "no_such_folder" / "v.svg"
    assert main(["polygon", str(SCENES / "r_rtr.toml"), "-o", str(missing)]) == 2
    assert not missing.exists()
    assert "no_such_folder" in capsys.readouterr().err


def test_a_polygon_of_fixed_points_only_is_a_named_error(capsys, tmp_path):
    """Only the fixed pivots reported: nothing moves, nothing to draw, one line and exit 9."""
    text = (SCENES / "r_rtr.toml").read_text(encoding="utf-8").replace("../", str(SCENES.parent) + "/")
    text = re.sub(r"\[points\.B3\][^\[]*", "", text).replace('"A", "B", "B3", "C", "D"', '"A", "C"')
    scene, out = tmp_path / "fixed.toml", tmp_path / "v.svg"
    scene.write_text(text, encoding="utf-8")
    assert main(["polygon", str(scene), "-o", str(out)]) == 9
    assert "nothing to draw" in capsys.readouterr().err and not out.exists()


def test_bad_recorder_options_are_named_errors():
    from pinmech.exceptions import PinmechError
    from pinmech.plot import SweepPlot
    from pinmech.plot_paths import PathRecorder
    from pinmech.sweep import Sweep

    sweep = Sweep.from_scene(Scene.load(SCENES / "r_rtr.toml"))
    with pytest.raises(PinmechError, match="angles must be one of continuous, wrapped"):
        SweepPlot(sweep, angles="degrees")
    with pytest.raises(PinmechError, match="path plane must be one of xy, yz, zx or 3d"):
        PathRecorder(sweep.mechanism, "xz")


def test_jansen_foot_velocity_and_acceleration_by_finite_differences():
    """The foot G of the Jansen leg: o->g is dG/dtheta w and o'->g' is d2G/dtheta2 w^2 (the
    crank at a constant 60 rpm), central differences of the closed form with h = 1e-4 rad:
    truncation ~h^2 |G'''| ~ 1e-8 m and rounding ~eps |G| / h^2 ~ 2e-8 m, far below the
    read-back tolerance (1 um on paper, 5e-5 m/s or more)."""
    from closed_form_jansen import jansen_leg

    analysis = analyse(Scene.load(SCENES / "jansen_leg.toml"))
    w, h, theta = 2 * math.pi, 1e-4, math.pi / 2
    G = [jansen_leg(theta + k * h)["G"] for k in (-1, 0, 1)]
    per_mm, v, _, _ = read_svg(polygon_svg(velocity_polygon(analysis)))
    np.testing.assert_allclose(v["v_G"], w * (G[2] - G[0]) / (2 * h), atol=READ_MM * per_mm)
    per_mm, a, _, _ = read_svg(polygon_svg(acceleration_polygon(analysis)))
    np.testing.assert_allclose(a["a_G"], w**2 * (G[2] - 2 * G[1] + G[0]) / h**2, atol=READ_MM * per_mm)


def test_the_svg_file_is_made_as_any_file_is(tmp_path):
    """Written whole then moved in place, with the permissions open() gives (not 0600)."""
    import os

    out = tmp_path / "v.svg"
    assert main(["polygon", str(SCENES / "r_rtr.toml"), "-o", str(out)]) == 0
    umask = os.umask(0)
    os.umask(umask)
    assert out.stat().st_mode & 0o777 == 0o666 & ~umask
    assert [p.name for p in tmp_path.iterdir()] == ["v.svg"]  # no temporary file left


def test_a_polygon_is_written_only_under_an_svg_name(tmp_path, capsys):
    """`-o p.png` wrote SVG text under a PNG name and said it was done."""
    out = tmp_path / "p.png"
    assert main(["polygon", str(SCENES / "r_rtr.toml"), "-o", str(out)]) == 2
    assert "name the file *.svg" in capsys.readouterr().err and not out.exists()
