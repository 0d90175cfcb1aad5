"""Sweep figures read back from matplotlib's own objects (the lines' data, the axes' limits)
against the R-RTR's closed form (scripts/closed_form.py): the driver axis runs 0-360 deg for
a whole turn, link 3's angle and D's path are the closed form's, and constant curves are
said, not drawn. Tolerance 1e-9: the sweep closes every loop to 1e-13 of the mechanism's
size, and the figure keeps float64 data.
"""

from __future__ import annotations

import closed_form as cf
import numpy as np
import pytest

from pinmech import Scene
from pinmech.cli import main
from tests.conftest import SCENES
from tests.tolerance import REGULAR, closure, rounding

pytest.importorskip("matplotlib", reason='plots need pip install "pinmech[plot]"')



def _axes(fig, title_start: str):
    return next(ax for ax in fig.axes if ax.get_title().startswith(title_start))


def test_a_whole_turn_from_30_deg_is_drawn_from_0_to_360(figures, tmp_path):
    """The R-RTR swept from the scene's 30 deg: the axis runs 0..360 and link 3's angle at
    every drawn x is the closed form's phi3 there (continuous: steps under 180 deg)."""
    assert main(["sweep", str(SCENES / "r_rtr.toml"), "--steps", "73", "--plot", str(tmp_path / "f.png"),
                 "--csv", str(tmp_path / "f.csv")]) == 0
    ax = _axes(figures[0], "link3: angle")
    assert ax.get_xlim() == (0.0, 360.0)
    (line,) = [x for x in ax.get_lines() if x.get_label() == "link3"]
    x, y = (np.asarray(a, dtype=float) for a in line.get_data())
    assert x[0] == 0.0 and x[-1] == 360.0 and np.all(np.diff(x) > 0)
    phi3 = np.degrees(cf.r_rtr(np.radians(x), 1.0, 0.0).phi3)
    np.testing.assert_allclose(np.mod(y - phi3 + 180, 360) - 180, 0.0, atol=1e-9)
    assert np.max(np.abs(np.diff(y))) < 180 and -180 < y[0] <= 180


def test_wrapped_angles_stay_in_half_open_turn(figures, tmp_path):
    assert main(["sweep", str(SCENES / "r_rtr.toml"), "--steps", "73", "--angles", "wrapped",
                 "--plot", str(tmp_path / "f.png")]) == 0
    (line,) = [x for x in _axes(figures[0], "link3: angle").get_lines() if x.get_label() == "link3"]
    y = np.asarray(line.get_ydata(), dtype=float)
    finite = y[np.isfinite(y)]
    assert np.all((finite > -180) & (finite <= 180))
    assert np.nanmax(np.abs(np.diff(y))) < 180  # a gap, not a vertical line, where it wraps


def test_path_of_d_is_the_closed_forms_circle(figures, tmp_path):
    """D = C + CD u: the path drawn [mm] is the closed form's, a circle of 150 mm about C,
    on equal axes; the mechanism is drawn under it."""
    assert main(["sweep", str(SCENES / "r_rtr.toml"), "--steps", "37", "--paths", str(tmp_path / "p.png")]) == 0
    ax = figures[0].axes[0]
    (line,) = [x for x in ax.get_lines() if x.get_label() == "path of D"]
    u, v = (np.asarray(a, dtype=float) for a in line.get_data())
    theta = np.radians(np.linspace(30, 390, 37))
    np.testing.assert_allclose(np.column_stack([u, v]), 1000 * cf.r_rtr(theta, 1.0, 0.0).D, atol=1e-9)
    assert ax.get_aspect() == 1.0
    assert ax.patches  # the mechanism: ground triangles, the slider block


def test_slider_position_is_plotted_and_in_the_csv(figures, tmp_path):
    """B_slider's s = -|CB| (the slider sits at -|CB| from B), plotted and a CSV column."""
    csv = tmp_path / "s.csv"
    assert main(["sweep", str(SCENES / "r_rtr.toml"), "--steps", "13", "--plot", str(tmp_path / "s.png"),
                 "--csv", str(csv)]) == 0
    header = csv.read_text(encoding="utf-8").splitlines()[0].split(",")
    data = np.array([r.split(",") for r in csv.read_text(encoding="utf-8").splitlines()[1:]])
    s = data[:, header.index("B_slider.s [m]")].astype(float)
    theta = np.radians(data[:, 0].astype(float))
    np.testing.assert_allclose(s, -cf.r_rtr(theta, 1.0, 0.0).s, atol=closure(0.2, REGULAR))
    assert _axes(figures[0], "B_slider: position").get_lines()


def test_constant_curves_are_said_not_drawn(figures, tmp_path):
    """The slider-crank's piston never turns: its angle is named constant, with no curve."""
    assert main(["sweep", str(SCENES / "slider_crank.toml"), "--steps", "19", "--links", "rod", "piston",
                 "--plot", str(tmp_path / "c.png")]) == 0
    ax = _axes(figures[0], "angle")
    drawn = [x.get_label() for x in ax.get_lines() if len(x.get_xdata()) and not x.get_label().startswith("_")]
    assert drawn == ["rod"]
    legend = ax.get_legend()  # said in the legend, beside the panel: no box over a curve
    assert any("piston" in t.get_text() and "constant" in t.get_text() for t in legend.get_texts())
    assert not [t for t in ax.texts if t.get_gid() != "marker"]  # only the limit positions' labels
    assert legend.get_bbox_to_anchor().x0 >= ax.get_window_extent().x1 - 1


