"""A study parameter is read, written and differentiated in the frame the file writes it
in, wherever Pinocchio stores it: a URDF point on a fixed link turned on another fixed
link, a joint origin on a turned fixed link, a cut on a turned fixed link, an MJCF site on
a jointless body with its own turn, an MJCF body's pos under a joint with a `pos`.

The reference is a four-bar written by hand (circle intersection, no Pinocchio): its
nominal outputs, and central differences of it in each parameter, against the study's
nominal values, outputs and dy/dp by the implicit-function theorem.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pinmech.design.study.file import parse_study
from pinmech.design.study.outputs import StudyOutputs
from pinmech.design.study.sensitivity import cycle_sensitivity
from pinmech.design.study.variant import StudyMechanism

MODELS = Path(__file__).resolve().parents[1] / "models"
G1, G, G2 = 0.4, np.pi / 6, -0.3  # turns [rad]: the crank's plate, P's plate, the coupler's end
H = 1e-7  # [m] central differences of the hand geometry (see _check)


def _rot(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


def _four_bar(theta: np.ndarray, A_of, AB: np.ndarray, O4: np.ndarray, c: float, P_on_coupler: np.ndarray,
              branch: int) -> np.ndarray:
    """(steps, 3): P.x, P.y [m] and the rocker's angle atan2(B - O4) [rad] of a four-bar
    whose crank pin is A_of(theta) [m], coupler end B at AB in the coupler's frame, rocker
    |O4 B| = c; B the circles' intersection on side `branch` of A -> O4."""
    out = []
    for t in theta:
        A = A_of(t)
        b, d = np.linalg.norm(AB), O4 - A
        L = np.linalg.norm(d)
        x = (b * b - c * c + L * L) / (2 * L)  # along A -> O4
        y = branch * np.sqrt(b * b - x * x)
        B = A + (x * d + y * np.array([-d[1], d[0]])) / L
        phi = np.arctan2(*(B - A)[::-1]) - np.arctan2(AB[1], AB[0])
        P = A + _rot(phi) @ P_on_coupler
        out.append([P[0], P[1], np.arctan2(*(B - O4)[::-1])])
    return np.array(out)


def _urdf_model(tmp_path: Path) -> Path:
    """The bundled four-bar with its dimensions written on turned fixed links: the crank pin
    A on a crank plate turned G1, P at x = 60 mm on a plate turned G on the coupler, the cut
    B's coupler side on an end turned G2."""
    text = (MODELS / "four_bar.urdf").read_text()
    text = text.replace(
        '<joint name="A" type="continuous">\n    <parent link="crank"/><child link="coupler"/><origin xyz="0.04 0 0"/>',
        f'<joint name="A" type="continuous">\n    <parent link="crank_plate"/><child link="coupler"/>'
        f'<origin xyz="0.04 0 0" rpy="0 0 {-G1!r}"/>')
    bx, by = float(0.12 * np.cos(-G2)), float(0.12 * np.sin(-G2))
    text = text.replace('<parent link="coupler"/> <parent_origin xyz="0.12 0 0"/>',
                        f'<parent link="coupler_end"/> <parent_origin xyz="{bx!r} {by!r} 0"/>')
    text = text.replace(
        '<joint name="point_P" type="fixed"><parent link="coupler"/><child link="P"/><origin xyz="0.06 0.03 0"/></joint>',
        f'<link name="crank_plate"/><joint name="crank_plate" type="fixed"><parent link="crank"/>'
        f'<child link="crank_plate"/><origin rpy="0 0 {G1!r}"/></joint>\n'
        f'<link name="coupler_end"/><joint name="coupler_end" type="fixed"><parent link="coupler"/>'
        f'<child link="coupler_end"/><origin rpy="0 0 {G2!r}"/></joint>\n'
        f'<link name="plate"/><joint name="plate" type="fixed"><parent link="coupler"/><child link="plate"/>'
        f'<origin xyz="0.01 0.02 0" rpy="0 0 {G!r}"/></joint>\n'
        '<joint name="point_P" type="fixed"><parent link="plate"/><child link="P"/><origin xyz="0.06 0 0"/></joint>')
    assert text.count("crank_plate") == 4 and "coupler_end" in text and 'link="plate"' in text
    (tmp_path / "four_bar_plates.urdf").write_text(text)
    scene = (MODELS / "scenes" / "four_bar.toml").read_text().replace('"../four_bar.urdf"', '"four_bar_plates.urdf"')
    scene = scene.replace('A = "40 deg"', 'A = "17 deg"')  # the coupler's joint angle less the crank plate's turn
    (tmp_path / "four_bar_plates.toml").write_text(scene)
    return tmp_path / "four_bar_plates.toml"


