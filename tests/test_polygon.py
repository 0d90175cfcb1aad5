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
from pinmech.model.display import display_names
from pinmech.draw import DrawError
from pinmech.draw.polygon_svg import PAPER, polygon_svg
from pinmech.draw.polygon import acceleration_polygon, velocity_polygon
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
    shown = display_names(analysis.mechanism)  # A_pin is drawn as the textbook's A
    for name, p in analysis.motion.points.items():
        value = polygon.axes @ (p.velocity if letter == "v" else p.acceleration)
        if np.linalg.norm(value) > 0:
            np.testing.assert_allclose(vectors[f"{letter}_{shown.get(name, name)}"], value, atol=READ_MM * per_mm)
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
    relative = v["v_BA"]
    assert abs(relative @ AB) <= READ_MM * per_mm * np.linalg.norm(AB)
    assert np.linalg.norm(relative) == pytest.approx(abs(w3) * np.linalg.norm(AB), abs=READ_MM * per_mm)


@pytest.mark.parametrize("make", [velocity_polygon, acceleration_polygon])
def test_the_scale_is_round_and_the_drawing_fits_the_paper(make):
    """1, 2 or 5 times a power of ten per millimetre; the polygon spans 30 to 150 mm."""
    polygon = make(r_rtr())
    per_mm, _, _, root = read_svg(polygon_svg(polygon))
    mantissa = per_mm / 10 ** math.floor(math.log10(per_mm))
    assert min(abs(mantissa - m) for m in (1, 2, 5)) < 1e-9
    ends = np.array([[float(c.get("cx")), float(c.get("cy"))] for c in root.iter(f"{SVG}circle")
                     if c.get("class") == "image"])
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


def test_a_polygon_of_fixed_points_only_draws_the_pins(tmp_path):
    """Only the fixed pivots reported: the polygon draws the moving pin B anyway (every pin,
    as the graphical method does), with o->b = v_B of the R-RTR's closed form."""
    import closed_form as cf

    text = (SCENES / "r_rtr.toml").read_text(encoding="utf-8").replace("../", str(SCENES.parent) + "/")
    text = re.sub(r"\[points\.B3\][^\[]*", "", text).replace('"A", "B", "B3", "C", "D"', '"A", "C"')
    scene = tmp_path / "fixed.toml"
    scene.write_text(text, encoding="utf-8")
    polygon = velocity_polygon(analyse(Scene.load(scene)))
    v_B = cf.r_rtr(math.radians(30.0), -50.0 * math.pi / 30.0, 0.0).vB
    from tests.tolerance import REGULAR, closure

    # a pose closed to the solver's tolerance at a regular pose (tests/tolerance.py)
    assert np.linalg.norm(polygon.images["b"] - v_B) <= closure(np.linalg.norm(v_B), REGULAR, 1)


def test_a_polygon_of_a_mechanism_at_rest_is_a_named_error(capsys, tmp_path):
    """The driver at rest: nothing moves, nothing to draw, one line and exit 9."""
    text = (SCENES / "r_rtr.toml").read_text(encoding="utf-8").replace("../", str(SCENES.parent) + "/")
    scene, out = tmp_path / "rest.toml", tmp_path / "v.svg"
    scene.write_text(text.replace('speed = "-50 rpm"', 'speed = "0 rpm"'), encoding="utf-8")
    assert main(["polygon", str(scene), "-o", str(out)]) == 9
    assert "nothing to draw" in capsys.readouterr().err and not out.exists()


def test_bad_recorder_options_are_named_errors():
    from pinmech.exceptions import PinmechError
    from pinmech.draw.plot import SweepPlot
    from pinmech.draw.plot_paths import PathRecorder
    from pinmech.io.sweep import Sweep

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


# ----------------------------------------------------------------- the figure a lecturer prints

