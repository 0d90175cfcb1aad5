"""Messages in the user's terms: every option that can come from a scene file or the
command line names where it came from (the file and the key, or the flag) and ends with
the exit code of its class (README, "Errors and exit codes": a scene's key is exit 4, a
flag a usage error, exit 2); units are named as people write them, not as pint's root
units; each file is called by its kind (URDF, MJCF, linkage file).

Each case runs `pinmech.cli.main` and asserts the contract of an error: its exit code,
one line on stderr naming the file (and key), no traceback.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from pinmech.cli import main
from tests.conftest import MODELS, SCENES


def _copy(scene: str, tmp_path: Path) -> Path:
    """A bundled scene copied beside its model files' absolute paths (so it can be edited)."""
    text = (SCENES / scene).read_text(encoding="utf-8")
    for key in ("urdf", "mjcf", "linkage", "sidecar"):
        text = text.replace(f'{key} = "../', f'{key} = "{MODELS}/')
    out = tmp_path / scene
    out.write_text(text, encoding="utf-8")
    return out


def _error(capsys, argv: list[str]) -> tuple[int, str]:
    """Run the CLI; the exit code and the one line it printed on stderr."""
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err
    assert len(err.splitlines()) == 1, err
    return code, err


# ------------------------------------------------------------------ [sweep] keys
SWEEP_KEYS = [  # a [sweep] value, the key it must be blamed on, and words the message must hold
    ("sweep.steps=1", "sweep.steps", "at least 2"),
    ("sweep.interpolate=0", "sweep.interpolate", "at least 1"),
    ('sweep.from="2 m"', "sweep.from", "angle"),
    ('sweep.to="1"', "sweep.to", "no unit"),
]


@pytest.mark.parametrize(("override", "key", "words"), SWEEP_KEYS)
def test_a_bad_sweep_key_of_the_scene_is_blamed_on_the_file_and_key(override, key, words, tmp_path, capsys):
    """`[sweep] steps = 1` is the scene's mistake (exit 4, file and key), not `--steps`'s."""
    scene = _copy("r_rtr.toml", tmp_path)
    code, err = _error(capsys, ["sweep", str(scene), "--set", override])
    assert code == 4, err
    assert str(scene) in err and key in err and words in err, err
    assert " --" not in err, err  # no flag is blamed for the file's value


@pytest.mark.parametrize(("flags", "flag"), [(["--steps", "1"], "--steps"), (["--interpolate", "0"], "--interpolate"),
                                             (["--from", "2 m"], "--from")])
def test_a_bad_flag_is_blamed_on_the_flag(flags, flag, tmp_path, capsys):
    """The same value given as a flag is a usage error naming the flag (2), or a unit
    error naming it (4)."""
    scene = _copy("r_rtr.toml", tmp_path)
    code, err = _error(capsys, ["sweep", str(scene), *flags])
    assert code in (2, 4) and flag in err and "sweep." not in err, err


PATH_KEYS = [
    ('sweep.scheme="rk5"', "sweep.scheme", "euler, taylor, rk4"),
    ("sweep.gain=-1", "sweep.gain", "from 0"),
    ('sweep.duration="-1 s"', "sweep.duration", "positive"),
    ('sweep.step="1 s"', "sweep.step", "sweep.duration"),
    ('sweep.duration="0 s"', "sweep.duration", "positive"),
]


@pytest.mark.parametrize("command", ["path", "sweep"])
@pytest.mark.parametrize(("override", "key", "words"), PATH_KEYS)
def test_a_bad_path_key_of_a_task_scene_is_a_scene_error(command, override, key, words, tmp_path, capsys):
    """A misspelt `scheme` (or a negative gain, a step longer than the duration) in the
    scene is exit 4 naming the file and the key; it was exit 8 (a task error) or 2 with
    "--step" named."""
    scene = _copy("planar_arm.toml", tmp_path)
    code, err = _error(capsys, [command, str(scene), "--set", override, "--csv", str(tmp_path / "p.csv")])
    assert code == 4, err
    assert str(scene) in err and key in err and words in err, err
    assert "--step" not in err and "--duration" not in err and "--gain" not in err, err


def test_a_bad_flag_of_a_path_is_blamed_on_the_flag(tmp_path, capsys):
    scene = _copy("planar_arm.toml", tmp_path)
    code, err = _error(capsys, ["path", str(scene), "--step", "1 s", "--csv", str(tmp_path / "p.csv")])
    assert code == 2 and "--step" in err and "sweep.step" not in err, err


def test_a_misspelt_rates_method_is_a_scene_error(tmp_path, capsys):
    """`[rates] method = "exactt"` is the scene's mistake: exit 4 naming rates.method (was 8)."""
    scene = _copy("ur5.toml", tmp_path)
    code, err = _error(capsys, ["solve", str(scene), "--set", 'rates.method="exactt"'])
    assert code == 4 and str(scene) in err and "rates.method" in err and "least_squares" in err, err