def _study(scene: Path, params: dict, outputs: dict) -> tuple[StudyMechanism, np.ndarray, np.ndarray]:
    raw = {"scene": str(scene), "kind": "sensitivity", "steps": 13, "params": params, "outputs": outputs}
    sm = StudyMechanism(parse_study(raw, scene.parent / "inline.toml"))
    cycle = sm.cycle(sm.nominal)
    assert not cycle.cause, cycle.detail
    y, dy = cycle_sensitivity(sm, StudyOutputs(sm), cycle)
    return sm, y, dy


def _check(sm, y, dy, hand, nominal: np.ndarray, columns: slice) -> None:
    """The study's nominals are the file's values (to 1e-15 m: one rotation applied and
    undone); its outputs the hand geometry's (1e-11 m, 1e-10 rad: the loop closed to 1e-13
    m times a condition number < 100); dy/dp central differences of the hand geometry,
    h = 1e-7 m: truncation (h / 0.04 m)^2 ~ 1e-11, rounding 1e-16 * 0.1 m / h ~ 1e-10,
    both far below the 1e-7 held (the error of the wrong frame is of order 0.1 to 1)."""
    np.testing.assert_allclose(sm.nominal, nominal, rtol=0, atol=1e-15)
    expected = hand(nominal)
    np.testing.assert_allclose(y[:, columns], expected[:, columns], rtol=0, atol=1e-10)
    for k in range(len(nominal)):
        step = np.zeros(len(nominal))
        step[k] = H
        fd = (hand(nominal + step) - hand(nominal - step)) / (2 * H)
        np.testing.assert_allclose(dy[:, columns, k], fd[:, columns], rtol=0, atol=1e-7, err_msg=sm.spec.params[k].name)


def test_urdf_dimensions_on_turned_fixed_links_are_in_the_frames_they_are_written_in(tmp_path):
    """Joint A's x on the crank plate (40 mm), P's x on its plate (60 mm), the cut B's
    coupler-side x on the coupler's end (120 cos 0.3 mm): each read as written and moving
    the mechanism along its own frame's x: dP/dp equals the hand geometry's."""
    scene = _urdf_model(tmp_path)
    params = {"a": {"joint": "A", "component": "x"}, "p": {"point": "P", "component": "x"},
              "s": {"cut": "B", "side": "parent", "component": "x"}}
    sm, y, dy = _study(scene, params, {"points": ["P"], "links": ["rocker"]})
    t_B = 0.12 * np.sin(-G2)  # the cut's y on the coupler's end, held

    def hand(x: np.ndarray, branch: int = 1) -> np.ndarray:
        a, p, s = x
        return _four_bar(sm.values, lambda t: _rot(t + G1) @ [a, 0.0], _rot(G2) @ [s, t_B], np.array([0.1, 0.0]),
                         0.08, np.array([0.01, 0.02]) + _rot(G) @ [p, 0.0], branch)

    nominal = np.array([0.04, 0.06, 0.12 * np.cos(G2)])
    branch = min((1, -1), key=lambda b: np.abs(hand(nominal, b)[:, :2] - y[:, :2]).max())
    _check(sm, y, dy, lambda x: hand(x, branch), nominal, slice(0, 2))
    rocker = np.angle(np.exp(1j * (y[:, 2] - hand(nominal, branch)[:, 2])))
    np.testing.assert_allclose(rocker, 0.0, rtol=0, atol=1e-10)


