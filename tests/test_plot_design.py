"""The design diagnostics in the sweep figures, read back from matplotlib's own objects
against closed forms derived apart from Pinocchio (Norton, Design of Machinery, §4.10):
the least transmission angle marked where the law of cosines puts it, the limit positions
drawn as vertical lines where the rocker's extremes (crank and coupler in line) and the
slider's dead centres are, ghost outlines of the mechanism there in the paths figure,
timing marks at the closed-form coupler points, and one length unit per figure.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from closed_form import four_bar

from pinmech.cli import main
from tests.conftest import SCENES
from tests.test_design import _four_bar_files

pytest.importorskip("matplotlib", reason='plots need pip install "pinmech[plot]"')

DEG = math.pi / 180
#: Driver values of the marks: the least angle is refined by golden section to 1e-10 rad,
#: limit positions bisected to 1e-12 rad (limit_positions.BISECTION_TOL); where the
#: angle is least it is flat, so its place is known only to sqrt(closure tol ~ 1e-13)
#: ~ 3e-7 rad: 1e-4 deg (2e-6 rad) is a margin of 5 on that, 1e-5 deg on the limits.
LEAST_AT_TOL_DEG = 1e-4
LIMIT_TOL_DEG = 1e-5
#: Angles of solved poses against the closed form: exact to the closure's rounding.
ANGLE_TOL_DEG = 1e-8
#: Places drawn [mm]: loops closed to 1e-13 of a 0.1 m mechanism: 1e-6 mm leaves 1e5.
PLACE_TOL_MM = 1e-6



def _panel(fig, start: str):
    return next(ax for ax in fig.axes if start in ax.get_title())


def _four_bar_mu(theta_deg: np.ndarray, a, b, c, d) -> np.ndarray:
    """Norton §4.10: cos mu = (b² + c² - a² - d² + 2 a d cos theta) / (2 b c), mu on [0, 180] deg."""
    cos_mu = (b**2 + c**2 - a**2 - d**2 + 2 * a * d * np.cos(np.radians(theta_deg))) / (2 * b * c)
    return np.degrees(np.arccos(cos_mu))


# (d, a, b, c) [mm] and the crank angle where mu is farthest from 90 deg: the diagonal O4 A
# is shortest (theta 0) or longest (theta 180), and mu is farthest from 90 deg at one of them.
FOUR_BARS = [((100, 40, 120, 80), "crank-rocker"), ((40, 90, 110, 100), "double-crank")]


@pytest.mark.parametrize("lengths, label", FOUR_BARS, ids=[f[1] for f in FOUR_BARS])
def test_least_transmission_angle_is_marked_where_the_law_of_cosines_puts_it(figures, tmp_path, lengths, label):
    d, a, b, c = lengths
    scene = _four_bar_files(tmp_path, d, a, b, c)
    # 50 poses from 5 deg: the least (at 0 or 180 deg) is on no pose, it is found between them
    assert main(["sweep", str(scene), "--steps", "50", "--from", "5 deg", "--to", "365 deg", "--plot", str(tmp_path / "f.png"), "--csv",
                 str(tmp_path / "f.csv")]) == 0
    ax = _panel(figures[0], "transmission angle")
    (curve,) = [line for line in ax.get_lines() if line.get_label().startswith("B") and line.get_gid() is None]
    x, y = (np.asarray(v, dtype=float) for v in curve.get_data())
    np.testing.assert_allclose(y, _four_bar_mu(x, a, b, c, d), rtol=0, atol=ANGLE_TOL_DEG)
    (least,) = [line for line in ax.get_lines() if line.get_gid() == "least transmission angle"]
    (at,), (mu,) = least.get_data()
    extremes = np.array([0.0, 180.0])
    where = extremes[np.argmax(abs(90.0 - _four_bar_mu(extremes, a, b, c, d)))]
    assert abs((at - where + 180) % 360 - 180) < LEAST_AT_TOL_DEG
    np.testing.assert_allclose(mu, _four_bar_mu(np.array([where]), a, b, c, d)[0], rtol=0, atol=ANGLE_TOL_DEG)
    assert any(f"μ = {mu:.1f}°" in t.get_text() for t in ax.get_legend().get_texts())


def test_least_transmission_angle_of_the_offset_slider_crank(figures, tmp_path):
    """mu = 90 deg - asin(|r sin theta - e| / l): least where r sin theta - e is most
    negative, theta = 270 deg (r 50, l 150, e 10 mm)."""
    assert main(["sweep", str(SCENES / "slider_crank.toml"), "--steps", "40", "--plot", str(tmp_path / "f.png")]) == 0
    ax = _panel(figures[0], "transmission angle")
    (least,) = [line for line in ax.get_lines() if line.get_gid() == "least transmission angle"]
    (at,), (mu,) = least.get_data()
    assert abs((at - 270.0 + 180) % 360 - 180) < LEAST_AT_TOL_DEG
    np.testing.assert_allclose(mu, 90 - math.degrees(math.asin(0.06 / 0.15)), rtol=0, atol=ANGLE_TOL_DEG)


def _rocker_extremes(a=0.04, b=0.12, c=0.08, d=0.10):
    """Crank angles [deg] and B [m] where crank and coupler are in line: |O2 B| = b + a
    (extended) and b - a (folded), B above the ground line (the drawn assembly)."""
    out = []
    for reach, flip in ((b + a, 0.0), (b - a, math.pi)):
        x = (reach**2 - c**2 + d**2) / (2 * d)
        B = np.array([x, math.sqrt(reach**2 - x**2)])
        out.append((math.degrees((math.atan2(B[1], B[0]) + flip) % (2 * math.pi)), B))
    return out


def _markers(ax) -> list[float]:
    return sorted(float(line.get_xdata()[0]) for line in ax.get_lines() if line.get_gid() == "marker")


def test_limit_positions_are_vertical_lines_in_every_panel(figures, tmp_path):
    assert main(["sweep", str(SCENES / "four_bar.toml"), "--steps", "37", "--plot", str(tmp_path / "f.png")]) == 0
    expected = sorted(theta for theta, _ in _rocker_extremes())
    panels = [ax for ax in figures[0].axes if ax.get_lines() and "paths" not in ax.get_title()]
    assert len(panels) >= 4
    for ax in panels:
        np.testing.assert_allclose(_markers(ax), expected, rtol=0, atol=LIMIT_TOL_DEG)


def test_dead_centres_are_vertical_lines(figures, tmp_path):
    """TDC: crank and rod extended, |OB| = l + r on y = e: theta = atan2(e, x_TDC); BDC
    folded: theta = atan2(-e, -x_BDC) (r 50, l 150, e 10 mm)."""
    r, l, e = 0.05, 0.15, 0.01
    x_tdc, x_bdc = math.sqrt((l + r) ** 2 - e**2), math.sqrt((l - r) ** 2 - e**2)
    expected = sorted(math.degrees(t) % 360 for t in (math.atan2(e, x_tdc), math.atan2(-e, -x_bdc)))
    assert main(["sweep", str(SCENES / "slider_crank.toml"), "--steps", "37", "--plot", str(tmp_path / "f.png")]) == 0
    ax = _panel(figures[0], "angle")
    np.testing.assert_allclose(_markers(ax), expected, rtol=0, atol=LIMIT_TOL_DEG)
    labels = " ".join(t.get_text() for t in ax.texts)
    assert "TDC" in labels and "BDC" in labels


def test_ghost_outlines_at_the_rocker_extremes(figures, tmp_path):
    """The paths figure outlines the mechanism at each limit position: the rocker's end B
    is where the circles (O2, b +- a) and (O4, c) meet."""
    assert main(["sweep", str(SCENES / "four_bar.toml"), "--steps", "37", "--paths", str(tmp_path / "p.png")]) == 0
    ax = figures[0].axes[0]
    ghosts = [line for line in ax.get_lines() if line.get_gid() == "ghost"]
    assert ghosts
    drawn = np.vstack([np.column_stack(line.get_data()) for line in ghosts])
    for _, B in _rocker_extremes():
        nearest = np.min(np.linalg.norm(drawn - 1000 * B, axis=1))
        assert nearest < PLACE_TOL_MM, nearest


def _coupler_point(theta_deg: np.ndarray) -> np.ndarray:
    """P of models/linkages/four_bar.toml [mm]: drawn at (100, 30) mm with the crank at 0,
    carried by the coupler (closed form A, theta3 of the open assembly)."""
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    drawn = four_bar(0.0, 0.0, 0.0, a, b, c, d)
    rel = np.array([0.100, 0.030]) - drawn.A
    t3 = drawn.theta3
    local = np.array([math.cos(t3) * rel[0] + math.sin(t3) * rel[1], -math.sin(t3) * rel[0] + math.cos(t3) * rel[1]])
    fb = four_bar(np.radians(theta_deg), 0.0, 0.0, a, b, c, d)
    ct, st = np.cos(fb.theta3), np.sin(fb.theta3)
    return 1000 * np.column_stack([fb.A[:, 0] + ct * local[0] - st * local[1], fb.A[:, 1] + st * local[0] + ct * local[1]])


def test_timing_marks_sit_at_the_closed_form_coupler_points(figures, tmp_path):
    """--timing-marks: a mark every 30 deg of the crank on P's coupler curve, at the closed
    form's P there, though no pose of the 50 falls on those angles."""
    assert main(["sweep", str(SCENES / "four_bar_drawn.toml"), "--steps", "50", "--points", "P",
                 "--paths", str(tmp_path / "p.png"), "--timing-marks"]) == 0
    ax = figures[0].axes[0]
    (marks,) = [line for line in ax.get_lines() if line.get_gid() == "timing P"]
    drawn = np.column_stack(marks.get_data())
    labels = [t.get_text() for t in ax.texts if t.get_gid() == "timing P"]
    angles = sorted(float(a.rstrip("°")) for t in labels for a in t.split(", "))
    assert angles == list(range(0, 360, 30))  # the marks are drawn in this order
    np.testing.assert_allclose(drawn, _coupler_point(np.array(angles)), rtol=0, atol=PLACE_TOL_MM)