# ------------------------------------------------------------------ assemblies in words
@pytest.mark.parametrize(("scene", "start", "steps"), [("four_bar.toml", "cold", 73), ("jansen.toml", "cold", 73),
                                                       ("marghitu_slider_crank.toml", "warm", 7)])
def test_a_start_landing_on_another_assembly_is_named_by_its_loops_not_sign_tuples(scene, start, steps, capsys):
    """A cold or warm start that lands on the other assembly printed "((1,) instead of
    (-1,))": now the loops whose assembly changed, and each assembly in the report's words."""
    code, err = _error(capsys, ["sweep", str(SCENES / scene), "--start", start, "--steps", str(steps)])
    assert code == 10, err
    assert "instead of (" not in err and "(1,)" not in err and "(-1," not in err, err
    # named by its loops (the signature changed), or by the joints where the pose differs
    # from the one continuation reaches (same signature, another assembly)
    assert ("the other assembly of loop" in err and "the sweep's" in err) or (
        "on another assembly than the reference's" in err and "joint " in err), err


def test_a_warm_start_landing_on_a_dead_centre_is_an_assembly_error_not_a_traceback(capsys):
    """Warm starts along the Marghitu slider-crank at 5 deg steps land on a singular pose:
    an internal exception escaped as a traceback; now a named error (singular pose, 7, or
    no assembly to keep, 10) naming the driver value."""
    code, err = _error(capsys, ["sweep", str(SCENES / "marghitu_slider_crank.toml"), "--start", "warm",
                                "--steps", "73"])
    assert code in (7, 10) and "singular" in err and "A = " in err, err


# ------------------------------------------------------------------ files called by their kind
@pytest.mark.parametrize(("scene", "model", "kind"), [("four_bar_mjcf.toml", "mjcf/four_bar.xml", "the MJCF file"),
                                                     ("four_bar_drawn.toml", "linkages/four_bar.toml",
                                                      "the linkage file"),
                                                     ("four_bar.toml", "four_bar.urdf", "the URDF")])
@pytest.mark.parametrize("command", ["sweep", "snapshot"])
def test_an_output_over_the_model_file_names_the_file_by_its_kind(scene, model, kind, command, tmp_path, capsys):
    """An MJCF or linkage file about to be overwritten was called "the URDF"."""
    shutil.copytree(MODELS, tmp_path / "models")
    target = tmp_path / "models" / model
    before = target.read_bytes()
    flag = ["--csv", str(target)] if command == "sweep" else ["-o", str(target)]
    code, err = _error(capsys, [command, str(tmp_path / "models" / "scenes" / scene), *flag])
    assert code == 2 and f"would overwrite {kind}" in err, err
    assert target.read_bytes() == before


# ------------------------------------------------------------------ the API's numbers
def _not_real(nq: int) -> list:
    """Configurations that are not real numbers: complex, boolean (array and list), text."""
    return [np.full(nq, 0.5 + 0.1j), np.zeros(nq, dtype=bool), [True] + [0.0] * (nq - 1), np.array(["0"] * nq)]


def test_evaluate_motion_and_the_rate_solver_refuse_a_q_that_is_not_real():
    """A complex q was cast to its real part (numpy's ComplexWarning only) and a boolean q
    to 0 and 1, in silence: now a ModelError naming q and its type."""
    from pinmech import Mechanism, RateSolver, Task, evaluate_motion
    from pinmech.exceptions import ModelError

    mech = Mechanism.from_urdf(MODELS / "planar_arm.urdf")
    nq = mech.model.nq
    solver = RateSolver(mech, [Task("D", ("x", "y"), np.array([1.0, 0.0]), np.zeros(2))])
    for q in _not_real(nq):
        with pytest.raises(ModelError, match=r"q must be real numbers"):
            evaluate_motion(mech, mech.model.createData(), q, np.zeros(mech.model.nv), np.zeros(mech.model.nv))
        with pytest.raises(ModelError, match=r"q must be real numbers"):
            solver.solve(q)
    with pytest.raises(ModelError, match=r"velocity must be real numbers"):
        solver.solve(mech.neutral(), velocity=np.array([1.0 + 1j, 0.0]))


def test_the_loop_solver_refuses_driver_values_guesses_and_q_that_are_not_real():
    from pinmech import LoopSolver, Mechanism
    from pinmech.exceptions import PinmechError

    mech = Mechanism.from_urdf(MODELS / "four_bar.urdf")
    solver = LoopSolver(mech, ["O2"])
    for bad in ([True], np.array([0.5 + 0.5j]), [np.True_]):
        with pytest.raises(PinmechError, match="real numbers"):
            solver.solve(bad)
    q = solver.solve([0.5]).q
    for guess in _not_real(mech.model.nq):
        with pytest.raises(PinmechError, match="real numbers"):
            solver.solve([0.5], guess=guess)
        with pytest.raises(PinmechError, match="real numbers"):
            solver.rates(guess, [1.0], [0.0])
    v, _, _ = solver.rates(q, [1.0], [0.0])  # a real q is still served
    assert np.all(np.isfinite(v))


