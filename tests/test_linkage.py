"""Linkages written as drawn: the generated URDF moves as the closed forms and hand URDFs say.

Every expected number comes from scripts/closed_form.py (Norton's four-bar, the offset
slider-crank, the R-RTR) or from a circle-intersection chain written here, never from the
linkage module. Poses are followed from the drawn pose in steps of 10-30 deg, each solve
started at the last one, so the branch is the drawn one.

Tolerances: loops close to 1e-13 of the mechanism's size (~0.1-0.2 m), and away from
toggle poses the condition numbers stay below 1e3, so positions agree to ~1e-13 m and rates
to ~1e-12 relative; we allow 1e-10 m for positions and 1e-9 relative (to the largest value
over the cycle) for angles, rates and accelerations. A wrong branch, sign or missing term
is off by 1e-3 or more.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from pinmech import LoopSolver, Mechanism, Scene, analyse
from pinmech.cli import main
from pinmech.exceptions import ModelError
from pinmech.model.linkage import parse_linkage
from pinmech.model.linkage_model import load_linkage
from pinmech.model.linkage_urdf import linkage_urdf
from pinmech.solve.motion import evaluate_motion
from tests._mechanisms import cut_rows
from tests.tolerance import REGULAR, rounding
from tests.tolerance import closure as closure_bound

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
import closed_form as cf

LINKAGES = Path(__file__).resolve().parents[1] / "models" / "linkages"
POS_TOL = 1e-10  # [m]
REL_TOL = 1e-9


def follow(mech: Mechanism, driver: str, values, omega: float, alpha: float = 0.0, *, start=None,
           points=None, links=None):
    """Solve at each driver value in turn, each started at the last pose; the motions."""
    solver = LoopSolver(mech, [driver])
    q = mech.neutral() if start is None else start
    out = []
    for value in values:
        sol = solver.solve([value], [omega], [alpha], guess=q)
        q = sol.q
        out.append(evaluate_motion(mech, solver.data, sol.q, sol.v, sol.a, points=points, links=links))
    return out


def path_to(first: float, values) -> list[float]:
    """Steps of at most 15 deg from `first` through every value in turn."""
    out, last = [], first
    for value in values:
        n = max(1, math.ceil(abs(value - last) / math.radians(15)))
        out += list(np.linspace(last, value, n + 1)[1:])
        last = value
    return out


def angle_close(actual, expected, scale, label):
    diff = np.angle(np.exp(1j * (np.asarray(actual) - np.asarray(expected))))
    np.testing.assert_allclose(diff, 0.0, atol=REL_TOL * max(scale, 1.0), err_msg=label)


def circle(a, b, ra, rb, sign):
    """The point at ra from a and rb from b, left (+1) or right (-1) of a -> b."""
    d = np.linalg.norm(b - a)
    u = (b - a) / d
    x = (d * d + ra * ra - rb * rb) / (2 * d)
    return a + x * u + sign * math.sqrt(ra * ra - x * x) * np.array([-u[1], u[0]])


# ------------------------------------------------------------------- four-bar
THETAS = np.radians([0.0, 30.0, 60.0, 95.0, 150.0, 200.0, 260.0, 330.0])


def test_four_bar_drawn_matches_norton_and_the_hand_urdf(models_dir):
    mech = load_linkage(LINKAGES / "four_bar.toml")
    values = path_to(0.0, THETAS)
    motions = follow(mech, "O2", values, omega=12.0, alpha=3.0, points=["P"])
    hand = Mechanism.from_urdf(models_dir / "four_bar.urdf")
    guess = hand.neutral()
    hand.set_coordinate(guess, "A", math.radians(40))
    hand.set_coordinate(guess, "O4", math.radians(100))
    hand_motions = follow(hand, "O2", values, omega=12.0, alpha=3.0, start=guess, points=["P"])
    ref = cf.four_bar(np.array(values), 12.0, 3.0, 0.04, 0.12, 0.08, 0.10, branch=+1)
    for k, (m, h) in enumerate(zip(motions, hand_motions)):
        angle_close(m.links["coupler"].angle, ref.theta3[k], 1, "theta3")
        angle_close(m.links["rocker"].angle, ref.theta4[k], 1, "theta4")
        np.testing.assert_allclose(m.links["coupler"].angular_velocity[2], ref.omega3[k],
                                   atol=REL_TOL * np.max(np.abs(ref.omega3)))
        np.testing.assert_allclose(m.links["rocker"].angular_acceleration[2], ref.alpha4[k],
                                   atol=REL_TOL * np.max(np.abs(ref.alpha4)))
        # P is drawn at (100, 30) mm, so on the hand URDF's coupler it sits elsewhere:
        # compare P through the coupler's own frame (A, theta3) instead.
        A = ref.A[k]
        P0 = np.array([0.100, 0.030]) - np.array([0.04, 0.0])
        theta3_0 = cf.four_bar(0.0, 0.0, 0.0, 0.04, 0.12, 0.08, 0.10).theta3
        turn = ref.theta3[k] - theta3_0
        R = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
        np.testing.assert_allclose(m.points["P"].position[:2], A + R @ P0, atol=POS_TOL)
        for name in ("coupler", "rocker"):
            np.testing.assert_allclose(m.links[name].angular_velocity, h.links[name].angular_velocity,
                                       atol=REL_TOL * 20)


def test_drawn_pose_is_the_reference_and_closes():
    mech = load_linkage(LINKAGES / "four_bar.toml")
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    ref = cf.four_bar(0.0, 0.0, 0.0, 0.04, 0.12, 0.08, 0.10)
    for closure in mech.closures:
        np.testing.assert_allclose(cut_rows(mech.model, data, closure), 0.0, atol=rounding(0.12))
    assert mech.coordinate(mech.neutral(), "O4") == pytest.approx(ref.theta4, abs=rounding(math.pi))
    assert mech.mobility == 1 and [c.rows for c in mech.closures] == [2]


# ------------------------------------------------------------------- slider-cranks
def test_offset_slider_crank_matches_closed_form():
    mech = load_linkage(LINKAGES / "slider_crank.toml")
    values = path_to(0.0, np.radians([40.0, 120.0, 210.0, 300.0]))
    motions = follow(mech, "O", values, omega=-5.0, alpha=2.0, links=["rod"])
    ref = cf.slider_crank(np.array(values), -5.0, 2.0, r=0.04, l=0.13, e=0.05)
    x = np.array([0.160 + m.joints["slide"].q for m in motions])
    np.testing.assert_allclose(x, ref.x_B, atol=POS_TOL)
    np.testing.assert_allclose([m.joints["slide"].v for m in motions], ref.v_B, atol=REL_TOL)
    np.testing.assert_allclose([m.joints["slide"].a for m in motions], ref.a_B, atol=REL_TOL * 10)
    angle_close([m.links["rod"].angle for m in motions], ref.beta, 1, "beta")


def test_inverted_slider_crank_matches_r_rtr_closed_form_and_hand_urdf(models_dir):
    mech = load_linkage(LINKAGES / "inverted_slider_crank.toml")
    values = path_to(math.pi / 2, np.radians([150.0, 240.0, 330.0, 420.0]))
    motions = follow(mech, "A", values, omega=3.0, alpha=-1.0, points=["D"], links=["guide"])
    ref = cf.r_rtr(np.array(values), 3.0, -1.0)
    angle_close([m.links["guide"].angle for m in motions], ref.phi3, 1, "phi3")
    np.testing.assert_allclose([m.points["D"].position[:2] for m in motions], ref.D, atol=POS_TOL)
    np.testing.assert_allclose([m.points["D"].velocity[:2] for m in motions], ref.vD,
                               atol=REL_TOL * np.max(np.abs(ref.vD)))
    np.testing.assert_allclose([m.points["D"].acceleration[:2] for m in motions], ref.aD,
                               atol=REL_TOL * np.max(np.abs(ref.aD)))
    np.testing.assert_allclose([m.links["guide"].angular_acceleration[2] for m in motions], ref.alpha3,
                               atol=REL_TOL * np.max(np.abs(ref.alpha3)))
    hand = Mechanism.from_urdf(models_dir / "r_rtr.urdf")
    guess = hand.neutral()
    hand.set_coordinate(guess, "A", math.pi / 2)
    hand.set_coordinate(guess, "B", math.radians(20))
    hand.set_coordinate(guess, "B_slider", -0.06)
    theirs = follow(hand, "A", values, omega=3.0, alpha=-1.0, start=guess, points=["D"])
    np.testing.assert_allclose([m.points["D"].acceleration for m in motions],
                               [m.points["D"].acceleration for m in theirs], atol=REL_TOL * np.max(np.abs(ref.aD)))
    # the slot is the drawn model's loop cut: its slide is reported as the hand URDF's tree slider, from the
    # other side (the block on the guide, not link 3 on the block): every vector the opposite of the URDF's
    for ours, hands in zip(motions, theirs):
        slot, slider = ours.sliders["B_slide"], hands.sliders["B_slider"]
        for name in ("relative_velocity", "relative_acceleration", "coriolis_acceleration"):
            want = -getattr(slider, name)
            np.testing.assert_allclose(getattr(slot, name), want, atol=REL_TOL * max(1.0, np.max(np.abs(want))))
        assert (slot.parent, slot.child) == ("guide", "B_block")


def test_drawn_slider_crank_moves_as_the_bundled_hand_urdf(models_dir, tmp_path):
    """models/slider_crank.urdf (r 50 mm, l 150 mm, e 10 mm) drawn with the crank along x."""
    x_B = 0.05 + math.sqrt(0.15**2 - 0.01**2)
    path = tmp_path / "sc.toml"
    path.write_text(f"""ground = ["O"]
