"""`pinmech check`: where the printed R-RTR solution is right, where it rounds, where it is wrong.

The expectations below were established from the mathematics, not from pinmech: the
text's v_D = 0.386 i - 0.282 j is the velocity of B3 (omega_3 x CB), copied where
omega_3 x CD was meant; its program prints vD = (0.935792, -0.685048), which is
omega_3 x (r_D - r_C) = -7.7316 k x (0.088604, 0.121035). Its other three-decimal
values are truncated rather than rounded, hence "rounding" (within 1 unit of the last
digit) where a correctly rounded print would be "ok".
"""

from __future__ import annotations

import pytest

from pinmech import SceneError, analyse, compare, load_hand_file, to_dict
from pinmech.io.check import HandValue, format_verdicts
from pinmech.exceptions import UnitError
from pinmech.io.scene import Scene


@pytest.fixture(scope="module")
def verdicts(request):
    from tests.conftest import SCENES

    hand = load_hand_file(SCENES / "r_rtr.hand.toml")
    return {v.hand.label: v for v in compare(to_dict(analyse(Scene.load(hand.scene))), hand.values)}


def test_the_program_output_is_right_to_its_last_printed_digit(verdicts):
    program = {k: v for k, v in verdicts.items() if k.startswith("program:")}
    assert len(program) == 27
    assert {v.verdict for v in program.values()} == {"ok"}


def test_the_text_velocity_of_d_is_the_velocity_of_b3(verdicts):
    assert verdicts["text: v_D3 = v_D4 x"].verdict == "MISMATCH"
    assert verdicts["text: v_D3 = v_D4 y"].verdict == "MISMATCH"
    # ... and the printed numbers are those of B3, to their printed precision:
    assert verdicts["text: v_D3 = v_D4 x"].hand.value == pytest.approx(verdicts["program: vB3 x"].computed, abs=0.001)
    assert verdicts["text: v_D3 = v_D4 y"].hand.value == pytest.approx(verdicts["program: vB3 y"].computed, abs=0.001)


def test_the_other_text_values_hold_at_their_printed_precision(verdicts):
    text = {k: v for k, v in verdicts.items() if k.startswith("text:") or k.startswith("text eq")}
    wrong = sorted(k for k, v in text.items() if v.verdict == "MISMATCH")
    assert wrong == ["text: v_D3 = v_D4 x", "text: v_D3 = v_D4 y"]
    # truncated, not rounded: x_B = 0.0866 printed 0.086, omega_3 = -7.7316 printed -7.731
    assert verdicts["text eq. (3): r_B x"].verdict == "rounding"
    assert verdicts["text: omega_3 = omega_2"].verdict == "rounding"
    assert verdicts["text: alpha_3 = alpha_2"].verdict == "ok"


def test_a_printed_value_is_an_interval_of_half_a_last_digit():
    hv = HandValue("x", "points.B.position", 0, "0.386", "m", "length")
    assert hv.ulp == pytest.approx(0.001)
    [verdict] = compare({"points": {"B": {"position": [0.3864, 0, 0]}}}, [hv])
    assert verdict.verdict == "ok"
    [verdict] = compare({"points": {"B": {"position": [0.3869, 0, 0]}}}, [hv])
    assert verdict.verdict == "rounding"
    [verdict] = compare({"points": {"B": {"position": [0.3890, 0, 0]}}}, [hv])
    assert verdict.verdict == "MISMATCH"


def test_hand_units_are_converted():
    hv = HandValue("phi", "links.l.angle", None, "90.0", "deg", "angle")
    [verdict] = compare({"links": {"l": {"angle": 1.5707963267948966}}}, [hv])
    assert verdict.verdict == "ok" and verdict.computed == pytest.approx(90.0)


def test_table_counts(verdicts):
    table = format_verdicts(list(verdicts.values()))
    assert table.splitlines()[-1] == "35 ok, 11 within rounding, 2 mismatch"


@pytest.mark.parametrize(
    "body, message",
    [
        ('scene = "x.toml"\n[[value]]\nquantity = "points.D.velocity"\nhand = [0.386]\nunit = "m/s"\n', "must be a string"),
        ('scene = "x.toml"\n[[value]]\nquantity = "points.D.velocity"\nhand = ["abc"]\nunit = "m/s"\n', "is not a number"),
        ('scene = "x.toml"\n[[value]]\nquantity = "points.D.velocity"\nhand = ["1"]\nunit = "blorps/s"\n', "cannot read"),
        ('scene = "x.toml"\n[[value]]\nquantity = "points.D.weird"\nhand = ["1"]\nunit = "m"\n', "cannot tell the kind"),
        ('scene = "x.toml"\n[[value]]\nhand = ["1"]\nunit = "m"\n', "missing quantity"),
        ('[[value]]\n', "missing scene"),
        ('scene = [\n', "malformed TOML"),
    ],
)
def test_bad_hand_files(tmp_path, body, message):
    path = tmp_path / "h.toml"
    path.write_text(body)
    with pytest.raises(SceneError, match=message):
        load_hand_file(path)