def _drawn_four_bar(tmp_path, d, a, b, c, theta):
    """A drawn four-bar O2 (0, 0), O4 (d, 0), crank a, coupler b, rocker c [mm], B left of
    A -> O4 (the closed form's branch +1), the crank at theta [deg] turning at 60 rpm."""
    (tmp_path / "fb.toml").write_text(f"""title = "four-bar"
ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"]
O4 = ["{d} mm", "0 mm"]
A = {{ from = "O2", length = "{a} mm", angle = "{theta} deg" }}
B = {{ from = ["A", "O4"], lengths = ["{b} mm", "{c} mm"], side = "left" }}
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
""", encoding="utf-8")
    scene = tmp_path / "scene.toml"
    scene.write_text(f'title = "four-bar"\nlinkage = "fb.toml"\n[drivers.O2]\nangle = "{theta} deg"\n'
                     'speed = "60 rpm"\n[report]\npoints = ["A", "B"]\n', encoding="utf-8")
    return analyse(Scene.load(scene))


def _lines(root: ET.Element) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Vector label -> its drawn ends on paper [mm], y up."""
    out = {}
    for line in root.iter(f"{SVG}line"):
        if line.get("class") == "vector":
            x1, y1, x2, y2 = (float(line.get(k)) for k in ("x1", "y1", "x2", "y2"))
            out[line.get("data-label")] = (np.array([x1, -y1]), np.array([x2, -y2]))
    return out


# (d, a, b, c) [mm] and crank angles [deg]: one four-bar of each Grashof class that turns or
# rocks through these poses (Norton §2.12), B left of A -> O4.
FOUR_BARS = [((100, 40, 120, 80), (40, 130, 250)),  # crank-rocker: the crank shortest
             ((40, 90, 110, 100), (0, 130)),  # double-crank: the ground shortest
             ((100, 80, 40, 90), (55, 70)),  # double-rocker: the coupler shortest
             ((100, 45, 50, 55), (-8, 9))]  # non-Grashof triple rocker


@pytest.mark.parametrize(("lengths", "angles"), FOUR_BARS, ids=["crank-rocker", "double-crank", "double-rocker",
                                                                 "triple-rocker"])
def test_four_bar_acceleration_polygon_reaches_b_by_both_routes(tmp_path, lengths, angles):
    """The graphical method: b' = a' + a^n_BA + a^t_BA = o' + a^n_BO4 + a^t_BO4. Each part is
    measured off the SVG against Norton's closed form (scripts/closed_form.py): normal parts
    -w^2 r, tangential parts alpha k x r, with w3, alpha3 of the coupler, w4, alpha4 of the
    rocker; both chains end at the drawn b' within the drawing's precision (READ_MM)."""
    d, a, b, c = (x / 1000 for x in lengths)
    for theta in angles:
        ref = cf.four_bar(math.radians(theta), 2 * math.pi, 0.0, a, b, c, d)
        polygon = acceleration_polygon(_drawn_four_bar(tmp_path, *lengths, theta))
        per_mm, parts, _, root = read_svg(polygon_svg(polygon))
        atol = READ_MM * per_mm
        AB, O4B = ref.B - ref.A, ref.B - np.array([d, 0.0])
        np.testing.assert_allclose(parts["a_B"], ref.aB, atol=atol)
        for name, r, w, alpha in (("BA", AB, ref.omega3, ref.alpha3), ("BO4", O4B, ref.omega4, ref.alpha4)):
            np.testing.assert_allclose(parts[f"a^n_{name}"], -(w**2) * r, atol=atol)
            np.testing.assert_allclose(parts[f"a^t_{name}"], alpha * np.array([-r[1], r[0]]), atol=atol)
        lines = _lines(root)
        b_image = next(np.array([float(e.get("cx")), -float(e.get("cy"))]) for e in root.iter(f"{SVG}circle")
                       if e.get("class") == "image" and e.get("data-label") == "b'")
        for route in ("a^t_BA", "a^t_BO4"):  # each chain ends at the image b' (5e-4 mm: the printed digits)
            np.testing.assert_allclose(lines[route][1], b_image, atol=5e-4)


def _segments_lie_along(s1, s2, within: float = 0.5, shared: float = 0.5) -> bool:
    """Two segments on paper [mm] lie along each other (one would hide the other): both ends
    of the second within `within` mm of the first's line, sharing more than `shared` mm."""
    (a, b), (c, d) = s1, s2
    u = (b - a) / np.linalg.norm(b - a)
    off = [abs(u[0] * (p - a)[1] - u[1] * (p - a)[0]) for p in (c, d)]
    lo, hi = sorted([(c - a) @ u, (d - a) @ u])
    return max(off) < within and min(np.linalg.norm(b - a), hi) - max(0.0, lo) > shared