def test_mjcf_site_on_a_turned_body_and_a_body_pos_under_a_joint_pos(tmp_path):
    """An MJCF site P at x = 60 mm on a jointless body turned 30 deg on the coupler, the
    coupler body's pos x = 40 mm on a crank whose hinge sits 5 mm along it (joint pos), and
    the connect's anchor x on a jointless end turned -0.3 rad on the coupler: each read as
    written, and dP/dp is the hand geometry's (the crank turns about its hinge)."""
    text = (MODELS / "mjcf" / "four_bar.xml").read_text()
    text = text.replace('<site name="P" pos="0.06 0.03 0"/>',
                        f'<body name="plate" pos="0.01 0.02 0" euler="0 0 {G!r}"><site name="P" pos="0.06 0 0"/></body>')
    text = text.replace('<joint name="O2" type="hinge" axis="0 0 1"/>',
                        '<joint name="O2" type="hinge" axis="0 0 1" pos="0.005 0 0"/>')
    bx, by = float(0.12 * np.cos(-G2)), float(0.12 * np.sin(-G2))
    text = text.replace('<body name="plate"', f'<body name="coupler_end" euler="0 0 {G2!r}"/><body name="plate"')
    text = text.replace('body1="coupler" body2="rocker" anchor="0.12 0 0"',
                        f'body1="coupler_end" body2="rocker" anchor="{bx!r} {by!r} 0"')
    assert "plate" in text and 'pos="0.005 0 0"' in text and 'body1="coupler_end"' in text
    (tmp_path / "four_bar.xml").write_text(text)
    scene = (MODELS / "scenes" / "four_bar_mjcf.toml").read_text().replace('"../mjcf/four_bar.xml"', '"four_bar.xml"')
    (tmp_path / "four_bar_mjcf.toml").write_text(scene)
    params = {"a": {"body": "coupler", "component": "x"}, "p": {"point": "P", "component": "x"},
              "s": {"cut": "B", "side": "parent", "component": "x"}}
    sm, y, dy = _study(tmp_path / "four_bar_mjcf.toml", params, {"points": ["P"]})
    theta_c = 0.6341838408240407  # the coupler's drawn turn; B = A + 120 mm along it at qpos0
    B0 = np.array([0.04, 0.0]) + 0.12 * np.array([np.cos(theta_c), np.sin(theta_c)])
    c, hinge = np.linalg.norm(B0 - [0.1, 0.0]), np.array([0.005, 0.0])

    def hand(x: np.ndarray, branch: int = 1) -> np.ndarray:
        a, p, s = x
        return _four_bar(sm.values, lambda t: hinge + _rot(t) @ [a - 0.005, 0.0], _rot(G2) @ [s, by],
                         np.array([0.1, 0.0]), c, np.array([0.01, 0.02]) + _rot(G) @ [p, 0.0], branch)

    nominal = np.array([0.04, 0.06, bx])
    branch = min((1, -1), key=lambda b: np.abs(hand(nominal, b)[:, :2] - y).max())
    _check(sm, y, dy, lambda x: hand(x, branch), nominal, slice(0, 2))


@pytest.mark.parametrize("component", ["x", "y"])
def test_a_written_value_reads_back_in_its_frame(tmp_path, component):
    """Writing 61 mm into P's x (or 1 mm into its y) on the turned plate reads back 61 mm
    (1 mm) and moves P in the coupler by 1 mm along the plate's own axis."""
    scene = _urdf_model(tmp_path)
    sm, _, _ = _study(scene, {"p": {"point": "P", "component": component}}, {"points": ["P"]})
    place, frame = sm.placements[0], sm.mechanism.points["P"]
    before = np.array(sm.model.frames[frame].placement.translation)
    sm.write(sm.nominal + 0.001)
    np.testing.assert_allclose(place.read(), sm.nominal[0] + 0.001, rtol=0, atol=1e-16)
    axis = {"x": 0, "y": 1}[component]
    expected = np.append(_rot(G)[:, axis], 0.0) * 0.001
    np.testing.assert_allclose(np.array(sm.model.frames[frame].placement.translation) - before, expected,
                               rtol=0, atol=1e-17)