def test_an_unknown_quantity_path_names_what_exists():
    hv = HandValue("x", "points.Q.position", 0, "1.0", "m", "length")
    with pytest.raises(SceneError, match=r"no 'Q' in the result \(has B\)"):
        compare({"points": {"B": {"position": [1, 0, 0]}}}, [hv])


@pytest.mark.parametrize("printed, si", [("413.794", 0.938892), ("-330", 0.523599), ("30", 0.523599 - 2 * 3.14159265),
                                         ("180", -3.14159265), ("53.794", 0.938892 + 4 * 3.14159265)])
def test_an_angle_and_its_equivalent_a_turn_away_agree(printed, si):
    # 413.794 deg = 53.794 deg + 360 deg; 53.794 deg = 0.938892 rad (to the 6 digits given here).
    hv = HandValue("phi", "links.L.angle", None, printed, "deg", "angle")
    [verdict] = compare({"links": {"L": {"angle": si}}}, [hv], slack=100)
    assert verdict.verdict != "MISMATCH" and abs(verdict.difference) < 1e-3


def test_angles_a_fraction_of_a_turn_apart_still_mismatch():
    hv = HandValue("phi", "links.L.angle", None, "233.794", "deg", "angle")  # 180 deg off
    [verdict] = compare({"links": {"L": {"angle": 0.938892}}}, [hv])
    assert verdict.verdict == "MISMATCH"


def test_a_magnitude_is_checked_as_the_norm_of_the_vector(tmp_path):
    # The program prints vD = (0.935792, -0.685048) m/s: |vD| = sqrt(0.935792^2 + 0.685048^2) = 1.159740.
    from tests.conftest import SCENES

    hand = tmp_path / "h.toml"
    hand.write_text(f'scene = "{SCENES / "r_rtr.toml"}"\n[[value]]\nquantity = "points.D.velocity.norm"\n'
                    'hand = "1.1597"\nunit = "m/s"\n[[value]]\nquantity = "points.D.velocity.norm"\n'
                    'hand = "1.2"\nunit = "mm/s"\n')
    values = load_hand_file(hand).values
    assert values[0].kind == "velocity" and values[0].component == "norm"
    ok, wrong = compare(to_dict(analyse(Scene.load(SCENES / "r_rtr.toml"))), values)
    assert ok.verdict == "ok" and wrong.verdict == "MISMATCH"
    [three_four] = compare({"points": {"D": {"velocity": [3.0, -4.0, 0.0]}}},
                           [HandValue("v", "points.D.velocity", "norm", "5.00", "m/s", "velocity")])
    assert three_four.verdict == "ok" and three_four.computed == 5.0


@pytest.mark.parametrize("slack", ["nan", "-1", "inf", "1e9"])
def test_a_slack_that_is_not_a_small_number_of_digits_is_refused(slack, capsys):
    from pinmech.cli import main
    from tests.conftest import SCENES

    assert main(["check", str(SCENES / "r_rtr.hand.toml"), "--slack", slack]) == 2
    assert "--slack must be a number from 0 to 100" in capsys.readouterr().err
    with pytest.raises(SceneError, match="slack must be"):
        compare({}, [], float(slack))


# ------------------------------------------------------------- a hand file checks what it says
def _hand_file(tmp_path, body: str, scene: str = "r_rtr.toml"):
    from tests.conftest import SCENES

    path = tmp_path / "h.hand.toml"
    path.write_text(f'scene = "{SCENES / scene}"\n{body}')
    return path


def _entry(quantity: str, hand: str, unit: str, extra: str = "") -> str:
    return f'[[value]]\nquantity = "{quantity}"\nhand = {hand}\nunit = "{unit}"\n{extra}'


def test_a_misspelled_values_table_is_refused_not_checked_as_nothing(tmp_path):
    path = _hand_file(tmp_path, _entry("points.D.velocity", '["0.386", "-0.282"]', "m/s").replace("[[value]]", "[[values]]"))
    with pytest.raises(SceneError, match=r"h\.hand\.toml, values: unknown key 'values' \(did you mean \[\[value\]\]\?\)"):
        load_hand_file(path)


