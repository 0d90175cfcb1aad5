"""Every kind of loop cut through every output: the sweep's CSV and JSON lines, its figure
(the series drawn), the paths figure, the text and JSON reports and the HTML report page.

One mechanism per cut type pinmech accepts: a URDF `<constraint>` of each type
(revolute, prismatic on a fixed and on a turning guide), a drawn pin-in-slot (`[slots]`,
cut at its slide), an MJCF `<connect>` (spherical) and an MJCF `<weld>` (fixed). The
numbers are checked against the textbook closed forms of scripts/closed_form.py
(vector loops differentiated by hand, no Pinocchio): the slide's s, its rates along the
guide, the Coriolis term |2 w x v_rel| of the guide's turn, and a point's path.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import closed_form as cf
import numpy as np
import pytest

from pinmech import Scene
from pinmech.cli import main
from pinmech.io.sweep import Sweep
from tests._mechanisms import slider_crank_prismatic_cut_urdf
from tests.tolerance import rounding

MODELS = Path(__file__).resolve().parents[1] / "models"
RPM = 120.0
OMEGA = RPM * math.pi / 30.0  # the crank's speed in every case [rad/s]
DEGREES = (30.0, 50.0, 70.0, 90.0)  # the sweep: --from 30 deg --to 90 deg --steps 4
# Every pose closes to 1e-13 of the loop's size and the rate equations' condition numbers
# are below 1e2 here, so the outputs carry ~1e-11 relative error; the CSV prints 12
# significant digits. 1e-9 of each quantity's scale keeps a margin of a hundred while a
# wrong sign, origin, lever arm or a missing Coriolis term (1e-2 or more) fails.
RTOL = 1e-9


@dataclass(frozen=True)
class Case:
    """A mechanism, its cut, and what the closed form says at crank angle theta [rad]."""

    scene: Callable[[Path], Path]
    cut: str
    expected: Callable[[float], dict[str, float]]  # CSV column -> value (SI; s, rates, points)


# ----------------------------------------------------------------------- closed forms
def _r_rtr(theta: float) -> cf.RRTR:
    return cf.r_rtr(theta, OMEGA, 0.0)


def _slide_columns(name: str, s: float, s_dot: float, s_ddot: float, coriolis: float) -> dict[str, float]:
    return {f"{name}.s [m]": s, f"{name}.v_rel [m/s]": s_dot, f"{name}.a_rel [m/s^2]": s_ddot,
            f"{name}.|a_cor| [m/s^2]": coriolis}


def _point_columns(name: str, p, v, a) -> dict[str, float]:
    out = {f"{name}.{c} [m]": float(p[i]) for i, c in enumerate("xy")}
    out |= {f"{name}.v{c} [m/s]": float(v[i]) for i, c in enumerate("xy")}
    return out | {f"{name}.a{c} [m/s^2]": float(a[i]) for i, c in enumerate("xy")}


def _r_rtr_guide_slides(theta: float) -> dict[str, float]:
    """The R-RTR with link 3 (origin C, x along C -> B) on the block at B: link 3's origin
    C = B - s u, so the slide's coordinate is -s along u, its rates -s_dot, -s_ddot, and
    the block turns with link 3: Coriolis |2 w3 s_dot|."""
    r = _r_rtr(theta)
    return (_slide_columns("B_slider", -float(r.s), -float(r.s_dot), -float(r.s_ddot),
                           abs(2.0 * float(r.omega3) * float(r.s_dot)))
            | _point_columns("D", r.D, r.vD, r.aD))


def _drawn_slot(theta: float) -> dict[str, float]:
    """The drawn R-RTR: the block B slides along C -> B from where it was drawn (A at 90
    deg: B = (0, 100) mm, |CB| = sqrt(50^2 + 100^2) mm), so s = |CB| - |CB drawn|."""
    r = _r_rtr(theta)
    return (_slide_columns("B_slide", float(r.s) - math.hypot(0.05, 0.10), float(r.s_dot), float(r.s_ddot),
                           abs(2.0 * float(r.omega3) * float(r.s_dot)))
            | _point_columns("D", r.D, r.vD, r.aD))


def _slider_crank_at_slide(theta: float) -> dict[str, float]:
    """Offset slider-crank (r 50 mm, l 150 mm, e 10 mm) cut at its slide: the block's x is
    s (the guide's cut frame sits at x = 0), on a guide that does not turn."""
    k = cf.slider_crank(theta, OMEGA, 0.0, 0.05, 0.15, 0.01)
    return (_slide_columns("slide", float(k.x_B), float(k.v_B), float(k.a_B), 0.0)
            | _point_columns("B_pin", k.B, (float(k.v_B), 0.0), (float(k.a_B), 0.0)))


def _four_bar_point(theta: float) -> dict[str, float]:
    """The bundled four-bar (40, 120, 80, 100 mm) and its coupler point P at (60, 30) mm in
    the coupler's frame: P = A + R(theta3) (60, 30) mm, differentiated as a rigid body."""
    k = cf.four_bar(theta, OMEGA, 0.0, 0.04, 0.12, 0.08, 0.10)
    t3, w3, a3 = float(k.theta3), float(k.omega3), float(k.alpha3)
    rho = np.array([[math.cos(t3), -math.sin(t3)], [math.sin(t3), math.cos(t3)]]) @ np.array([0.06, 0.03])
    perp = np.array([-rho[1], rho[0]])
    return _point_columns("P", k.A + rho, k.vA + w3 * perp, k.aA + a3 * perp - w3**2 * rho)


# ----------------------------------------------------------------------- the scenes
def _scene(tmp_path: Path, model: str, driver: str, guess: str = "") -> Path:
    """A scene of `model` (its TOML line) driven at `driver`, 30 deg and RPM."""
    path = tmp_path / "scene.toml"
    path.write_text(f'{model}\n[drivers.{driver}]\nangle = "30 deg"\nspeed = "{RPM} rpm"\n{guess}', encoding="utf-8")
    return path


def _urdf_revolute(tmp_path: Path) -> Path:
    """The bundled R-RTR: cut at the pin C, the slide B_slider in the tree."""
    return _scene(tmp_path, f'urdf = "{(MODELS / "r_rtr.urdf").as_posix()}"', "A",
                  '[guess]\nB = "20 deg"\nB_slider = "-60 mm"\n')


def _urdf_prismatic_turning(tmp_path: Path) -> Path:
    """The R-RTR cut at its slide instead of at C: C is a tree pin, B_slider the cut."""
    text = (MODELS / "r_rtr.urdf").read_text(encoding="utf-8")
    text = re.sub(r'<joint name="B_slider".*?</joint>', '<joint name="C" type="continuous"><parent link="ground"/>'
                  '<child link="link3"/><origin xyz="0.05 0 0"/><axis xyz="0 0 1"/></joint>', text, flags=re.S)
    text = re.sub(r'<constraint name="C".*?</constraint>', '<constraint name="B_slider" type="prismatic">'
                  '<parent link="link2"/><parent_origin xyz="0 0 0"/><parent_axis xyz="1 0 0"/>'
                  '<child link="link3"/><child_origin xyz="0 0 0"/><child_axis xyz="1 0 0"/></constraint>',
                  text, flags=re.S)
    (tmp_path / "r_rtr_cut_at_slide.urdf").write_text(text, encoding="utf-8")
    return _scene(tmp_path, 'urdf = "r_rtr_cut_at_slide.urdf"', "A", '[guess]\nB = "20 deg"\nC = "54 deg"\n')


def _urdf_prismatic_fixed_guide(tmp_path: Path) -> Path:
    """tests/_mechanisms.py's slider-crank cut at its slide, with the block's pin B named."""
    text = slider_crank_prismatic_cut_urdf().replace("</robot>", '<link name="B_pin"/><joint name="point_B" '
                                                     'type="fixed"><parent link="block"/><child link="B_pin"/></joint>'
                                                     "</robot>")
    (tmp_path / "slider_crank_cut.urdf").write_text(text, encoding="utf-8")
    return _scene(tmp_path, 'urdf = "slider_crank_cut.urdf"', "O", '[guess]\nA = "-40 deg"\nB = "10 deg"\n')


def _drawn_slot_scene(tmp_path: Path) -> Path:
    return _scene(tmp_path, f'linkage = "{(MODELS / "linkages" / "inverted_slider_crank.toml").as_posix()}"', "A")


def _mjcf_connect(tmp_path: Path) -> Path:
    return MODELS / "scenes" / "four_bar_mjcf.toml"


#: The four-bar of models/mjcf/four_bar.xml closed by a weld instead: the rocker hangs on
#: the coupler at B, a base body on the rocker at O4, welded to the ground where it stands.
_WELDED_FOUR_BAR = """<mujoco model="four_bar_weld">
  <compiler angle="radian"/>
  <worldbody>
    <body name="crank">
      <joint name="O2" type="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 0.04 0 0" size="0.004"/>
      <body name="coupler" pos="0.04 0 0" euler="0 0 {t3}">
        <joint name="A" type="hinge" axis="0 0 1"/>
        <geom type="capsule" fromto="0 0 0 0.12 0 0" size="0.004"/>
        <site name="P" pos="0.06 0.03 0"/>
        <body name="rocker" pos="0.12 0 0" euler="0 0 {t4_rel}">
          <joint name="B" type="hinge" axis="0 0 1"/>
          <geom type="capsule" fromto="0 0 0 0.08 0 0" size="0.004"/>
          <body name="base" pos="0.08 0 0">
            <joint name="O4" type="hinge" axis="0 0 1"/>
            <geom type="box" size="0.01 0.01 0.01"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <equality><weld name="O4_weld" body1="base"/></equality>
</mujoco>
"""


def _mjcf_weld(tmp_path: Path) -> Path:
    k = cf.four_bar(0.0, 0.0, 0.0, 0.04, 0.12, 0.08, 0.10)  # assembled at qpos0: the crank along x
    t3, t4 = float(k.theta3), float(k.theta4)
    # the rocker's frame at B with x towards O4: its world angle t4 + pi
    (tmp_path / "weld.xml").write_text(_WELDED_FOUR_BAR.format(t3=t3, t4_rel=t4 + math.pi - t3), encoding="utf-8")
    return _scene(tmp_path, 'mjcf = "weld.xml"', "O2")


CASES = {
    "revolute <constraint>, slide in the tree": Case(_urdf_revolute, "C", _r_rtr_guide_slides),
    "prismatic <constraint>, turning guide": Case(_urdf_prismatic_turning, "B_slider", _r_rtr_guide_slides),
    "prismatic <constraint>, fixed guide": Case(_urdf_prismatic_fixed_guide, "slide", _slider_crank_at_slide),
    "drawn [slots]": Case(_drawn_slot_scene, "B_slide", _drawn_slot),
    "MJCF <connect> (spherical)": Case(_mjcf_connect, "B", _four_bar_point),
    "MJCF <weld> (fixed)": Case(_mjcf_weld, "O4_weld", _four_bar_point),
}


def _sweep_args(scene: Path) -> list[str]:
    return [str(scene), "--from", f"{DEGREES[0]} deg", "--to", f"{DEGREES[-1]} deg", "--steps", str(len(DEGREES))]


def _assert_rows(rows: list[dict[str, float]], case: Case, label: str) -> None:
    """Each row's numbers against the closed form at its crank angle."""
    assert len(rows) == len(DEGREES), label
    for row, deg in zip(rows, DEGREES):
        expected = case.expected(math.radians(deg))
        for column, value in expected.items():
            scale = max(abs(v) for k, v in expected.items() if k.split(" ")[1] == column.split(" ")[1]) or 1.0
            np.testing.assert_allclose(row[column], value, rtol=0, atol=RTOL * scale,
                                       err_msg=f"{label}: {column} at {deg} deg")


@pytest.mark.parametrize("name", list(CASES))
def test_the_sweep_csv_holds_every_cut_type(name, tmp_path, capsys):
    """CSV to standard output (the default), each cut type, against the closed form."""
    case = CASES[name]
    assert main(["sweep", *_sweep_args(case.scene(tmp_path))]) == 0, capsys.readouterr().err
    table = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    rows = [{k: float(v) for k, v in row.items() if _is_number(v)} for row in table]
    _assert_rows(rows, case, f"{name}, CSV")


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


@pytest.mark.parametrize("name", list(CASES))
def test_the_sweep_json_lines_hold_every_cut_type(name, tmp_path):
    """JSON lines: the slide's s and its rates along the guide, and the points, in SI."""
    case = CASES[name]
    out = tmp_path / "sweep.jsonl"
    argv = ["sweep", *_sweep_args(case.scene(tmp_path)), "--json", str(out), "--csv", str(tmp_path / "s.csv")]
    assert main(argv) == 0
    rows = []
    for line in out.read_text(encoding="utf-8").splitlines():
        entry, row = json.loads(line), {}
        for slider, s in entry["sliders"].items():
            coriolis = float(np.linalg.norm(s["coriolis_acceleration"]))
            row |= _slide_columns(slider, s["s"], s["s_dot"], s["s_ddot"], coriolis)
            axis = np.array(s["axis"])
            np.testing.assert_allclose(np.array(s["relative_velocity"]), s["s_dot"] * axis, rtol=0, atol=rounding(abs(s["s_dot"])))
        for point, p in entry["points"].items():
            row |= _point_columns(point, p["position"], p["velocity"], p["acceleration"])
        rows.append(row)
    _assert_rows(rows, case, f"{name}, JSON lines")


@pytest.mark.parametrize("name", list(CASES))
def test_the_sweep_figure_draws_every_cut_type(name, tmp_path):
    """The figure's series (what is drawn) against the closed form, then the file itself."""
    pytest.importorskip("matplotlib")
    from pinmech.draw.plot import SweepPlot

    case = CASES[name]
    sweep = Sweep.from_scene(Scene.load(case.scene(tmp_path)))
    recorder = SweepPlot(sweep, total=len(DEGREES))
    for pose in sweep.poses(np.radians(DEGREES)):
        recorder.add(pose)
    drawn = recorder.series.get("position along its guide, s [m]", {})
    for slider, values in drawn.items():
        for kind, title in (("s [m]", "position along its guide, s [m]"),
                            ("v_rel [m/s]", "velocity along its guide, v_rel [m/s]"),
                            ("a_rel [m/s^2]", "acceleration along its guide, a_rel [m/s²]")):
            expected = [case.expected(math.radians(d))[f"{slider}.{kind}"] for d in DEGREES]
            scale = max(map(abs, expected)) or 1.0
            np.testing.assert_allclose(list(recorder.series[title][slider]), expected, rtol=0, atol=RTOL * scale,
                                       err_msg=f"{name}: figure, {slider}.{kind}")
    assert recorder.save(tmp_path / "figure.png").stat().st_size > 0


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("output", ["plot", "paths", "report page", "text", "json"])
def test_every_output_takes_every_cut_type(name, output, tmp_path, capsys):
    """Exit 0 and a written file (or report) for each output kind; the numbers in them are
    the ones checked above."""
    case = CASES[name]
    scene = case.scene(tmp_path)
    target = tmp_path / {"plot": "f.png", "paths": "p.png", "report page": "r.html"}.get(output, "-")
    argv = {"plot": ["sweep", *_sweep_args(scene), "--plot", str(target), "--csv", str(tmp_path / "s.csv")],
            "paths": ["sweep", *_sweep_args(scene), "--paths", str(target), "--csv", str(tmp_path / "s.csv")],
            "report page": ["report", str(scene), "-o", str(target), "--steps", "5"],
            "text": ["solve", str(scene)],
            "json": ["solve", str(scene), "--json"]}[output]
    if output in ("plot", "paths", "report page"):
        pytest.importorskip("matplotlib")
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0, err
    if output in ("plot", "paths", "report page"):
        assert target.stat().st_size > 0
    elif output == "json":
        result = json.loads(out)
        assert set(result["sliders"]) == {k.split(".")[0] for k in case.expected(0.5) if k.endswith(".s [m]")}
    else:
        assert "Accuracy" in out


@pytest.mark.parametrize("name", ["prismatic <constraint>, fixed guide", "prismatic <constraint>, turning guide"])
def test_a_slide_cut_is_sketched_as_a_tree_slide_is(name, tmp_path):
    """Drawings without visuals (figures, pages): a slide cut gets a block on one link and
    its guide's line on the other, as a prismatic tree joint does. At the pose the block
    sits on the guide's line and both run along the slide (the closed form's direction)."""
    import pinocchio as pin

    from pinmech.model.link_nodes import sketch_links

    scene = Scene.load(CASES[name].scene(tmp_path))
    sweep = Sweep.from_scene(scene)
    mech = sweep.mechanism
    pose = next(iter(sweep.poses(np.radians([40.0]))))
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, sweep.last_q)
    sketches = sketch_links(mech)
    blocks = [s for s in sketches.values() if s.slide_axis is not None]
    guides = [s for s in sketches.values() if s.guides]
    assert len(blocks) == 1 and len(guides) == 1, name
    block, guide = blocks[0], guides[0]
    point, direction = guide.guides[0]
    M_g, M_b = data.oMi[guide.joint], data.oMi[block.joint]
    line_point, line_dir = M_g.act(point), M_g.rotation @ direction
    if name.endswith("fixed guide"):  # the line y = 10 mm along x; the block's pin B on it
        expected_dir, on_line = np.array([1.0, 0.0, 0.0]), pose.motion.points["B_pin"].position
    else:  # the guide C -> D (link 3's x), the block at B
        u = cf.r_rtr(math.radians(40.0), 0.0, 0.0).u
        expected_dir, on_line = np.array([u[0], u[1], 0.0]), pose.motion.points["D"].position
    np.testing.assert_allclose(abs(line_dir @ expected_dir), 1.0, atol=rounding(1.0))
    np.testing.assert_allclose(abs((M_b.rotation @ block.slide_axis) @ expected_dir), 1.0, atol=rounding(1.0))
    gap = (on_line - line_point) - ((on_line - line_point) @ line_dir) * line_dir
    np.testing.assert_allclose(gap, 0.0, atol=rounding(1.0))


