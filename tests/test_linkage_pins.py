"""A drawn linkage's pins reported as points by name, and what a ground pin's driver value is.

Expected numbers: Norton's four-bar, the R-RTR and the crank's rotation by hand
(scripts/closed_form.py). Tolerances as tests/test_linkage.py: 1e-10 m for positions and
1e-9 relative for rates (loops close to ~1e-13 of a 0.1 m mechanism, condition numbers
below 1e3 away from toggles); a point on the wrong link or a relative angle is off by mm.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import closed_form as cf
import numpy as np
import pytest

from pinmech import Scene, analyse
from pinmech.cli import main

LINKAGES = Path(__file__).resolve().parents[1] / "models" / "linkages"
POS, REL = 1e-10, 1e-9


def solved(tmp_path: Path, linkage: Path, driver: str, deg: float, rpm: float, points: list[str],
           alpha: str = "0 rad/s^2"):
    path = tmp_path / "scene.toml"
    path.write_text(f'linkage = "{linkage}"\n[drivers.{driver}]\nangle = "{deg!r} deg"\nspeed = "{rpm!r} rpm"\n'
                    f'acceleration = "{alpha}"\n[report]\npoints = {points!r}\n'.replace("'", '"'))
    return analyse(Scene.load(path)).motion.points


def close(point, position, velocity, acceleration, label):
    np.testing.assert_allclose(point.position[:2], position, rtol=0, atol=POS, err_msg=label)
    np.testing.assert_allclose(point.velocity[:2], velocity, rtol=0, atol=REL * max(1.0, np.abs(velocity).max()),
                               err_msg=label)
    np.testing.assert_allclose(point.acceleration[:2], acceleration, rtol=0,
                               atol=REL * max(1.0, np.abs(acceleration).max()), err_msg=label)


@pytest.mark.parametrize("deg", [75.0, 200.0])
def test_four_bar_pins_are_points_norton_gives(tmp_path, deg):
    """A (a tree pin), B (the loop cut, which was 'unknown point') and O4 (a ground pin)."""
    omega, alpha = 120 * math.pi / 30, 5.0
    points = solved(tmp_path, LINKAGES / "four_bar.toml", "O2", deg, 120.0, ["A", "B", "O4"], "5 rad/s^2")
    ref = cf.four_bar(math.radians(deg), omega, alpha, 0.04, 0.12, 0.08, 0.10, branch=+1)
    close(points["A"], ref.A, ref.vA, ref.aA, "A")
    close(points["B"], ref.B, ref.vB, ref.aB, "B")
    close(points["O4"], [0.10, 0.0], [0.0, 0.0], [0.0, 0.0], "O4")


def test_a_slot_pin_is_the_crank_pin(tmp_path):
    """The drawn R-RTR's slot pin B (joints B_pin, B_slide): the crank pin's motion."""
    deg, omega = 130.0, -50 * math.pi / 30
    points = solved(tmp_path, LINKAGES / "inverted_slider_crank.toml", "A", deg, -50.0, ["B"])
    ref = cf.r_rtr(math.radians(deg), omega, 0.0)
    close(points["B"], ref.B, ref.vB, ref.aB, "B")


def test_a_pin_of_three_links_is_one_point(tmp_path):
    """Jansen's A joins crank, upper and lower (joints A_upper, A_lower): the crank tip,
    m (cos theta, sin theta) with m = 15 mm, turning at 60 rpm."""
    deg, omega = 60.0, 2 * math.pi
    points = solved(tmp_path, LINKAGES / "jansen.toml", "O", deg, 60.0, ["A"])
    th = math.radians(deg)
    u = np.array([math.cos(th), math.sin(th)])
    close(points["A"], 0.015 * u, 0.015 * omega * np.array([-u[1], u[0]]), -0.015 * omega**2 * u, "A")


def test_a_ground_pins_value_is_the_cranks_angle_from_world_x(tmp_path):
    """A crank drawn at 30 deg, its ground line O2 -> O4 at 53.13 deg: the driver value 75 deg
    puts A at 40 mm (cos 75, sin 75) deg, the crank's absolute angle (not 30 + 75, nor 75
    from the ground line)."""
    path = tmp_path / "tilted.toml"
    path.write_text("""ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"]
O4 = ["60 mm", "80 mm"]
A = { from = "O2", length = "40 mm", angle = "30 deg" }
B = { from = ["A", "O4"], lengths = ["120 mm", "80 mm"], side = "right" }
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
""")
    points = solved(tmp_path, path, "O2", 75.0, 0.0, ["A"])
    th = math.radians(75.0)
    np.testing.assert_allclose(points["A"].position[:2], [0.04 * math.cos(th), 0.04 * math.sin(th)], atol=POS)


def test_a_pin_is_accepted_in_a_sweep(tmp_path):
    """Reported and plotted by name over a sweep: the CSV's B columns are Norton's B."""
    pytest.importorskip("matplotlib", reason='needs pip install "pinmech[plot]"')
    path = tmp_path / "scene.toml"
    path.write_text(f'linkage = "{LINKAGES / "four_bar.toml"}"\n[drivers.O2]\nangle = "0 deg"\nspeed = "1 rad/s"\n'
                    '[report]\npoints = ["B"]\n')
    table = tmp_path / "s.csv"
    assert main(["sweep", str(path), "--steps", "5", "--csv", str(table), "--plot", str(tmp_path / "s.png"),
                 "--points", "B"]) == 0
    rows = list(csv.DictReader(table.open()))
    x = next(k for k in rows[0] if k.startswith("B.x"))
    scale = 1e-3 if "[mm]" in x else 1.0
    for row in rows:
        theta = math.radians(float(next(v for k, v in row.items() if k.startswith("O2"))))
        ref = cf.four_bar(theta, 1.0, 0.0, 0.04, 0.12, 0.08, 0.10, branch=+1)
        np.testing.assert_allclose(float(row[x]) * scale, ref.B[0], atol=1e-9)  # CSV digits: ~1e-12 m


@pytest.mark.parametrize("figure", ["--plot", "--paths"])
def test_a_pin_named_only_on_the_command_line_is_drawn(tmp_path, figures, figure):
    """`--points B` on a scene whose [report] does not list pin B (it ended in a KeyError
    traceback): B is evaluated at every pose and drawn; its drawn path is Norton's B."""
    path = tmp_path / "scene.toml"
    path.write_text(f'linkage = "{LINKAGES / "four_bar.toml"}"\n[drivers.O2]\nangle = "0 deg"\nspeed = "1 rad/s"\n')
    assert main(["sweep", str(path), "--steps", "9", figure, str(tmp_path / "f.png"), "--points", "B"]) == 0
    ax = next(a for a in figures[-1].axes if any(line.get_label() == "path of B" for line in a.get_lines()))
    (line,) = [x for x in ax.get_lines() if x.get_label() == "path of B"]
    x, y = line.get_data()
    scale = 1e-3 if "mm" in ax.get_xlabel() else 1.0
    for k, theta in enumerate(np.radians(np.linspace(0.0, 360.0, 9))):
        ref = cf.four_bar(theta, 1.0, 0.0, 0.04, 0.12, 0.08, 0.10, branch=+1)
        # drawn coordinates are the solved ones (loops closed to 1e-13 of 0.1 m)
        np.testing.assert_allclose([x[k] * scale, y[k] * scale], ref.B[:2], atol=1e-9)