def test_a_misspelled_key_of_a_value_is_refused(tmp_path):
    path = _hand_file(tmp_path, _entry("links.link3.angle", '["53.794"]', "deg", 'knd = "angle"\n'))
    with pytest.raises(SceneError, match=r"h\.hand\.toml, value\[0\]\.knd: unknown key 'knd' \(did you mean 'kind'\?\)"):
        load_hand_file(path)


@pytest.mark.parametrize("body", ["", "value = []\n", 'source = "p. 12"\n'])
def test_a_hand_file_with_nothing_to_check_is_an_error_not_a_pass(tmp_path, body):
    with pytest.raises(SceneError, match=r"h\.hand\.toml, value: no \[\[value\]\] to check"):
        load_hand_file(_hand_file(tmp_path, body))


def test_a_component_path_takes_one_printed_value(tmp_path):
    # v_D = (0.935792, -0.685048) m/s: a second "0.936" is not v_D,y and must not be labelled so.
    path = _hand_file(tmp_path, _entry("points.D.velocity.x", '["0.936", "0.936"]', "m/s"))
    with pytest.raises(SceneError, match=r"value\[0\]: 'points.D.velocity.x' is one component: give one printed "
                                         r"value, or list x, y \(, z\) on 'points.D.velocity'"):
        load_hand_file(path)


def test_a_list_of_values_on_a_number_of_the_result_is_refused():
    angle = {"links": {"L": {"angle": 0.938882}}}
    for component in (0, 1):
        with pytest.raises(SceneError, match=r"'links.L.angle' is a number, not a vector"):
            compare(angle, [HandValue(f"phi {component}", "links.L.angle", component, "53.79", "deg", "angle")])


def test_a_vector_has_no_fourth_component():
    with pytest.raises(SceneError, match=r"'points.B.position' has 2 components, no z"):
        compare({"points": {"B": {"position": [0.1, 0.2]}}}, [HandValue("z", "points.B.position", 2, "0", "m", "length")])


@pytest.mark.parametrize(
    "quantity, hand, unit, kind, message",
    [
        # m/s read as deg/s, rad/s as mm/s: each was "ok"
        ("points.D.velocity.x", '["53.62"]', "deg/s", "angular_velocity",
         (r"'points.D.velocity' is a velocity, not an angular velocity as kind = 'angular_velocity' and "
          r"unit = 'deg/s' say: give it in m/s \(or another velocity unit\)")),
        ("links.link3.angular_velocity.z", '["-7732"]', "mm/s", "velocity",
         (r"'links.link3.angular_velocity' is an angular velocity, not a velocity as kind = 'velocity' and "
          r"unit = 'mm/s' say: give it in rad/s")),
        ("points.D.position.x", '["0.1386"]', "m", "angle", r"'points.D.position' is a length, not an angle"),
        ("points.D.velocity", '["0.9", "0.1"]', "rpm", None,
         r"'points.D.velocity' is a velocity, not an angular velocity as unit = 'rpm' says"),
    ],
)
def test_a_unit_must_have_the_dimension_of_the_quantity(tmp_path, quantity, hand, unit, kind, message):
    extra = f'kind = "{kind}"\n' if kind else ""
    path = _hand_file(tmp_path, _entry(quantity, hand, unit, extra))
    with pytest.raises(UnitError, match=r"h\.hand\.toml, value\[0\]: " + message):
        load_hand_file(path)


def test_a_joint_coordinate_is_checked_in_the_joint_s_own_kind():
    # B_slider is prismatic: its q is a length, however kind and unit are declared.
    result = {"joints": {"B_slider": {"q": -0.061966, "v": 0.2112, "type": "prismatic"},
                         "A": {"q": 0.5236, "type": "continuous"}}}
    slider_in_degrees = HandValue("q", "joints.B_slider.q", None, "-3.4", "deg", "angle", file="h.toml", entry="value[1]")
    with pytest.raises(UnitError, match=r"h\.toml, value\[1\] \(q\): 'joints.B_slider.q' is a length \(joint B_slider is "
                                        r"prismatic\), not an angle as kind = 'angle' and unit = 'deg' say"):
        compare(result, [slider_in_degrees])
    crank_in_mm = HandValue("q", "joints.A.q", None, "523.6", "mm", "length")
    with pytest.raises(UnitError, match=r"'joints.A.q' is an angle \(joint A is continuous\)"):
        compare(result, [crank_in_mm])
    right = [HandValue("q", "joints.B_slider.q", None, "-61.97", "mm", "length"),
             HandValue("v", "joints.B_slider.v", None, "0.2112", "m/s", "velocity"),
             HandValue("q", "joints.A.q", None, "30.00", "deg", "angle")]
    assert [v.verdict for v in compare(result, right)] == ["ok", "ok", "ok"]


