"""Forces from scenes and the command line: `[forces]`, `[gravity]`, `[[load]]`,
`pinmech forces`, `pinmech sweep --forces`, the JSON section, and every error as one line
with its exit code. Expected numbers come from the hand analysis of
scripts/closed_form_forces.py (Newton-Euler per link) and the closed-form kinematics."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import closed_form as cf
import closed_form_forces as cff
import numpy as np
import pytest

import pinmech
from pinmech.cli import main
from tests.tolerance import rounding

# The slider-crank's force equations over a sweep: condition numbers below 1e2 (as
# tests/test_forces.py states), each power balance to rounding times that.
FORCE_COND = 1e2

SCENES = Path(__file__).resolve().parents[1] / "models" / "scenes"
SCENE = SCENES / "slider_crank_dynamic.toml"
OMEGA = 3000 * np.pi / 30


def hand(deg: float, gas: float = -200.0, g: float = 9.81):
    return cff.slider_crank_forces(np.radians(deg), OMEGA, 0.0, 0.05, 0.15, 0.01, *cff.SLIDER_CRANK_BODIES,
                                   gravity=(0.0, -g), load_B=(gas, 0.0))


def test_forces_json_gives_the_hand_torque_and_pin_forces(capsys):
    """Tolerance 1e-9 of the largest pin force (see tests/test_forces.py: RTOL)."""
    assert main(["forces", str(SCENE), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)["forces"]
    h = hand(45.0)
    scale = np.abs(h.F12).max()
    assert out["drivers"]["O"] == {"effort": pytest.approx(h.T, abs=1e-9 * scale), "unit": "N m"}
    np.testing.assert_allclose(out["reactions"]["A"]["force"][:2], h.F23, atol=1e-9 * scale)
    np.testing.assert_allclose(out["reactions"]["B"]["force"][:2], h.F34, atol=1e-9 * scale)
    assert out["reactions"]["B"]["cut"] and (out["reactions"]["B"]["by"], out["reactions"]["B"]["on"]) == ("rod", "piston")
    assert out["reactions"]["slide"]["normal_force"][1] == pytest.approx(h.N14, abs=1e-9 * scale)
    assert out["reactions"]["O"]["angle"] == pytest.approx(np.arctan2(h.F12[1], h.F12[0]), abs=rounding(np.pi, out["condition_number"]))
    assert out["gravity"] == pytest.approx([0.0, -9.81, 0.0])
    assert out["power"]["residual"] < rounding(1.0, out["condition_number"]) and out["power"]["velocity"] == "actual"


def test_solve_reports_forces_only_when_the_scene_asks(capsys):
    assert main(["solve", str(SCENE)]) == 0
    text = capsys.readouterr().out
    assert "driver torque =  116.253 N m" in text and "gravity 9.81 m/s^2" in text and "power balance" in text
    assert main(["solve", str(SCENES / "slider_crank.toml"), "--json"]) == 0
    assert "forces" not in json.loads(capsys.readouterr().out)


def test_forces_on_a_kinematic_scene_say_gravity_is_off(capsys):
    assert main(["forces", str(SCENES / "slider_crank.toml")]) == 0
    text = capsys.readouterr().out
    assert "gravity off; loads: none" in text


def test_statics_gives_the_mechanical_advantage_of_virtual_work(capsys):
    """Gravity off, 200 N on the piston: tau = F dx_B/dtheta, so |F| / |tau| = 1 / |dx_B/dtheta|,
    with dx_B/dtheta = v_B / omega from the closed form."""
    for deg in (45.0, 120.0, 250.0):
        assert main(["forces", str(SCENE), "--static", "--json", "--angle", f"{deg} deg",
                     "--set", 'gravity.acceleration="0 m/s^2"']) == 0  # reached on the scene's assembly
        out = json.loads(capsys.readouterr().out)["forces"]
        ratio = float(cf.slider_crank(np.radians(deg), 1.0, 0.0, 0.05, 0.15, 0.01).v_B)
        assert out["mechanical_advantage"] == pytest.approx(1 / abs(ratio), rel=1e-10)
        assert out["drivers"]["O"]["effort"] == pytest.approx(200.0 * ratio, rel=1e-10)  # tau dtheta = -F dx_B
        assert out["power"]["velocity"] == "virtual" and out["power"]["residual"] < rounding(1.0, out["condition_number"])


def test_four_bar_statics_advantage_is_the_inverse_velocity_ratio_and_toggles_are_its_limits(capsys):
    """A torque T4 on the rocker, gravity off: tau2 = -T4 omega4 / omega2, so the advantage
    |T4| / |tau2| = |omega2 / omega4| (closed form, 1e-10); it vanishes where the rocker
    stops, at the limit positions, where crank and coupler are in line: |O2 B| = b +- a,
    B on the rocker's circle. The sweep reports those crank angles (printed to 4 digits,
    linear interpolation over 0.5 deg steps: 0.05 deg)."""
    scene, off = str(SCENES / "four_bar_dynamic.toml"), 'gravity.acceleration="0 m/s^2"'
    assert main(["forces", scene, "--static", "--json", "--set", off]) == 0
    out = json.loads(capsys.readouterr().out)["forces"]
    k = cf.four_bar(np.radians(60.0), 1.0, 0.0, 0.04, 0.12, 0.08, 0.10)
    assert out["mechanical_advantage"] == pytest.approx(abs(1.0 / float(k.omega4)), rel=1e-10)
    assert out["drivers"]["O2"]["effort"] == pytest.approx(0.5 * float(k.omega4), rel=1e-10)  # T4 = -0.5 N m
    assert main(["sweep", scene, "--static", "--set", off, "--steps", "721"]) == 0
    line = next(x for x in capsys.readouterr().err.splitlines() if "changes sign" in x)
    found = sorted(float(x) % 360 for x in line.split("near ")[1].replace(" deg", "").split(", "))
    a, b, c, d = 0.04, 0.12, 0.08, 0.10
    limits = []
    for reach, turn in ((b + a, 0.0), (b - a, 180.0)):
        x = (reach**2 - c**2 + d**2) / (2 * d)
        limits.append((np.degrees(np.arctan2(np.sqrt(reach**2 - x**2), x)) + turn) % 360)
    np.testing.assert_allclose(found, sorted(limits), atol=0.05)


def test_check_compares_hand_forces_at_their_printed_precision(capsys):
    """The hand file holds the Newton-Euler values as scripts/closed_form_forces.py prints
    them; every one is correctly rounded (within half a unit of its last digit)."""
    assert main(["check", str(SCENES / "slider_crank_dynamic.hand.toml")]) == 0
    assert "8 ok, 0 within rounding, 0 mismatch" in capsys.readouterr().out


def test_static_in_the_scene_is_the_static_flag(capsys):
    assert main(["forces", str(SCENE), "--json", "--static"]) == 0
    by_flag = json.loads(capsys.readouterr().out)["forces"]
    assert main(["forces", str(SCENE), "--json", "--set", "forces.static=true"]) == 0
    by_scene = json.loads(capsys.readouterr().out)["forces"]
    assert by_scene["static"] and by_scene["drivers"] == by_flag["drivers"]
    assert by_scene["power"]["kinetic_rate"] == 0.0


def test_python_api_carries_the_forces():
    analysis = pinmech.analyse(pinmech.Scene.load(SCENE))
    assert analysis.forces.effort[0] == pytest.approx(hand(45.0).T, rel=1e-9)
    assert analysis.forces.is_balanced(rounding(1.0, analysis.forces.condition))
    assert pinmech.analyse(pinmech.Scene.load(SCENES / "slider_crank.toml")).forces is None


def _rows(text: str) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(text)))


def test_sweep_adds_torque_and_reaction_columns_and_the_cycle_summary(capsys):
    """Each row's torque is the hand value at its angle. Over a full turn at constant speed
    with gravity and a constant load (all conservative) the mean torque is zero: the
    trapezoid rule on a smooth periodic curve is exact to rounding, so 1e-9 of the peak."""
    assert main(["sweep", str(SCENE), "--steps", "73"]) == 0
    captured = capsys.readouterr()
    rows = _rows(captured.out)
    assert len(rows) == 73
    for row in rows[::9]:
        deg = float(row["O.q [deg]"])
        h = hand(deg)
        assert float(row["O.torque [N*m]"]) == pytest.approx(h.T, abs=1e-9 * np.abs(h.F12).max())
        assert float(row["B.Fx [N]"]) == pytest.approx(h.F34[0], abs=1e-9 * np.abs(h.F12).max())
        assert float(row["slide.Ny [N]"]) == pytest.approx(h.N14, abs=1e-9 * np.abs(h.F12).max())  # signed
        assert abs(float(row["slide.Nx [N]"])) < 1e-9 * np.abs(h.F12).max()  # across a horizontal guide
        assert float(row["power_residual [1]"]) < rounding(1.0, FORCE_COND)
    summary = captured.err
    mean = float(summary.split("mean torque ")[1].split(" N m")[0])
    peak = max(abs(float(r["O.torque [N*m]"])) for r in rows)
    assert abs(mean) <= 1e-9 * peak
    assert "energy fluctuation" in summary and "coefficient of speed fluctuation" in summary
    assert "0.01 kg m^2 flywheel" in summary


def test_sweep_energy_fluctuation_matches_the_hand_torque_curve(capsys):
    """The summary's energy fluctuation equals that of the hand torque curve over the same
    poses (same trapezoid rule), to the printed precision."""
    assert main(["sweep", str(SCENE), "--steps", "181", "--flywheel", "0.02 kg*m^2"]) == 0
    err = capsys.readouterr().err
    got = float(err.split("energy fluctuation ")[1].split(" J")[0])
    theta = np.radians(np.linspace(45.0, 405.0, 181))
    expected = pinmech.energy_fluctuation(theta, [hand(np.degrees(t)).T for t in theta]).energy_fluctuation
    assert got == pytest.approx(expected, rel=5e-6)  # printed with 6 significant digits: half a unit
    coefficient = float(err.split("coefficient of speed fluctuation ")[1].split()[0])
    assert coefficient == pytest.approx(expected / (0.02 * OMEGA**2), rel=1e-3)  # printed with 4 digits


def test_sweep_json_lines_carry_forces(tmp_path, capsys):
    path = tmp_path / "out.jsonl"
    assert main(["sweep", str(SCENE), "--steps", "5", "--json", str(path)]) == 0
    lines = [json.loads(x) for x in path.read_text().splitlines()]
    assert len(lines) == 5 and all("forces" in x and "points" in x for x in lines)
    assert lines[0]["forces"]["drivers"]["O"]["effort"] == pytest.approx(hand(45.0).T, rel=1e-9)


def test_sweep_without_force_tables_has_no_force_columns(capsys):
    assert main(["sweep", str(SCENES / "slider_crank.toml"), "--steps", "3"]) == 0
    assert "torque" not in capsys.readouterr().out.splitlines()[0]
    assert main(["sweep", str(SCENES / "slider_crank.toml"), "--steps", "3", "--forces"]) == 0
    assert "O.torque [N*m]" in capsys.readouterr().out.splitlines()[0]


# --------------------------------------------------------------------- errors
def _scene(tmp_path: Path, extra: str, base: Path = SCENE) -> Path:
    text = base.read_text().replace('urdf = "../', f'urdf = "{base.parent.parent}/')
    path = tmp_path / "scene.toml"
    path.write_text(text + "\n" + extra)
    return path


@pytest.mark.parametrize(("extra", "code", "message"), [
    ('[[load]]\npoint = "B_pin"\nforce = ["2 N*m", "0 N"]\n', 4, "'2 N*m' is not a force"),
    ('[[load]]\npoint = "Q"\nforce = ["2 N", "0 N"]\n', 4, "unknown point (in [[load]] Q) 'Q'"),
    ('[[load]]\nlink = "crank"\ntorque = "3 N"\n', 4, "'3 N' is not a torque"),
    ('[[load]]\npoint = "B_pin"\n', 4, "give a force"),
    ('[[load]]\nforce = ["1 N", "0 N"]\n', 4, "say where the load acts"),
    ('[[load]]\nlink = "ground"\ntorque = "1 N*m"\n', 4, "is on the ground"),
    ('[[load]]\npoint = "B_pin"\nforce = ["1 N"]\n', 4, "list of 2 or 3 quantities"),
])
def test_load_errors_are_one_line(tmp_path, capsys, extra, code, message):
    assert main(["forces", str(_scene(tmp_path, extra))]) == code
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "scene.toml" in err


@pytest.mark.parametrize(("old", "new", "code", "message"), [
    ("direction = [0, -1, 0]", "", 4, "give acceleration"),
    ("direction = [0, -1, 0]", "direction = [0, 0, 0]", 4, "is not a direction"),
    ('acceleration = "9.81 m/s^2"', 'acceleration = "9.81 m/s"', 4, "is not an acceleration"),
    ('flywheel = "0.01 kg*m^2"', 'flywheel = "0.01 kg"', 4, "is not a moment of inertia"),
    ('flywheel = "0.01 kg*m^2"', 'fly = 1', 4, "unknown key(s) fly"),
    ('flywheel = "0.01 kg*m^2"', 'massless = ["nope"]', 4, "unknown link (in [forces] massless) 'nope'"),
    ('flywheel = "0.01 kg*m^2"', 'static = "yes"', 4, "must be true or false"),
])
def test_force_table_errors_are_one_line(tmp_path, capsys, old, new, code, message):
    path = tmp_path / "scene.toml"
    text = SCENE.read_text().replace('urdf = "../', f'urdf = "{SCENE.parent.parent}/')
    assert old in text
    path.write_text(text.replace(old, new))
    assert main(["forces", str(path)]) == code
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_missing_masses_name_the_links(tmp_path, capsys):
    urdf = (SCENE.parent.parent / "slider_crank_dynamic.urdf").read_text()
    start = urdf.index('<inertial><origin xyz="0.06 0 0"/>')
    urdf = urdf[:start] + urdf[urdf.index("</inertial>", start) + len("</inertial>"):]
    (tmp_path / "m.urdf").write_text(urdf)
    path = tmp_path / "scene.toml"
    path.write_text(SCENE.read_text().replace('urdf = "../slider_crank_dynamic.urdf"', 'urdf = "m.urdf"'))
    assert main(["forces", str(path)]) == 3
    err = capsys.readouterr().err
    assert "rod have no <inertial> mass" in err and err.count("\n") == 1
    path.write_text(path.read_text() + '\nmassless = ["rod"]\n')  # appended to [forces]
    assert main(["forces", str(path)]) == 0


def test_forces_on_a_task_scene_are_refused(capsys):
    assert main(["forces", str(SCENES / "planar_arm.toml")]) == 4
    assert "not for [[task]] scenes" in capsys.readouterr().err


def test_torque_plot_is_drawn(tmp_path, capsys):
    pytest.importorskip("matplotlib", reason='needs pip install "pinmech[plot]"')
    path = tmp_path / "torque.png"
    assert main(["sweep", str(SCENE), "--steps", "37", "--torque-plot", str(path)]) == 0
    assert path.stat().st_size > 10_000 and "figure written to" in capsys.readouterr().err


def test_failed_poses_leave_blank_force_cells(tmp_path, capsys):
    """The four-bar driven at its rocker cannot turn it fully: the poses out of reach are
    rows with their error and empty force cells; the others carry forces."""
    text = (SCENES / "four_bar_dynamic.toml").read_text().replace('urdf = "../', f'urdf = "{SCENES.parent}/')
    text = text.replace("[drivers.O2]", "[drivers.O4]").replace('angle = "60 deg"', 'angle = "100 deg"')
    text = text.replace('O4 = "100 deg"', 'O2 = "60 deg"')
    path = tmp_path / "rocker.toml"
    path.write_text(text)
    assert main(["sweep", str(path), "--steps", "37", "--skip-failures", "--start", "cold"]) == 0
    rows = _rows(capsys.readouterr().out)
    failed = [r for r in rows if r["pose"] == "failed"]
    solved = [r for r in rows if r["pose"] == "solved"]
    assert failed and solved
    assert all(r["O4.torque [N*m]"] == "" for r in failed)
    assert all(float(r["power_residual [1]"]) < rounding(1.0, FORCE_COND) for r in solved)


def test_a_sweeps_slider_normal_force_keeps_its_side(scenes_dir, tmp_path):
    """The CSV held |N| of the guide's normal force, its side lost (+700.756 N where the
    ground pushes the piston down, -700.756 N in y): now its components, the JSON's
    normal_force, to the printed digits."""
    import csv
    import json

    from pinmech.cli import main

    out, lines = tmp_path / "f.csv", tmp_path / "f.jsonl"
    assert main(["sweep", str(scenes_dir / "slider_crank_dynamic.toml"), "--steps", "5", "--csv", str(out),
                 "--json", str(lines)]) == 0
    rows = list(csv.DictReader(out.open()))
    for row, line in zip(rows, lines.read_text().splitlines()):
        want = json.loads(line)["forces"]["reactions"]["slide"]["normal_force"]
        got = [float(row["slide.Nx [N]"]), float(row["slide.Ny [N]"])]
        assert got == pytest.approx(want[:2], rel=1e-9, abs=1e-9)
    assert any(float(r["slide.Ny [N]"]) < 0 for r in rows)


@pytest.mark.parametrize("steps, resolved", [(5, False), (25, False), (73, True), (361, True)])
def test_the_energy_fluctuation_states_its_accuracy_or_is_not_given(scenes_dir, capsys, steps, resolved):
    """Against the fine sweep's value (1441 poses, whose own bound is 0.002 J): a stated
    'within about X J' holds, and poses too coarse for the curve give no number (5 poses
    gave 28.9 J where the curve holds 125.8, with nothing to say so)."""
    from pinmech.cli import main

    def summary(n: int) -> str:
        assert main(["sweep", str(scenes_dir / "slider_crank_dynamic.toml"), "--steps", str(n), "--csv",
                     "/dev/null"]) == 0
        return [line for line in capsys.readouterr().err.splitlines() if "energy fluctuation" in line][0]

    fine = float(summary(1441).split("energy fluctuation ")[1].split(" J")[0])
    line = summary(steps)
    if not resolved:
        assert f"not resolved by {steps} poses" in line and "more --steps" in line
        return
    value = float(line.split("energy fluctuation ")[1].split(" J")[0])
    bound = float(line.split("within about ")[1].split(" J")[0])
    assert abs(value - fine) <= bound


def test_a_sweep_through_a_fold_gives_no_mean_torque(scenes_dir, tmp_path, capsys):
    """The bundled dynamic four-bar driven at its rocker, past the rocker's extreme and back
    (--through-folds): the work over a net travel of nearly nothing made a mean torque of
    -3.5e8 N m and a speed fluctuation of 4e10. Now the summary says why there is none."""
    from pinmech.cli import main

    text = (scenes_dir / "four_bar_dynamic.toml").read_text()
    scene = tmp_path / "rocker.toml"
    model = (scenes_dir.parent / "four_bar_dynamic.urdf").as_posix()
    scene.write_text(f'title = "rocker-driven"\nurdf = "{model}"\n[drivers.O4]\nangle = "100 deg"\n'
                     'speed = "10 rpm"\n[guess]\nO2 = "127 deg"\nA = "-100 deg"\n'
                     + text[text.index("[gravity]"):])
    assert main(["sweep", str(scene), "--from", "120 deg", "--to", "137.3 deg", "--steps", "10", "--through-folds",
                 "--flywheel", "0.001 kg*m^2", "--csv", str(tmp_path / "f.csv")]) == 0
    err = capsys.readouterr().err
    assert "turned back at a fold" in err and "mean torque" not in err.replace("no mean torque", "")
    assert "coefficient of speed fluctuation" not in err


def test_forces_are_not_computed_on_interpolated_poses(scenes_dir, tmp_path, capsys):
    """--interpolate 4 with forces ended, pose after pose, in a BalanceError blaming 'a term
    the model holds': interpolated rates miss the loops' equations. Now refused before any
    pose is computed, saying why, and no file is written."""
    from pinmech.cli import main

    out = tmp_path / "f.csv"
    assert main(["sweep", str(scenes_dir / "slider_crank_dynamic.toml"), "--interpolate", "4", "--csv",
                 str(out)]) == 2
    err = capsys.readouterr().err
    assert "forces need solved poses" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_static_sweeps_json_lines_carry_the_mechanical_advantage(scenes_dir, tmp_path):
    """The CSV had the column, the JSON lines of the same sweep did not: now both, equal."""
    import csv
    import json

    from pinmech.cli import main

    out, lines = tmp_path / "s.csv", tmp_path / "s.jsonl"
    assert main(["sweep", str(scenes_dir / "four_bar_dynamic.toml"), "--static", "--steps", "5", "--csv", str(out),
                 "--json", str(lines)]) == 0
    column = [float(r["mechanical_advantage [1]"]) for r in csv.DictReader(out.open())]
    json_values = [json.loads(line)["forces"]["mechanical_advantage"] for line in lines.read_text().splitlines()]
    assert json_values == pytest.approx(column, rel=1e-9)


@pytest.mark.parametrize(("direction", "unit"), [
    ("[0, -1e200, 0]", (0.0, -1.0, 0.0)),          # its norm overflowed: gravity went off in silence
    ("[1e-200, 0, 0]", (1.0, 0.0, 0.0)),           # its norm underflowed: refused as [0, 0, 0]
    ("[0, -1e308, 1e308]", (0.0, -2**-0.5, 2**-0.5)),  # a NaN direction, refused with numpy's words
    ("[3e-320, -4e-320, 0]", (0.6, -0.8, 0.0)),    # subnormal components: still a 3-4-5 triangle
])
def test_a_gravity_direction_at_any_scale_is_its_unit_vector(tmp_path, direction, unit):
    """Issue 22 item 9: gravity is 9.81 m/s^2 along direction / |direction|, whatever the
    components' scale. The expected unit vectors are exact (0, +-1, 1/sqrt 2, 3-4-5), so the
    tolerance is a few units in the last place (rtol 1e-15)."""
    path = tmp_path / "scene.toml"
    text = SCENE.read_text().replace('urdf = "../', f'urdf = "{SCENE.parent.parent}/')
    path.write_text(text.replace("direction = [0, -1, 0]", f"direction = {direction}"))
    gravity = pinmech.force_settings(pinmech.Scene.load(path)).gravity
    np.testing.assert_allclose(gravity, 9.81 * np.array(unit), rtol=rounding(1.0), atol=1e-300)


def test_a_zero_gravity_direction_is_named_as_written(tmp_path, capsys):
    path = tmp_path / "scene.toml"
    text = SCENE.read_text().replace('urdf = "../', f'urdf = "{SCENE.parent.parent}/')
    path.write_text(text.replace("direction = [0, -1, 0]", "direction = [0.0, -0.0, 0]"))
    assert main(["forces", str(path)]) == 4
    assert "gravity.direction: [0.0, -0.0, 0] is not a direction" in capsys.readouterr().err