[joints]
O = ["0 mm", "0 mm"]
A = ["50 mm", "0 mm"]
B = ["{x_B * 1000!r} mm", "10 mm"]
[links]
crank = ["O", "A"]
rod = ["A", "B"]
piston = ["B"]
[sliders]
slide = {{ block = "piston", on = "ground", at = "B", along = "0 deg" }}
""")
    drawn = load_linkage(path)
    hand = Mechanism.from_urdf(models_dir / "slider_crank.urdf")
    guess = hand.neutral()
    hand.set_coordinate(guess, "slide", x_B)
    values = path_to(0.0, np.radians([45.0, 170.0, 300.0]))
    omega = 3000 * 2 * math.pi / 60
    ours = follow(drawn, "O", values, omega=omega, links=["rod"])
    theirs = follow(hand, "O", values, omega=omega, start=guess, links=["rod"])
    for o, t in zip(ours, theirs):
        assert o.joints["slide"].q + x_B == pytest.approx(t.joints["slide"].q, abs=POS_TOL)
        assert o.joints["slide"].a == pytest.approx(t.joints["slide"].a, rel=REL_TOL)
        np.testing.assert_allclose(o.links["rod"].angular_velocity, t.links["rod"].angular_velocity,
                                   atol=REL_TOL * omega)
        angle_close(o.links["rod"].angle, t.links["rod"].angle, 1, "rod")


# ------------------------------------------------------------------- six-bars
def _six_bar_reference(kind: str, theta2: float):
    """D and link 6's angle of the Watt or Stephenson file, from Norton and one circle."""
    fb = cf.four_bar(theta2, 0.0, 0.0, 0.04, 0.12, 0.08, 0.10, branch=+1)
    fb0 = cf.four_bar(0.0, 0.0, 0.0, 0.04, 0.12, 0.08, 0.10, branch=+1)
    if kind == "watt":
        O4, O6 = np.array([0.1, 0.0]), np.array([0.19, 0.03])
        B0 = fb0.B
        C0 = circle(O4, B0, 0.06, 0.05, -1)
        turn = fb.theta4 - fb0.theta4
        C = O4 + _rot(turn) @ (C0 - O4)
        D = circle(C, O6, 0.09, 0.07, +1)
    else:
        O6 = np.array([0.16, 0.11])
        C0 = circle(fb0.A, fb0.B, 0.07, 0.07, +1)
        C = fb.A + _rot(fb.theta3 - fb0.theta3) @ (C0 - fb0.A)
        D = circle(C, O6, 0.08, 0.06, +1)
    return C, D