def test_timing_marks_need_a_paths_figure(tmp_path, capsys):
    assert main(["sweep", str(SCENES / "four_bar.toml"), "--steps", "5", "--timing-marks"]) == 2
    assert "--timing-marks" in capsys.readouterr().err


def test_one_length_unit_in_a_figure(figures, tmp_path):
    """The R-RTR (150 mm): the paths are in mm, so are the slider's place and the speeds; the
    accelerations, the slider's and D's alike, are in m/s^2 (|a_D| reaches 10.38 m/s^2:
    10,380 mm/s^2 would be five digits); the slider's place is the closed form's in mm (s = -|CB|, as tests/test_figures.py)."""
    import closed_form as cf

    assert main(["sweep", str(SCENES / "r_rtr.toml"), "--steps", "13", "--plot", str(tmp_path / "f.png")]) == 0
    fig = figures[0]
    texts = " ".join([ax.get_title() + ax.get_ylabel() + ax.get_xlabel() for ax in fig.axes])
    assert "[mm]" in texts and "[mm/s]" in texts and "[m/s²]" in texts
    assert not re.search(r"\[m(/s)?\]|\[mm/s²\]", texts), texts
    ax = _panel(fig, "position along its guide")
    (line,) = [x for x in ax.get_lines() if x.get_label().startswith("B")]
    x, s = (np.asarray(v, dtype=float) for v in line.get_data())
    np.testing.assert_allclose(s, -1000 * cf.r_rtr(np.radians(x), 1.0, 0.0).s, rtol=0, atol=PLACE_TOL_MM)