@pytest.mark.parametrize("scene", ["r_rtr", "four_bar", "slider_crank", "crank_shaper", "jansen_leg"])
@pytest.mark.parametrize("make", [velocity_polygon, acceleration_polygon])
def test_no_vector_hides_another(scene, make):
    """In the R-RTR, C, B3 and D lie on one line through the fixed pivot: v_D runs along
    o-b3-d, and the Coriolis part (perpendicular to the guide) along the tangential part
    a^t_B3C (perpendicular to CB). Each is drawn beside the other, no two lines along one
    another (0.5 mm: a line's width and arrowhead), and still measures its value."""
    analysis = analyse(Scene.load(SCENES / f"{scene}.toml"))
    _, _, _, root = read_svg(polygon_svg(make(analysis)))
    lines = list(_lines(root).items())
    for i, (n1, s1) in enumerate(lines):
        for n2, s2 in lines[i + 1:]:
            assert not _segments_lie_along(s1, s2), f"{n1} and {n2} drawn along one another"


@pytest.mark.parametrize(("overrides", "theta", "omega", "alpha"), CASES[:2])
def test_each_vector_is_named_with_its_magnitude_beside_it(overrides, theta, omega, alpha):
    """The R-RTR's vectors written on the drawing as 'v_D = 1.160 m/s': the number is the
    closed form's magnitude at the 4 significant digits printed (rtol 5e-4 and a hair)."""
    ref = cf.r_rtr(math.radians(theta), omega, alpha)
    expected = {"velocity": {"v_B": ref.vB, "v_D": ref.vD, "v_B3": ref.vB3, "v_BB3": ref.v_rel},
                "acceleration": {"a_B": ref.aB, "a_D": ref.aD, "a^c_BB3": ref.coriolis, "a^r_BB3": ref.a_rel}}
    analysis = r_rtr(overrides)
    for make in (velocity_polygon, acceleration_polygon):
        polygon = make(analysis)
        root = ET.fromstring(polygon_svg(polygon, analysis))
        written = {t.get("data-label"): "".join(t.itertext()) for t in root.iter(f"{SVG}text")
                   if t.get("class") == "magnitude"}
        assert set(written) == {v.label for v in polygon.vectors}  # every vector drawn is named
        for label, vector in expected[polygon.quantity].items():
            number = re.search(r"= ([0-9.e+-]+) m/s", written[label]).group(1)
            assert float(number) == pytest.approx(np.linalg.norm(vector), rel=5.01e-4), label


def test_the_coupler_image_is_the_coupler_turned_and_scaled():
    """The velocity image a-b-p of the four-bar's coupler is closed, shaded in the coupler's
    colour, and similar to the coupler A-B-P with ratio |w3| (Norton's closed form): each
    side drawn [mm] times the scale is |w3| times the side of the link [m]; the acceleration
    image a'-b'-p' with ratio sqrt(w3^4 + alpha3^2). Tolerance 1e-3 mm on paper (READ_MM)."""
    from pinmech.model.display import colour_of, hex_colour

    analysis = analyse(Scene.load(SCENES / "four_bar.toml"))
    ref = cf.four_bar(math.radians(60.0), 4 * math.pi, 0.0, 0.04, 0.12, 0.08, 0.10)
    P = ref.A + 0.06 * np.array([math.cos(ref.theta3), math.sin(ref.theta3)]) + 0.03 * np.array(
        [-math.sin(ref.theta3), math.cos(ref.theta3)])  # P at (60, 30) mm in the coupler's frame
    sides = sorted(np.linalg.norm(x - y) for x, y in ((ref.A, ref.B), (ref.B, P), (P, ref.A)))
    for make, ratio in ((velocity_polygon, abs(ref.omega3)), (acceleration_polygon, math.hypot(ref.omega3**2,
                                                                                                 ref.alpha3))):
        per_mm, _, _, root = read_svg(polygon_svg(make(analysis), analysis))
        (image,) = [e for e in root.iter(f"{SVG}polygon") if e.get("class") == "image-figure"
                    and e.get("data-link") == "coupler"]
        corners = np.array([[float(c) for c in xy.split(",")] for xy in image.get("points").split()])
        drawn = sorted(np.linalg.norm(corners[i] - corners[i - 1]) * per_mm for i in range(3))
        np.testing.assert_allclose(drawn, ratio * np.array(sides), atol=2 * READ_MM * per_mm)
        assert image.get("fill") == hex_colour(colour_of(analysis.mechanism, "coupler"))