def _rot(t):
    return np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])


@pytest.mark.parametrize("kind", ["watt", "stephenson"])
def test_six_bars_match_four_bar_plus_dyad(kind, tmp_path):
    mech = load_linkage(LINKAGES / f"{kind}.toml")
    assert mech.mobility == 1 and len(mech.closures) == 2
    values = path_to(0.0, np.radians([25.0, 50.0, 75.0]))
    solver = LoopSolver(mech, ["O2"])
    q = mech.neutral()
    data = solver.data
    link6 = mech.links["link6"]
    for value in values:
        sol = solver.solve([value], [0.0], [0.0], guess=q)
        q = sol.q
        pin.framesForwardKinematics(mech.model, data, q)
        C, D = _six_bar_reference(kind, value)
        # link6's frame sits on O6 with x towards D (its first bar), so D is at |O6 D| along x
        O6 = data.oMf[link6].translation[:2]
        x_axis = data.oMf[link6].rotation[:2, 0]
        length = 0.07 if kind == "watt" else 0.06
        np.testing.assert_allclose(O6 + length * x_axis, D, atol=POS_TOL)
        # link5's x axis runs from C to D (the order it lists them): checks C as well
        np.testing.assert_allclose(data.oMf[mech.links["link5"]].rotation[:2, 0], (D - C) / np.linalg.norm(D - C),
                                   atol=POS_TOL)


# ------------------------------------------------------------------- Jansen
JANSEN = {"a": 38, "b": 41.5, "c": 39.3, "d": 40.1, "e": 55.8, "f": 39.4, "g": 36.7, "h": 65.7, "i": 49, "j": 50,
          "k": 61.9, "l": 7.8, "m": 15}