def test_quick_return_limit_lines_where_the_lever_is_tangent_to_the_crank_circle(figures, tmp_path):
    """Crank-shaper (crank r 50 mm, lever pivot d 100 mm below): the lever's extremes are
    where it is tangent to the crank's circle, the crank at -90 deg +- acos(r / d)."""
    r, d = 0.05, 0.10
    expected = sorted((-90 + s * math.degrees(math.acos(r / d))) % 360 for s in (-1, 1))
    assert main(["sweep", str(SCENES / "crank_shaper.toml"), "--steps", "37", "--plot", str(tmp_path / "f.png")]) == 0
    for ax in [ax for ax in figures[0].axes if ax.get_lines() and "paths" not in ax.get_title()]:
        np.testing.assert_allclose(_markers(ax), expected, rtol=0, atol=LIMIT_TOL_DEG)


def _circles(p, r, q, s, side: float) -> np.ndarray:
    """The meeting point of the circles (p, r) and (q, s), left (side +1) or right (-1) of p -> q."""
    w = q - p
    L = np.linalg.norm(w)
    x = (r**2 - s**2 + L**2) / (2 * L)
    u = w / L
    return p + x * u + side * math.sqrt(r**2 - x**2) * np.array([-u[1], u[0]])


def _watt_mu(theta_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Acute transmission angles [deg] at B (coupler-rocker) and D (link5-link6) of
    models/linkages/watt.toml: the first four-bar's law of cosines; C turns with the rocker
    (drawn at the crank's 0), and at D: cos mu = (CD² + O6D² - |C O6|²) / (2 CD O6D)."""
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    O4, O6 = np.array([0.1, 0.0]), np.array([0.19, 0.03])
    B0 = four_bar(0.0, 0.0, 0.0, a, b, c, d).B
    C0 = _circles(O4, 0.06, B0, 0.05, -1.0)
    delta = math.atan2(*(C0 - O4)[::-1]) - math.atan2(*(B0 - O4)[::-1])
    fb = four_bar(np.radians(theta_deg), 0.0, 0.0, a, b, c, d)
    C = O4 + 0.06 * np.column_stack([np.cos(fb.theta4 + delta), np.sin(fb.theta4 + delta)])
    cos_d = (0.09**2 + 0.07**2 - np.sum((C - O6) ** 2, axis=1)) / (2 * 0.09 * 0.07)
    mu_d = np.degrees(np.arccos(cos_d))
    return _four_bar_mu(theta_deg, a, b, c, d), np.minimum(mu_d, 180 - mu_d)


def test_watt_six_bar_transmission_angles_and_their_least(figures, tmp_path):
    """Both dyads of a Watt six-bar: the curves are the closed form's at every drawn pose,
    the least of each where a dense closed-form search puts it (1e6 crank angles, then
    1e4 more within a grid step: to 1e-7 deg)."""
    from pinmech.cli import main as run

    scene = tmp_path / "watt.toml"
    scene.write_text(f'title = "Watt six-bar"\nlinkage = "{SCENES.parent / "linkages" / "watt.toml"}"\n'
                     '[drivers.O2]\nangle = "0 deg"\nspeed = "60 rpm"\n')
    assert run(["sweep", str(scene), "--steps", "50", "--from", "5 deg", "--to", "365 deg",
                "--plot", str(tmp_path / "f.png")]) == 0
    ax = _panel(figures[0], "transmission angle")
    grid = np.linspace(0.0, 360.0, 1_000_000, endpoint=False)
    for k, pin_name in enumerate(("B", "D")):
        (curve,) = [x for x in ax.get_lines() if x.get_label().startswith(pin_name) and x.get_gid() is None]
        x, y = (np.asarray(v, dtype=float) for v in curve.get_data())
        np.testing.assert_allclose(y, _watt_mu(x)[k], rtol=0, atol=ANGLE_TOL_DEG)
        # every local least within 1e-6 deg of the least: D's is reached twice a turn (the
        # rocker passes C's farthest place from O6 going and coming back), and either is marked
        mu_at = _watt_mu(grid)[k]
        local = (mu_at <= np.roll(mu_at, 1)) & (mu_at <= np.roll(mu_at, -1))  # a turn: 0 follows 360
        coarse = grid[local & (mu_at - mu_at.min() < 1e-6)]
        places = []
        for c in coarse:
            fine = np.linspace(c - 4e-4, c + 4e-4, 10_001)
            places.append(fine[np.argmin(_watt_mu(fine)[k])])
        (least,) = [x for x in ax.get_lines() if x.get_gid() == "least transmission angle"
                    and x.get_label().startswith(pin_name)]
        (at,), (mu,) = least.get_data()
        assert np.min(np.abs((at - np.array(places) + 180) % 360 - 180)) < LEAST_AT_TOL_DEG, (pin_name, at, places)
        np.testing.assert_allclose(mu, mu_at.min(), rtol=0, atol=ANGLE_TOL_DEG)


def test_a_slot_cut_slider_is_drawn_along_its_slot(figures, tmp_path):
    """The crank-shaper's pin B slides in the lever's slot (a loop cut, no tree joint): its
    place along the slot is s = |CB| - 150 mm (drawn at B = (0, 50) mm, C = (0, -100) mm)
    and its sliding speed ds/dt = (CB / |CB|) . dB/dt, B = A + r (cos theta, sin theta),
    the crank at 60 rpm. (The figure refused this scene before: "unknown joint 'B_slide'".)"""
    r, d, omega = 0.05, 0.10, 2 * math.pi
    assert main(["sweep", str(SCENES / "crank_shaper.toml"), "--steps", "37", "--plot", str(tmp_path / "f.png")]) == 0
    (line,) = [x for x in _panel(figures[0], "position along its guide").get_lines() if x.get_label().startswith("B_slide")]
    theta, s = (np.asarray(v, dtype=float) for v in line.get_data())
    B = r * np.column_stack([np.cos(np.radians(theta)), np.sin(np.radians(theta))])
    CB = B - np.array([0.0, -d])
    np.testing.assert_allclose(s, 1000 * (np.linalg.norm(CB, axis=1) - 0.15), rtol=0, atol=PLACE_TOL_MM)
    (line,) = [x for x in _panel(figures[0], "velocity along its guide").get_lines() if x.get_label().startswith("B_slide")]
    dB = r * omega * np.column_stack([-np.sin(np.radians(theta)), np.cos(np.radians(theta))])
    v = np.sum(CB * dB, axis=1) / np.linalg.norm(CB, axis=1)
    # rates: closure rounding times the condition number, 1e-9 mm/s on 300 mm/s
    np.testing.assert_allclose(line.get_ydata(), 1000 * v, rtol=0, atol=1e-6)


@pytest.mark.parametrize("step, said", [("0 deg", "--timing-marks must be a positive angle"),
                                        ("10 mm", "--timing-marks")])
def test_timing_marks_take_a_positive_angle_for_a_crank(tmp_path, capsys, step, said):
    assert main(["sweep", str(SCENES / "four_bar.toml"), "--steps", "5", "--paths", str(tmp_path / "p.png"),
                 "--timing-marks", step]) in (2, 4)
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err and not (tmp_path / "p.png").exists()


@pytest.mark.parametrize("flag", ["--skip-failures", "--through-folds"])
def test_fold_outlines_of_a_triple_rocker_are_at_the_law_of_cosines_angle(figures, tmp_path, flag):
    """Triple rocker d = 100, a = 45, b = 50, c = 55 mm (Norton §2.12): the crank stops where
    coupler and rocker are in line, |O4 A| = b + c, cos theta = (a^2 + d^2 - (b + c)^2) /
    (2 a d) = 1/9, theta = 83.62 deg (and -83.62 deg through the folds). The paths figure
    outlines the mechanism there: the crank's end A = a (cos theta, sin theta) and the
    rocker's end B on O4 A at c from O4."""
    a, b, c, d = 45.0, 50.0, 55.0, 100.0
    theta = math.acos((a**2 + d**2 - (b + c) ** 2) / (2 * a * d))
    scene = _four_bar_files(tmp_path, d, a, b, c)
    scene.write_text(scene.read_text() + '[report]\npoints = ["B"]\n')
    assert main(["sweep", str(scene), "--steps", "13", flag, "--paths", str(tmp_path / "p.png")]) == 0
    ax = figures[0].axes[0]
    folds = [line for line in ax.get_lines() if line.get_gid() == "fold"]
    assert any("fold" in line.get_label() for line in folds)
    drawn = np.vstack([np.column_stack(line.get_data()) for line in folds])
    O4 = np.array([d, 0.0])
    for t in ([theta] if flag == "--skip-failures" else [theta, -theta]):
        A = a * np.array([math.cos(t), math.sin(t)])
        B = O4 + c * (A - O4) / np.linalg.norm(A - O4)
        # A is set by the driver's value at the fold, located to rounding: PLACE_TOL_MM.
        # B: at a fold the loop's other angles move as the square root of the driver's
        # distance to it; the fold is located to ~1e-13 rad, so B to ~sqrt(1e-13) * 100 mm
        # ~ 3e-5 mm: 1e-3 mm leaves a margin of 30.
        for point, tol in ((A, PLACE_TOL_MM), (B, 1e-3)):
            nearest = np.min(np.linalg.norm(drawn - point, axis=1))
            assert nearest < tol, (t, point, nearest)