def test_a_hand_check_reads_a_slot_cuts_travel_in_millimetres(tmp_path, capsys):
    """`pinmech check` on the drawn R-RTR's slot: s [mm] and s_dot [mm/s] printed from the
    closed form to 6 decimals (its own rounding: within the check's 2 units of the last
    digit), and a length given for the speed is refused as the wrong kind (exit 4)."""
    scene = _drawn_slot_scene(tmp_path)
    expected = _drawn_slot(math.radians(30.0))
    s, s_dot = expected["B_slide.s [m]"] * 1e3, expected["B_slide.v_rel [m/s]"] * 1e3
    hand = tmp_path / "slot.hand.toml"

    def write(speed_unit: str) -> None:
        hand.write_text(f'scene = "{scene.name}"\nsource = "closed_form.r_rtr"\n'
                        f'[[value]]\nlabel = "s"\nquantity = "sliders.B_slide.s"\nhand = ["{s:.6f}"]\nunit = "mm"\n'
                        f'[[value]]\nlabel = "s_dot"\nquantity = "sliders.B_slide.s_dot"\nhand = ["{s_dot:.6f}"]\n'
                        f'unit = "{speed_unit}"\n', encoding="utf-8")

    write("mm/s")
    assert main(["check", str(hand)]) == 0, capsys.readouterr()
    assert "2 ok" in capsys.readouterr().out
    write("mm")
    assert main(["check", str(hand)]) == 4
    assert "s_dot" in capsys.readouterr().err