def test_a_sweep_refuses_boolean_and_complex_driver_values():
    from pinmech import Scene
    from pinmech.exceptions import ModelError
    from pinmech.io.sweep import Sweep

    sweep = Sweep.from_scene(Scene.load(SCENES / "four_bar.toml"))
    for values in ([0.1, True], [0.1, 0.2 + 0j], np.array([0.1, 0.2], dtype=complex)):
        with pytest.raises(ModelError, match="not a finite number|real numbers"):
            list(sweep.poses(values))


# ------------------------------------------------------------------ every subcommand, bad scene values
def _argv(command: str, scene: Path, tmp_path: Path) -> list[str]:
    out = {"snapshot": ["-o", str(tmp_path / "s.html")], "animate": ["-o", str(tmp_path / "a.html"), "--steps", "3"],
           "polygon": ["-o", str(tmp_path / "p.svg")], "report": ["-o", str(tmp_path / "r.html"), "--steps", "0"],
           "sweep": ["--steps", "3", "--csv", str(tmp_path / "s.csv")]}
    return [command, str(scene), *out.get(command, [])]


BAD_VALUES = [  # an override, the exit code of its class, and the key the message must name
    ('drivers.A.angle="30 blorps"', 4, "drivers.A.angle"),
    ('drivers.A.speed="2 rad/a"', 4, "drivers.A.speed"),
    ('drivers.A.angle="1,5 deg"', 4, "drivers.A.angle"),
    ('guess.NOPE="1 deg"', 4, "NOPE"),
    ("bogus=1", 4, "bogus"),
    ('assembly.C="left-ish"', 4, "assembly"),
    ('report.limits="loud"', 4, "report.limits"),
    ("solver.tol=1.0", 4, "solver.tol"),
]


@pytest.mark.parametrize("command", ["solve", "forces", "sweep", "snapshot", "animate", "polygon", "report", "view"])
@pytest.mark.parametrize(("override", "code", "key"), BAD_VALUES)
def test_every_subcommand_names_the_file_and_key_of_a_bad_scene_value(command, override, code, key, tmp_path, capsys):
    """Each subcommand that reads a scene: the documented exit code, one line on stderr, no
    traceback, the scene file and the key named; nothing written."""
    scene = _copy("r_rtr.toml", tmp_path)
    got, err = _error(capsys, [*_argv(command, scene, tmp_path), "--set", override])
    assert got == code and str(scene) in err and key in err, err
    assert not any(tmp_path.glob("*.html")) and not any(tmp_path.glob("*.svg"))


@pytest.mark.parametrize(("override", "key"), [('pose.A="50 a"', "pose.A"), ('task.0.velocity=["1 Nm", "0 m/s"]', "task"),
                                               ('rates.method="exactt"', "rates.method")])
@pytest.mark.parametrize("command", ["path", "sweep", "solve"])
def test_task_scene_commands_name_the_file_and_key(command, override, key, tmp_path, capsys):
    scene = _copy("planar_arm.toml", tmp_path)
    if command in ("path", "sweep") and key == "rates.method":
        pytest.skip("following a task in time takes no [rates] method")
    got, err = _error(capsys, [command, str(scene), "--set", override, "--csv", str(tmp_path / "p.csv")]
                      if command != "solve" else [command, str(scene), "--set", override])
    assert got == 4 and str(scene) in err and key in err, err


@pytest.mark.parametrize(("entry", "key", "words"), [
    ('quantity = "forces.drivers.O.effort"\nhand = "116.253"\nunit = "Nm"\nkind = "torque"', "value[0]", "N*m"),
    ('quantity = "points.B.velocity.x"\nhand = "1.0"\nunit = "m/a"', "value[0]", "year"),
])
def test_check_names_the_hand_file_and_entry_of_a_unit_in_pints_words(entry, key, words, tmp_path, capsys):
    """A hand file's unit "Nm" or "m/a": refused naming the hand file and its entry, in a
    user's words (N*m; 'a' is a year to pint)."""
    _copy("slider_crank_dynamic.toml", tmp_path)
    hand = tmp_path / "h.toml"
    hand.write_text(f'scene = "slider_crank_dynamic.toml"\n[[value]]\n{entry}\n', encoding="utf-8")
    got, err = _error(capsys, ["check", str(hand)])
    assert got == 4 and str(hand) in err and key in err and words in err, err