@pytest.mark.parametrize(("scene", "said"), [("r_rtr", "driver A at speed -50 rpm, acceleration 0 rad/s^2"),
                                             ("four_bar", "driver O2 at speed 120 rpm, acceleration 0")])
def test_the_title_gives_the_drivers_speed_and_acceleration(figures, tmp_path, scene, said):
    """As the scene writes them (the four-bar's scene gives no acceleration: 0)."""
    assert main(["sweep", str(SCENES / f"{scene}.toml"), "--steps", "5", "--plot", str(tmp_path / "t.png")]) == 0
    assert said in figures[0].get_suptitle()



def test_paths_on_a_chosen_world_plane(figures, tmp_path):
    """--path-plane yz: D's path drawn as (y, z) = (the closed form's y, 0)."""
    assert main(["sweep", str(SCENES / "r_rtr.toml"), "--steps", "13", "--path-plane", "yz",
                 "--paths", str(tmp_path / "p.png")]) == 0
    ax = figures[0].axes[0]
    (line,) = [x for x in ax.get_lines() if x.get_label() == "path of D"]
    u, v = (np.asarray(a, dtype=float) for a in line.get_data())
    theta = np.radians(np.linspace(30, 390, 13))
    np.testing.assert_allclose(u, 1000 * cf.r_rtr(theta, 1.0, 0.0).D[:, 1], atol=1e-9)
    np.testing.assert_allclose(v, 0.0, atol=rounding(200.0))
    assert ax.get_xlabel() == "y [mm]" and ax.get_ylabel() == "z [mm]"


def test_a_fixed_points_path_is_a_dot(figures, tmp_path):
    """The path of the fixed pivot A stays at A: every drawn place is (0, 0)."""
    assert main(["sweep", str(SCENES / "r_rtr.toml"), "--steps", "5", "--points", "A",
                 "--paths", str(tmp_path / "p.png")]) == 0
    (line,) = [x for x in figures[0].axes[0].get_lines() if x.get_label() == "path of A"]
    np.testing.assert_allclose(np.asarray(line.get_xydata(), dtype=float), 0.0, atol=rounding(200.0))


def test_a_turn_that_does_not_come_back_is_drawn_as_swept(figures, tmp_path):
    """Were the mechanism elsewhere after its turn, folding 360..390 onto 0..30 would draw a
    jump at 30 deg: then the axis runs as swept, 30..390 (the last pose is moved to mimic it)."""
    from pinmech.draw.plot import SweepPlot
    from pinmech.io.sweep import Sweep

    sweep = Sweep.from_scene(Scene.load(SCENES / "r_rtr.toml"))
    recorder = SweepPlot(sweep)
    for pose in sweep.poses(sweep.default_values(37)):
        recorder.add(pose)
    recorder.save(tmp_path / "back.png")
    assert _axes(figures[-1], "link3: angle").get_xlim() == (0.0, 360.0)
    recorder.series["speed, |v| [m/s]"]["D"][-1] *= 1.01
    recorder.save(tmp_path / "elsewhere.png")
    assert _axes(figures[-1], "link3: angle").get_xlim() == pytest.approx((30.0, 390.0))


def test_the_jansen_legs_foot_path_is_the_closed_forms(figures, tmp_path):
    """The Strandbeest leg (three loops, no visuals): the foot G's path drawn [mm] over a turn
    is the closed form's chain of dyads (scripts/closed_form_jansen.py) at the same crank
    angles. Tolerance 1e-6 mm: loops closed to 1e-13 of the 1.2 m leg, float64 data."""
    from closed_form_jansen import jansen_leg

    assert main(["sweep", str(SCENES / "jansen_leg.toml"), "--steps", "73", "--paths", str(tmp_path / "g.png")]) == 0
    (line,) = [x for x in figures[0].axes[0].get_lines() if x.get_label() == "path of G"]
    theta = np.radians(np.linspace(90, 450, 73))
    np.testing.assert_allclose(np.asarray(line.get_xydata(), dtype=float), 1000 * jansen_leg(theta)["G"], atol=1e-6)


def test_a_decimated_sweep_figure_keeps_its_last_pose(scenes_dir):
    """Above MAX_POINTS poses the figure keeps every n-th: 20,002 poses over a turn were drawn
    30 to 390 deg less the end (the last pose was not an n-th). The last pose is always kept."""
    import math

    import pinmech
    from pinmech.draw.plot import MAX_POINTS, SweepPlot

    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(scenes_dir / "r_rtr.toml"))
    total = MAX_POINTS + 2
    values = sweep.start + np.linspace(0.0, 2 * math.pi, total)
    plot = SweepPlot(sweep, total=total)
    for pose in sweep.poses(values):
        plot.add(pose)
    assert plot.every > 1 and plot.x[-1] == pytest.approx(math.degrees(values[-1]), abs=1e-9)