def test_hand_file_errors_name_the_hand_file_and_the_unit_as_written(tmp_path):
    path = _hand_file(tmp_path, _entry("points.D.velocity", '["0.9", "0.1"]', "rpm"))
    with pytest.raises(UnitError, match=r"^\S*h\.hand\.toml, value\[0\]: .*unit = 'rpm' says") as raised:
        load_hand_file(path)
    assert "'1 rpm'" not in str(raised.value)
    path = _hand_file(tmp_path, _entry("points.DD.velocity", '["0.9", "0.1"]', "m/s"))
    hand = load_hand_file(path)
    with pytest.raises(SceneError, match=r"^\S*h\.hand\.toml, value\[0\] \(points.DD.velocity x\): 'points.DD.velocity': "
                                         r"no 'DD' in the result \(has A, B\)"):
        compare({"points": {"A": {}, "B": {}}}, hand.values)
    path = _hand_file(tmp_path, _entry("points.D.velocity", '["0.9", "0.1"]', "blorps/s"))
    with pytest.raises(UnitError, match=r"^\S*h\.hand\.toml, value\[0\]\.unit: cannot read quantity 'blorps/s'"):
        load_hand_file(path)


def test_a_missing_scene_is_named_with_the_hand_file(tmp_path):
    path = tmp_path / "h.hand.toml"
    path.write_text('scene = "nope.toml"\n' + _entry("points.D.velocity", '["0.9", "0.1"]', "m/s"))
    with pytest.raises(SceneError, match=r"h\.hand\.toml, scene: scene = 'nope.toml': no such scene file \(.*nope\.toml\)"):
        load_hand_file(path)


NOT_QUANTITIES = [  # a result path that holds no quantity of a unit, the kind a hand file claims, and a word said
    ("assembly.C.sign", "velocity", "m/s", "pure number"),
    ("accuracy.condition_number", "length", "m", "pure number"),
    ("accuracy.newton_iterations", "time", "s", "pure number"),
    ("route.continuation_steps", "angle", "deg", "pure number"),
]


@pytest.mark.parametrize(("quantity", "kind", "unit", "said"), NOT_QUANTITIES)
def test_a_dimensionless_result_is_not_checked_as_a_quantity_of_a_unit(quantity, kind, unit, said, tmp_path,
                                                                       scenes_dir):
    """The assembly sign (+1 or -1) was "checked" as a velocity in m/s and called ok: a
    declared kind is trusted only where pinmech cannot tell the quantity's kind (a joint's
    q, v, a), and it must agree with the result's; a pure number is refused."""
    scene = tmp_path / "r_rtr.toml"
    scene.write_text((scenes_dir / "r_rtr.toml").read_text().replace('"../', f'"{scenes_dir.parent}/'))
    hand = tmp_path / "h.toml"
    hand.write_text(f'scene = "r_rtr.toml"\n[[value]]\nquantity = "{quantity}"\nhand = "-1"\nunit = "{unit}"\n'
                    f'kind = "{kind}"\n', encoding="utf-8")
    with pytest.raises(SceneError, match=said) as caught:
        values = load_hand_file(hand).values
        compare(to_dict(analyse(Scene.load(scene))), values)
    assert str(hand) in str(caught.value) and quantity in str(caught.value)


def test_a_route_value_is_checked_in_its_driver_joints_kind(tmp_path, scenes_dir):
    """route.from.A is the driver A's angle where the pose was reached from: an angle (30
    deg in the R-RTR scene), so a length unit is refused and degrees are checked."""
    scene = tmp_path / "r_rtr.toml"
    scene.write_text((scenes_dir / "r_rtr.toml").read_text().replace('"../', f'"{scenes_dir.parent}/'))
    result = to_dict(analyse(Scene.load(scene)))
    good = HandValue("start", "route.from.A", None, "30", "deg", "angle")
    assert compare(result, [good])[0].verdict == "ok"
    with pytest.raises(UnitError, match="is an angle"):
        compare(result, [HandValue("start", "route.from.A", None, "30", "mm", "length")])