def test_the_space_diagram_is_drawn_to_its_scale_beside_the_polygon():
    """The four-bar's links drawn to the scale written under them: crank 40 mm, coupler
    120 mm (A to B, P off the line: a plate), rocker 80 mm (the URDF's lengths); pins at
    A, B and the ground pivots O2, O4 100 mm apart. Tolerance 1e-3 mm on paper."""
    analysis = analyse(Scene.load(SCENES / "four_bar.toml"))
    root = ET.fromstring(polygon_svg(velocity_polygon(analysis), analysis))
    (space,) = [g for g in root.iter(f"{SVG}g") if g.get("class") == "space-diagram"]
    per_mm = float(space.get("data-per-mm"))
    bars = {e.get("data-link"): e for e in space.iter(f"{SVG}line") if e.get("class") == "link"}
    for link, length in (("crank", 0.04), ("rocker", 0.08)):
        e = bars[link]
        drawn = math.dist((float(e.get("x1")), float(e.get("y1"))), (float(e.get("x2")), float(e.get("y2"))))
        assert drawn * per_mm == pytest.approx(length, abs=1e-3 * per_mm)
    plate = [e for e in space.iter(f"{SVG}polygon") if e.get("data-link") == "coupler"]
    assert len(plate) == 1 and len(plate[0].get("points").split()) == 3
    grounds = [e for e in space.iter(f"{SVG}path") if e.get("class") == "ground"]
    assert len(grounds) == 2
    names = {t.text for t in space.iter(f"{SVG}text") if t.get("class") == "place"}
    assert {"O2", "O4", "A", "B", "P"} <= names


def test_a_polygon_draws_every_pin_the_scene_does_not_report():
    """The drawn four-bar's scene reports only the coupler point P; its polygons still draw
    the pins A and B, as the graphical method does: o->a is v_A and o->b is v_B (o'->a',
    o'->b' the accelerations) of Norton's closed form (scripts/closed_form.py), crank 40,
    coupler 120, rocker 80, ground 100 mm, crank at 60 deg turning at 120 rpm, B above O2-O4.
    Before, the polygon had only o, p and the fixed pivots. Tolerance: a pose closed to the
    solver's tolerance at a regular pose (tests/tolerance.py)."""
    from tests.tolerance import REGULAR, closure

    analysis = analyse(Scene.load(SCENES / "four_bar_drawn.toml"))
    assert list(analysis.motion.points) == ["P"]
    fb = next(f for f in (cf.four_bar(math.radians(60.0), 4 * math.pi, 0.0, 0.04, 0.12, 0.08, 0.10, branch)
                          for branch in (1, -1)) if f.B[1] > 0)
    for polygon, a, b, order in ((velocity_polygon(analysis), fb.vA, fb.vB, 1),
                                 (acceleration_polygon(analysis), fb.aA, fb.aB, 2)):
        prime = "'" if order == 2 else ""
        assert {"a" + prime, "b" + prime} <= set(polygon.images)
        for label, expected in (("a" + prime, a), ("b" + prime, b)):
            np.testing.assert_allclose(polygon.images[label], expected, rtol=0,
                                       atol=closure(np.linalg.norm(expected), REGULAR, order))
        drawn = {v.label for v in polygon.vectors if v.kind == "absolute"}
        assert {f"{polygon.quantity[0]}_A", f"{polygon.quantity[0]}_B"} <= drawn