def jansen_foot(theta: float) -> np.ndarray:
    """The foot G [m] at crank angle theta, by compass from the holy numbers (mm)."""
    n = {k: v / 1000 for k, v in JANSEN.items()}
    B = np.array([-n["a"], -n["l"]])
    A = n["m"] * np.array([math.cos(theta), math.sin(theta)])
    C = circle(A, B, n["j"], n["b"], -1)
    D = circle(A, B, n["k"], n["c"], +1)
    E = circle(B, C, n["d"], n["e"], +1)
    F = circle(E, D, n["f"], n["g"], -1)
    return circle(F, D, n["h"], n["i"], -1)


def test_jansen_foot_follows_the_compass_construction_over_a_turn():
    mech = load_linkage(LINKAGES / "jansen.toml")
    assert mech.mobility == 1 and len(mech.closures) == 3
    thetas = np.radians(np.arange(15.0, 361.0, 15.0))
    omega = 2 * math.pi  # one turn a second
    motions = follow(mech, "O", thetas, omega=omega, points=["G"])
    foot = np.array([jansen_foot(t) for t in thetas])
    np.testing.assert_allclose([m.points["G"].position[:2] for m in motions], foot, atol=POS_TOL)
    # velocity: central difference of the construction, h = 1e-6 rad: truncation
    # h^2/6 |G'''| ~ 1e-13 m/rad^3 * ..., round-off 1e-16 m / 1e-6 ~ 1e-10 m/s
    h = 1e-6
    fd = np.array([(jansen_foot(t + h) - jansen_foot(t - h)) / (2 * h) * omega for t in thetas])
    np.testing.assert_allclose([m.points["G"].velocity[:2] for m in motions], fd, atol=1e-7)
    # the foot's path: its lowest point and the stride along it, from the construction
    assert min(p[1] for p in foot) == pytest.approx(min(m.points["G"].position[1] for m in motions), abs=POS_TOL)


def test_jansen_file_is_short():
    lines = [line for line in (LINKAGES / "jansen.toml").read_text().splitlines() if line.strip()]
    assert len(lines) < 30


# ------------------------------------------------------------------- errors
BASE = """ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"]
O4 = ["100 mm", "0 mm"]
A = ["40 mm", "0 mm"]
B = { from = ["A", "O4"], lengths = ["120 mm", "80 mm"], side = "left" }
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
"""


@pytest.mark.parametrize("change, words", [
    (('A = ["40 mm", "0 mm"]', 'A = ["40", "0 mm"]'), ["[joints] A x", "no unit"]),
    (('crank = ["O2", "A"]', 'crank = ["O2", "Z"]'), ["[links] crank", "'Z'"]),
    (('"120 mm", "80 mm"', '"20 mm", "30 mm"'), ["[joints] B", "do not meet", "0.02", "0.03"]),
    (('A = ["40 mm", "0 mm"]', 'A = ["crank_len", "0 mm"]'), ["[joints] A x", "crank_len", "params"]),
    (('ground = ["O2", "O4"]', 'ground = "O2"'), ["ground", "list"]),
    (('side = "left"', 'side = "up"'), ["[joints] B", "side"]),
    (('rocker = ["O4", "B"]', 'rocker = ["O4", "B"]\nfloating = ["X"]\n[joints.X]'), ["[joints] X", "construction"]),
    (('[links]', 'colour = 1\n[links]'), ["[joints] colour"]),
    (('rocker = ["O4", "B"]', 'rocker = ["O4", "B"]\nloose = ["Q", "R"]'), ["Q"]),
])
def test_errors_name_file_key_and_numbers(tmp_path, change, words):
    path = tmp_path / "bad.toml"
    old, new = change
    assert old in BASE
    path.write_text(BASE.replace(old, new, 1))
    with pytest.raises(ModelError) as err:
        load_linkage(path)
    message = str(err.value)
    assert str(path) in message and "\n" not in message
    for word in words:
        assert word in message, message


