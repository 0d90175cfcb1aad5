"""The `pinmech` command: reports, JSON schema, one-line errors and documented exit codes."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

from pinmech.cli import main
from tests.tolerance import rounding


def test_solve_prints_the_textbook_report(r_rtr_scene, capsys):
    assert main(["solve", str(r_rtr_scene)]) == 0
    out = capsys.readouterr().out
    order = ["Positions", "Link angles", "Angular velocities", "Velocities of points",
             "Accelerations of points", "Sliders", "Joints", "Accuracy"]
    positions = [out.index(h) for h in order]
    assert positions == sorted(positions)
    assert "phi =  53.794 deg" in out
    assert "a_cor = 2 omega x v_rel = ( 2.63576, -1.92951) m/s^2" in out
    assert "(-50 rpm)" in out


def test_solve_json_schema(r_rtr_scene, capsys):
    assert main(["solve", str(r_rtr_scene), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert set(result["joints"]) == {"A", "B", "B_slider"}
    assert set(result["points"]) == {"A", "B", "B3", "C", "D"}
    assert set(result["links"]) >= {"link1", "link2", "link3"}
    slider = result["sliders"]["B_slider"]
    assert (slider["parent"], slider["child"]) == ("link2", "link3")
    assert set(slider) >= {"relative_velocity", "relative_acceleration", "coriolis_acceleration"}
    for point in result["points"].values():
        assert all(len(point[k]) == 3 for k in ("position", "velocity", "acceleration"))
    assert set(result["accuracy"]) >= {"closure_residual", "newton_iterations", "condition_number"}
    assert result["joints"]["A"]["q"] == pytest.approx(math.pi / 6)
    assert result["joints"]["A"]["v"] == pytest.approx(-50 * math.pi / 30)


def test_angle_and_speed_from_the_command_line(r_rtr_scene, capsys):
    assert main(["solve", str(r_rtr_scene), "--json", "--angle", "90 deg", "--speed", "100 rpm"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["points"]["B"]["position"][:2] == pytest.approx([0.0, 0.1], abs=rounding(0.1))
    assert result["joints"]["A"]["v"] == pytest.approx(100 * math.pi / 30)


def test_check_exits_one_on_the_misprinted_velocity(scenes_dir, capsys):
    assert main(["check", str(scenes_dir / "r_rtr.hand.toml")]) == 1
    out = capsys.readouterr().out
    assert "35 ok, 11 within rounding, 2 mismatch" in out


@pytest.mark.parametrize(
    "argv, code, message",
    [
        (["solve", "nope.toml"], 4, "nope.toml: no such scene file"),
        (["solve", "{scene}", "--angle", "30"], 4, "'30' has no unit"),
        (["solve", "{scene}", "--set", "drivers.Z.angle='1 deg'"], 4, "unknown joint"),
        (["solve", "{scene}", "--set", "guess.B='0 deg'", "--set", "guess.B_slider='0 mm'",
          "--angle", "0 deg"], 0, ""),
        (["check", "nope.toml"], 4, "no such hand-value file"),
    ],
)
def test_errors_are_one_line_with_their_exit_code(r_rtr_scene, capsys, argv, code, message):
    argv = [a.replace("{scene}", str(r_rtr_scene)) for a in argv]
    assert main(argv) == code
    err = capsys.readouterr().err
    if code:
        assert err.startswith("pinmech: error: ") and err.count("\n") == 1
        assert message in err
    else:
        assert err == ""


def test_installed_command_prints_no_traceback(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('urdf = "missing.urdf"\n[drivers.A]\nangle = "1 deg"\n')
    run = subprocess.run([sys.executable, "-m", "pinmech", "solve", str(bad)], capture_output=True, text=True, timeout=60)
    assert run.returncode == 3
    assert "Traceback" not in run.stderr
    assert run.stderr.strip().endswith('is not a file')


def test_help_lists_the_subcommands(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    assert "solve" in out and "check" in out and "Exit codes" in out


def test_snapshot_animate_and_view_commands(scenes_dir, tmp_path, monkeypatch, capsys):
    pytest.importorskip("meshcat", reason='drawing needs pip install "pinmech[viz]"')
    scene = str(scenes_dir / "r_rtr.toml")
    assert main(["snapshot", scene, "-o", str(tmp_path / "s.html"), "--arrows", "D.velocity", "D.acceleration"]) == 0
    assert main(["animate", scene, "-o", str(tmp_path / "a.html"), "--steps", "5"]) == 0
    assert (tmp_path / "s.html").stat().st_size > 500_000 and (tmp_path / "a.html").stat().st_size > 500_000
    assert main(["snapshot", scene, "-o", str(tmp_path / "x.html"), "--arrows", "Q.speed"]) == 2
    assert "expected POINT.velocity" in capsys.readouterr().err
    monkeypatch.setattr("builtins.input", lambda prompt="": "")
    assert main(["view", scene]) == 0
    assert "http://127.0.0.1:" in capsys.readouterr().out
