"""Bad input, fuzzed: truncated and corrupted URDF and scene files, NaN and infinite values,
negative lengths, unknown names and units. Each ends in a documented error through the CLI:
one line on stderr, the exit code of its class, never a traceback, never a hang."""

from __future__ import annotations

import random
import subprocess
import sys

import pytest

from pinmech.cli import main

CODES = {3, 4, 5, 6, 7, 8}


def _run(argv, capsys):
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err
    return code, err


def _scene_for(tmp_path, urdf_name, body=None):
    scene = tmp_path / "s.toml"
    scene.write_text(body or (f'urdf = "{urdf_name}"\n[drivers.A]\nangle = "30 deg"\nspeed = "-50 rpm"\n'
                              '[guess]\nB = "20 deg"\nB_slider = "-60 mm"\n'))
    return scene


def _one_line_error(code, err):
    assert code in CODES | {0}, code
    if code:
        assert err.startswith("pinmech: error: ") and err.count("\n") == 1, err
        assert "Traceback" not in err


@pytest.mark.parametrize("fraction", [i / 17 for i in range(1, 17)])
def test_truncated_urdf(models_dir, tmp_path, capsys, fraction):
    text = (models_dir / "r_rtr.urdf").read_text()
    (tmp_path / "m.urdf").write_text(text[: int(len(text) * fraction)])
    code, err = _run(["solve", _scene_for(tmp_path, "m.urdf")], capsys)
    assert code == 3 and "m.urdf" in err
    _one_line_error(code, err)


@pytest.mark.parametrize("seed", range(40))
def test_corrupted_urdf_bytes(models_dir, tmp_path, capsys, seed):
    """Random bytes replaced: an error naming the file, or (if the flip was harmless) a result."""
    rng = random.Random(seed)
    data = bytearray((models_dir / "r_rtr.urdf").read_bytes())
    for _ in range(5):
        data[rng.randrange(len(data))] = rng.choice(b'<>"/= 0123456789.-eanxyz\x00\xff')
    (tmp_path / "m.urdf").write_bytes(bytes(data))
    code, err = _run(["solve", _scene_for(tmp_path, "m.urdf")], capsys)
    _one_line_error(code, err)


@pytest.mark.parametrize("fraction", [i / 11 for i in range(1, 11)])
def test_truncated_scene(models_dir, tmp_path, capsys, fraction):
    (tmp_path / "r_rtr.urdf").write_text((models_dir / "r_rtr.urdf").read_text())
    full = (models_dir / "scenes" / "r_rtr.toml").read_text().replace("../r_rtr.urdf", "r_rtr.urdf")
    scene = _scene_for(tmp_path, "", full[: int(len(full) * fraction)])
    code, err = _run(["solve", scene], capsys)
    _one_line_error(code, err)


@pytest.mark.parametrize(
    "replace, code, message",
    [
        (('<origin xyz="0.10 0 0" rpy="0 0 0"/>', '<origin xyz="nan 0 0" rpy="0 0 0"/>'), 3, "Pinocchio cannot build"),
        (('<origin xyz="0.10 0 0" rpy="0 0 0"/>', '<origin xyz="inf 0 0" rpy="0 0 0"/>'), 3, "Pinocchio cannot build"),
        (('<parent_origin xyz="0.05 0 0"', '<parent_origin xyz="nan 0 0"'), 3, "not three finite numbers"),
        (('<parent_origin xyz="0.05 0 0"', '<parent_origin xyz="-0.5 0 0"'), 0, ""),  # negative: a valid mirror
        (('<child link="link3"/>   <child_origin', '<child link="link9"/>   <child_origin'), 3, "names no link"),
        (('type="revolute">\n    <parent link="ground"/> <parent_origin', 'type="universal">\n    <parent link="ground"/> <parent_origin'),
         3, "is not one of"),
    ],
)
def test_bad_urdf_values(models_dir, tmp_path, capsys, replace, code, message):
    text = (models_dir / "r_rtr.urdf").read_text()
    assert replace[0] in text
    (tmp_path / "m.urdf").write_text(text.replace(replace[0], replace[1], 1))
    got, err = _run(["solve", _scene_for(tmp_path, "m.urdf")], capsys)
    assert got == code and message in err
    _one_line_error(got, err)


@pytest.mark.parametrize(
    "override, code, message",
    [
        ('drivers.A.angle="nan deg"', 4, "not a finite number"),
        ('drivers.A.speed="inf rpm"', 4, "not a finite number"),
        ('drivers.A.angle="30 parsecs"', 4, "no angle unit"),
        ('drivers.A.angle="30 blorps"', 4, "cannot read quantity"),
        ('drivers.A.speed=12', 4, "has no unit"),
        ('drivers.Q.angle="1 deg"', 4, "unknown joint"),
        ('guess.Q="1 deg"', 4, "unknown joint"),
        ('lock.B="10 deg"', 5, "mobility 0"),
        ('lock.A="10 deg"', 4, "both driven and locked"),
        ('points.B3.link="link9"', 4, "unknown link 'link9'"),
        ('report.points=["Z"]', 4, "unknown point or frame 'Z'"),
        ('solver.max_iterations=0', 4, "positive number"),
    ],
)
def test_bad_scene_values(r_rtr_scene, capsys, override, code, message):
    got, err = _run(["solve", r_rtr_scene, "--set", override], capsys)
    assert got == code, err
    assert message in err
    _one_line_error(got, err)


def test_no_input_hangs_and_the_installed_command_prints_one_line(tmp_path):
    """A truncated URDF through the real executable, with a time limit."""
    (tmp_path / "m.urdf").write_text("<robot name='x'><link name='a'><visual><geometry><box size='1 1")
    scene = _scene_for(tmp_path, "m.urdf")
    run = subprocess.run([sys.executable, "-m", "pinmech", "solve", str(scene)],
                         capture_output=True, text=True, timeout=60, check=False)
    assert run.returncode == 3
    assert run.stderr.count("\n") == 1 and "Traceback" not in run.stderr