def test_slider_without_a_line_and_unconnected_link(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text((LINKAGES / "slider_crank.toml").read_text().replace(', along = "0 deg"', ""))
    with pytest.raises(ModelError, match=r"\[sliders\] slide.*no line"):
        load_linkage(path)
    text = BASE.replace("[links]", 'P1 = ["0 mm", "50 mm"]\nP2 = ["10 mm", "50 mm"]\n[links]') + 'lone = ["P1", "P2"]\n'
    path.write_text(text)
    with pytest.raises(ModelError, match="lone.*joined to the ground by no chain"):
        load_linkage(path)


def test_missing_file_and_unknown_key(tmp_path):
    with pytest.raises(ModelError, match="no such linkage file"):
        load_linkage(tmp_path / "none.toml")
    path = tmp_path / "k.toml"
    path.write_text("linkz = 1\n" + BASE)
    with pytest.raises(ModelError, match="unknown key.*linkz"):
        load_linkage(path)


def test_params_vary_the_design(tmp_path):
    """A named parameter moves every coordinate that uses it: crank 40 -> 30 mm."""
    text = BASE.replace('ground = ["O2", "O4"]', 'ground = ["O2", "O4"]\nparams = { r = "30 mm" }')
    path = tmp_path / "p.toml"
    path.write_text(text.replace('A = ["40 mm", "0 mm"]', 'A = ["r", "0 mm"]'))
    mech = load_linkage(path)
    motion = follow(mech, "O2", [0.5], omega=1.0, links=["rocker"])[0]
    ref = cf.four_bar(0.5, 1.0, 0.0, 0.03, 0.12, 0.08, 0.10, branch=+1)
    angle_close(motion.links["rocker"].angle, ref.theta4, 1, "theta4")


def test_urdf_text_is_valid_for_pinocchio_alone():
    """The generated URDF builds in Pinocchio without pinmech: a user can take it elsewhere."""
    text, reference = linkage_urdf(parse_linkage(LINKAGES / "jansen.toml"))
    model = pin.buildModelFromXML(text)
    assert model.nv == 7 and set(reference) <= set(model.names)


# ------------------------------------------------------------------- more classes
def test_r_rtr_with_a_block_sliding_on_the_moving_guide(tmp_path):
    """The R-RTR again, as a block pinned to the crank sliding on link 3: the slide is the cut."""
    text = (LINKAGES / "inverted_slider_crank.toml").read_text()
    text = text.replace('crank = ["A", "B"]', 'crank = ["A", "B"]\nblock = ["B"]')
    text = text.replace('[slots]\nB = { pin = "crank", slot = "guide", along = ["C", "B"] }',
                        '[sliders]\nS = { block = "block", on = "guide", at = "B", along = ["C", "B"] }')
    path = tmp_path / "r_rtr_slider.toml"
    path.write_text(text)
    mech = load_linkage(path)
    assert [c.name for c in mech.closures] == ["S"] and mech.closures[0].cut_type == "prismatic"
    values = path_to(math.pi / 2, np.radians([200.0, 330.0, 420.0]))
    motions = follow(mech, "A", values, omega=-2.0, alpha=0.5, points=["D"], links=["guide"])
    ref = cf.r_rtr(np.array(values), -2.0, 0.5)
    np.testing.assert_allclose([m.points["D"].position[:2] for m in motions], ref.D, atol=POS_TOL)
    np.testing.assert_allclose([m.links["guide"].angular_velocity[2] for m in motions], ref.omega3,
                               atol=REL_TOL * np.max(np.abs(ref.omega3)))


@settings(max_examples=15, deadline=None)
@given(a=st.floats(0.02, 0.05), b=st.floats(0.10, 0.16), c=st.floats(0.07, 0.12), theta=st.floats(0.0, 2 * math.pi))
def test_any_drawn_crank_rocker_follows_norton(tmp_path_factory, a, b, c, theta):
    """Random Grashof crank-rockers (ground 0.1 m, crank shortest), drawn with the crank along x."""
    d = 0.10
    # |A - O4| runs over [d - a, d + a]: the loop closes all round, 5 mm from the toggles
    assume(abs(b - c) + 0.005 < d - a and a + d + 0.005 < b + c)
    text = BASE.replace('"40 mm", "0 mm"]', f'"{a * 1000!r} mm", "0 mm"]').replace(
        '"120 mm", "80 mm"', f'"{b * 1000!r} mm", "{c * 1000!r} mm"')
    path = tmp_path_factory.mktemp("fb") / "fb.toml"
    path.write_text(text)
    mech = load_linkage(path)
    values = path_to(0.0, [theta])
    motion = follow(mech, "O2", values, omega=1.0, links=["coupler", "rocker"])[-1]
    ref = cf.four_bar(values[-1], 1.0, 0.0, a, b, c, d, branch=+1)
    angle_close(motion.links["rocker"].angle, ref.theta4, 1, "theta4")
    np.testing.assert_allclose(motion.links["coupler"].angular_velocity[2], ref.omega3, atol=1e-8)


def test_build_writes_the_urdf_whole(tmp_path, capsys):
    out = tmp_path / "jansen.urdf"
    assert main(["build", str(LINKAGES / "jansen.toml"), "-o", str(out)]) == 0
    said = capsys.readouterr().out
    assert "loop cuts: C, D_rocker, F" in said and "7 links" in said
    text = out.read_text()
    assert text.count("<constraint ") == 3 and pin.buildModelFromXML(text).nv == 7
    assert Mechanism.from_urdf(out).mobility == 1  # a plain URDF, loadable without the TOML
    bad = tmp_path / "bad.toml"
    bad.write_text(BASE.replace('"120 mm", "80 mm"', '"20 mm", "30 mm"'))
    out.write_text("previous")
    assert main(["build", str(bad), "-o", str(out)]) == 3
    assert out.read_text() == "previous"  # a failed build leaves the old file alone
    assert main(["build", str(LINKAGES / "jansen.toml"), "-o", str(tmp_path / "no" / "x.urdf")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 2


@pytest.mark.parametrize("head, code, words", [
    ('linkage = "{L}/four_bar.toml"\nurdf = "x.urdf"\n', 4, ["exactly one of"]),
    ('linkage = "{L}/missing.toml"\n', 3, ["linkage", "not a file"]),
    ('mjcf = "{L}/missing.xml"\n', 3, ["mjcf", "not a file"]),
    ('linkage = "{L}/four_bar.toml"\nsidecar = "robot.yaml"\n', 4, ["sidecar", "urdf"]),
])
def test_scene_model_keys(tmp_path, capsys, head, code, words):
    scene = tmp_path / "s.toml"
    scene.write_text(head.format(L=LINKAGES) + '[drivers.O2]\nangle = "10 deg"\n')
    assert main(["solve", str(scene)]) == code
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(scene) in err
    for word in words:
        assert word in err, err


def test_the_documented_jansen_leg_is_under_30_lines_and_the_bundled_one(tmp_path):
    """A user copying the docs' Jansen leg (docs/howto/linkage_toml.md) gets the bundled
    file's linkage, point for point."""
    section = (Path(__file__).resolve().parents[1] / "docs" / "howto" / "linkage_toml.md").read_text()
    block = section[section.index("```toml") + len("```toml\n"):]
    block = block[: block.index("```")]
    assert len([line for line in block.splitlines() if line.strip()]) < 30
    path = tmp_path / "jansen.toml"
    path.write_text(block)
    ours, bundled = parse_linkage(path), parse_linkage(LINKAGES / "jansen.toml")
    assert ours.links == bundled.links
    for name, point in bundled.points.items():
        np.testing.assert_array_equal(ours.points[name], point)
    assert load_linkage(path).mobility == 1


@pytest.mark.parametrize("angle", [200.0, -150.0, 330.0])
def test_a_scene_reaches_far_poses_on_the_drawn_assembly(scenes_dir, angle):
    """The Jansen scene asked for a crank angle far from the drawing: the foot is the compass
    construction's (same sides as drawn), reached from the drawn pose by continuation."""
    scene = Scene.load(scenes_dir / "jansen.toml", [f'drivers.O.angle="{angle} deg"'])
    foot = analyse(scene).motion.points["G"].position[:2]
    np.testing.assert_allclose(foot, jansen_foot(math.radians(angle)), atol=POS_TOL)


# ------------------------------------------------------------------- spatial
def test_spatial_rsur_drawn_moves_as_the_hand_urdf(tmp_path):
    """The RSUR of tests/_mechanisms.py, drawn where the hand URDF closes at R1 = 0.3 rad (its
    joint positions and axes read off Pinocchio there), a ball S as the cut: every joint's
    coordinate from the drawn pose plus its drawn value is the hand model's, with equal rates."""
    from tests._mechanisms import spatial_rsur_urdf, write

    hand = Mechanism.from_urdf(write(tmp_path, "rsur.urdf", spatial_rsur_urdf()))
    solver = LoopSolver(hand, ["R1"])
    drawn_q = solver.solve([0.3], guess=hand.neutral()).q
    data = hand.model.createData()
    pin.framesForwardKinematics(hand.model, data, drawn_q)
    at = {n: data.oMi[hand.model.getJointId(n)] for n in ("R1", "U1", "U2", "R4")}
    S = data.oMf[hand.closures[0].parent_frame].translation

    def mm(v):
        return "[" + ", ".join(f'"{float(x) * 1000!r} mm"' for x in v) + "]"

    def axis(name, local):
        return "[" + ", ".join(repr(float(x)) for x in at[name].rotation @ np.array(local)) + "]"

    path = tmp_path / "rsur.toml"
    path.write_text(f"""ground = ["R1", "R4"]
balls = ["S"]
[joints]
R1 = {mm(at["R1"].translation)}
U1 = {mm(at["U1"].translation)}
U2 = {mm(at["U2"].translation)}
S = {mm(S)}
R4 = {mm(at["R4"].translation)}
[axes]
R1 = {axis("R1", [0, 0, 1])}
U1 = {axis("U1", [0, 0, 1])}
U2 = {axis("U2", [0, 1, 0])}
R4 = {axis("R4", [1, 0, 0])}
[links]
crank = ["R1", "U1"]
cross = ["U1", "U2"]
coupler = ["U2", "S"]
rocker = ["R4", "S"]
""")
    mech = load_linkage(path)
    assert mech.mobility == 1 and mech.plane_normal is None
    assert [(c.name, c.cut_type) for c in mech.closures] == [("S", "spherical")]
    ours, theirs = LoopSolver(mech, ["R1"]), solver
    q_ours, q_hand = mech.neutral(), drawn_q
    for r1 in (0.4, 0.6, 0.2, 0.0, -0.2):
        a = ours.solve([r1 - 0.3], [1.5], [0.0], guess=q_ours)
        b = theirs.solve([r1], [1.5], [0.0], guess=q_hand)
        q_ours, q_hand = a.q, b.q
        for name in ("U1", "U2", "R4"):
            assert mech.coordinate(a.q, name) + hand.coordinate(drawn_q, name) == pytest.approx(
                hand.coordinate(b.q, name), abs=1e-11)
            assert a.v[mech.joints[name].idx_v] == pytest.approx(b.v[hand.joints[name].idx_v], abs=1e-10)


def test_spatial_errors(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(BASE + "[axes]\nA = [0, 0]\n")
    with pytest.raises(ModelError, match=r"\[axes\] A.*three numbers"):
        load_linkage(path)
    path.write_text(BASE + "[axes]\nZ = [0, 0, 1]\n")
    with pytest.raises(ModelError, match=r"\[axes\] Z.*not a joint"):
        load_linkage(path)
    path.write_text(BASE + "[axes]\nA = [0, 0, 0]\n")
    with pytest.raises(ModelError, match=r"\[axes\] A.*not a direction"):
        load_linkage(path)


def test_a_planar_linkage_written_in_3d_moves_as_the_planar_one(tmp_path):
    """The four-bar with a z = 0 coordinate written out: the planar linkage it draws (it was
    made spatial, its angles counted from the drawing: tests/test_linkage_plane_written_3d.py)."""
    path = tmp_path / "fb3.toml"
    path.write_text(BASE.replace('O2 = ["0 mm", "0 mm"]', 'O2 = ["0 mm", "0 mm", "0 mm"]'))
    mech = load_linkage(path)
    motion = follow(mech, "O2", path_to(0.0, [1.0]), omega=2.0, links=["rocker"])[-1]
    ref = cf.four_bar(1.0, 2.0, 0.0, 0.04, 0.12, 0.08, 0.10, branch=+1)
    # a planar linkage's frame x runs from the link's first point to its next: the rocker at theta4
    angle_close(motion.links["rocker"].angle, ref.theta4, 1, "theta4")
    assert motion.links["rocker"].angular_velocity[2] == pytest.approx(ref.omega4, abs=1e-9)


@pytest.mark.parametrize("scene", ["jansen", "four_bar_drawn", "rsur_drawn", "four_bar_mjcf", "leg_mjcf", "five_bar",
                                   "delta"])
def test_bundled_scenes_of_other_formats_solve(scenes_dir, scene, capsys):
    assert main(["solve", str(scenes_dir / f"{scene}.toml"), "--json"]) == 0
    assert capsys.readouterr().out.lstrip().startswith("{")


def test_a_drawn_linkage_locked_away_from_its_drawing(models_dir):
    """[lock] at another value than drawn was refused ('loop cut B is open ... at the drawn
    pose'): the drawing is checked as drawn, then the held joint opens the drawn pose and
    the solver closes it. The four-bar with its crank held 17 deg past the drawing is the
    free four-bar driven there (every coupler point to 1e-12 m)."""
    free = load_linkage(LINKAGES / "four_bar.toml")
    held_at = free.coordinate(free.reference, "O2") + math.radians(17)
    locked = load_linkage(LINKAGES / "four_bar.toml", locked={"O2": held_at})
    assert locked.mobility == 0 and "O2" not in locked.joints
    q = LoopSolver(locked, []).solve([], guess=locked.reference).q
    q_free = LoopSolver(free, ["O2"]).solve([held_at], guess=free.reference).q
    data, data_free = locked.model.createData(), free.model.createData()
    pin.framesForwardKinematics(locked.model, data, q)
    pin.framesForwardKinematics(free.model, data_free, q_free)
    for point in free.points:
        np.testing.assert_allclose(data.oMf[locked.points[point]].translation,
                                   data_free.oMf[free.points[point]].translation, atol=closure_bound(0.2, REGULAR))


# ------------------------------------------------------------------- spatial constructions
SPATIAL_LIFTED = """ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm", "50 mm"]
O4 = ["100 mm", "0 mm", "50 mm"]
A = { from = "O2", length = "40 mm", angle = "30 deg" }
B = { from = ["A", "O4"], lengths = ["120 mm", "80 mm"], side = "left" }
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
"""


def test_spatial_constructions_keep_their_bases_height(tmp_path):
    """A four-bar drawn in the plane z = 50 mm (was: the constructions dropped z, so the bars
    written 120 and 80 mm came out 130 and 94.3 mm). Each bar is its written length, by the
    distance formula on the drawn points, and the constructed points stay at z = 50 mm;
    A is the polar point (40 cos 30 deg, 40 sin 30 deg, 50) mm by hand."""
    path = tmp_path / "lifted.toml"
    path.write_text(SPATIAL_LIFTED)
    p = parse_linkage(path).points
    np.testing.assert_allclose(p["A"], [0.04 * math.cos(math.pi / 6), 0.02, 0.05], rtol=0, atol=rounding(0.05))
    bars = [np.linalg.norm(p[x] - p[y]) for x, y in (("O2", "A"), ("A", "B"), ("O4", "B"))]
    np.testing.assert_allclose(bars, [0.040, 0.120, 0.080], rtol=0, atol=rounding(0.12))  # rounding of mm -> m only
    assert p["B"][2] == pytest.approx(0.05, abs=rounding(0.12)) and p["B"][1] > 0  # left of A -> O4, seen from +z
    assert load_linkage(path).mobility == 1  # and the drawing closes as built


def test_a_compass_between_two_heights_is_refused(tmp_path):
    """Bases at z = 50 and 0 mm: the plane of the two circles is not given, so no guess."""
    path = tmp_path / "tilted.toml"
    path.write_text(SPATIAL_LIFTED.replace('O4 = ["100 mm", "0 mm", "50 mm"]', 'O4 = ["100 mm", "0 mm", "0 mm"]'))
    with pytest.raises(ModelError, match=r"tilted\.toml, \[joints\] B: a compass .* A is at z = 0\.05 m and O4 at "
                                         r"z = 0 m"):
        parse_linkage(path)


def test_a_drawn_slider_has_no_invented_limits():
    """URDF needs a <limit> on a prismatic joint; the one written for a drawn slider (1000
    times the mechanism's size) is no fact of the drawing and is no limit of the model."""
    assert load_linkage(LINKAGES / "slider_crank.toml").limits == {}


COLLIDING = [  # a linkage whose user name is one pinmech gives a generated URDF element, and that name
    ("""ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"]
O4 = ["100 mm", "0 mm"]
point_P = ["40 mm", "0 mm"]
B = { from = ["point_P", "O4"], lengths = ["120 mm", "80 mm"], side = "left" }
P = ["100 mm", "30 mm"]
[links]
crank = ["O2", "point_P"]
coupler = ["point_P", "B", "P"]
rocker = ["O4", "B"]
""", "point_P"),
    ("""ground = ["A", "C"]
[joints]
A = ["0 mm", "0 mm"]
C = ["50 mm", "0 mm"]
B = ["0 mm", "100 mm"]
D = { from = "C", length = "150 mm", angle = "116.56505117707799 deg" }
[links]
crank = ["A", "B"]
B_block = ["C", "D"]
[slots]
B = { pin = "crank", slot = "B_block", along = ["C", "B"] }
""", "B_block"),
]


@pytest.mark.parametrize(("text", "name"), COLLIDING)
def test_a_name_that_pinmech_generates_is_refused_naming_both(text, name, tmp_path, capsys):
    """A joint named point_P beside a point P: `pinmech build` wrote a URDF with two joints
    named point_P (exit 0), and a scene's error blamed the user's file for "not a valid URDF
    model". Now the linkage file is refused (exit 3) naming the clash, and nothing is written."""
    linkage = tmp_path / "clash.toml"
    linkage.write_text(text, encoding="utf-8")
    out = tmp_path / "clash.urdf"
    assert main(["build", str(linkage), "-o", str(out)]) == 3
    err = capsys.readouterr().err.strip()
    assert str(linkage) in err and f"'{name}'" in err and "pinmech gives" in err and "rename" in err, err
    assert len(err.splitlines()) == 1 and not out.exists()
    scene = tmp_path / "clash_scene.toml"
    first = "O2" if "O2" in text else "A"
    scene.write_text(f'linkage = "clash.toml"\n[drivers.{first}]\nangle = "0 deg"\n', encoding="utf-8")
    assert main(["solve", str(scene)]) == 3
    err = capsys.readouterr().err
    assert "valid URDF" not in err and "pinmech gives" in err, err


def test_an_error_in_the_generated_urdf_is_not_blamed_on_the_linkage_file(tmp_path, monkeypatch):
    """Should Pinocchio refuse the URDF pinmech generates (a pinmech defect), the error says
    it is the generated URDF, and where it lies, not that the user's file is a bad URDF."""
    from pinmech.model import mechanism

    def refuse(path, **kwargs):
        raise ModelError(f"The file {path} does not contain a valid URDF model.", path=str(path))

    monkeypatch.setattr(mechanism.Mechanism, "from_urdf", staticmethod(refuse))
    source = Path(__file__).resolve().parents[1] / "models" / "linkages" / "four_bar.toml"
    with pytest.raises(ModelError, match="the URDF pinmech generated from it") as caught:
        load_linkage(source)
    assert str(source) in str(caught.value) and "linkage-" in str(caught.value)
