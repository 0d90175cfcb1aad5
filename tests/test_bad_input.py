"""Bad input, fuzzed: truncated and corrupted URDF, scene and hand files, NaN and infinite
values, numbers out of floating-point range, unknown names and units, structural mistakes
in a URDF's loops. Each ends in a documented error through the CLI (`pinmech.cli.main`):
one line on stderr naming the file and the element or key, the exit code of its class,
never a traceback, and never a hang (every test here runs under a 20 s alarm).

Fuzzing is seeded: random.Random(seed) picks the bytes to change.
"""

from __future__ import annotations

import random
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from pinmech import exceptions
from pinmech.cli import main
from tests.conftest import MODELS, SCENES

CODES = {3, 4, 5, 6, 7, 8}


@pytest.fixture(autouse=True)
def no_hang():
    """Every test of this file must finish in 20 s (SIGALRM raises in the main thread)."""
    def hung(signum, frame):
        raise TimeoutError("pinmech hung on this input")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(20)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def _run(capsys, *argv) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


def _one_line_error(code: int, err: str, *names: str) -> None:
    """A documented exit code; if an error, one line naming what it is given to name."""
    assert code in CODES | {0}, (code, err)
    if code:
        assert err.startswith("pinmech: error: ") and err.count("\n") == 1, err
        assert "Traceback" not in err
        for name in names:
            assert name in err, (name, err)


@pytest.fixture
def copies(tmp_path):
    """The bundled models and scenes copied side by side: scenes name "m.urdf"-free paths."""
    for urdf in MODELS.glob("*.urdf"):
        shutil.copy(urdf, tmp_path / urdf.name)
    for scene in SCENES.glob("*.toml"):
        (tmp_path / scene.name).write_text(scene.read_text().replace("../", ""))
    return tmp_path


MECHANISMS = ["r_rtr", "four_bar", "slider_crank"]


# ------------------------------------------------------------------------------ URDF bytes
@pytest.mark.parametrize("name", MECHANISMS)
def test_urdf_truncated_at_every_97th_byte(copies, capsys, name):
    """Cut the file short everywhere along it: malformed XML, a link without its joint, a
    <constraint> without its child... each a ModelError (3) naming the file, or (cut in a
    trailing comment or element pinmech does not need) a result."""
    urdf = copies / f"{name}.urdf"
    text = urdf.read_bytes()
    for cut in range(0, len(text), 97):
        urdf.write_bytes(text[:cut])
        code, err = _run(capsys, "solve", copies / f"{name}.toml")
        _one_line_error(code, err, f"{name}.urdf")
        assert code in (0, 3, 4, 5, 6, 7), (cut, err)


@pytest.mark.parametrize("name", MECHANISMS)
@pytest.mark.parametrize("seed", range(12))
def test_urdf_bytes_flipped(copies, capsys, name, seed):
    rng = random.Random(seed)
    urdf = copies / f"{name}.urdf"
    data = bytearray(urdf.read_bytes())
    for _ in range(rng.randint(1, 8)):
        data[rng.randrange(len(data))] = rng.choice(b'<>"/= 0123456789.-eanixyz\x00\xff')
    urdf.write_bytes(bytes(data))
    code, err = _run(capsys, "solve", copies / f"{name}.toml")
    _one_line_error(code, err)


# ------------------------------------------------------------------------- scene bytes
@pytest.mark.parametrize("name", MECHANISMS + ["planar_arm"])
def test_scene_truncated_at_every_31st_byte(copies, capsys, name):
    scene = copies / f"{name}.toml"
    text = scene.read_bytes()
    for cut in range(0, len(text), 31):
        scene.write_bytes(text[:cut])
        code, err = _run(capsys, "solve", scene)
        _one_line_error(code, err, f"{name}.toml")


@pytest.mark.parametrize("name", MECHANISMS + ["planar_arm"])
@pytest.mark.parametrize("seed", range(12))
def test_scene_bytes_flipped(copies, capsys, name, seed):
    rng = random.Random(seed)
    scene = copies / f"{name}.toml"
    data = bytearray(scene.read_bytes())
    for _ in range(rng.randint(1, 6)):
        data[rng.randrange(len(data))] = rng.choice(b'[]"=. 0123456789-eanxyz\x00\xff#\n')
    scene.write_bytes(bytes(data))
    code, err = _run(capsys, "solve", scene)
    _one_line_error(code, err)


@pytest.mark.parametrize("name", ["r_rtr.hand", "planar_arm.hand"])
@pytest.mark.parametrize("seed", range(16))
def test_hand_file_bytes_flipped_or_cut(copies, capsys, name, seed):
    """A hand file: exit 0 or 1 (its verdicts), or a SceneError (4) on one line."""
    rng = random.Random(seed)
    hand = copies / f"{name}.toml"
    data = bytearray(hand.read_bytes())
    if seed % 2:
        data = data[: rng.randrange(len(data))]
    else:
        for _ in range(rng.randint(1, 6)):
            data[rng.randrange(len(data))] = rng.choice(b'[]"=. 0123456789-eanxyz\x00\xff#\n')
    hand.write_bytes(bytes(data))
    code = main(["check", str(hand)])
    err = capsys.readouterr().err
    if code not in (0, 1):
        _one_line_error(code, err)


# -------------------------------------------------------------------- URDF, by mistake
R_RTR_CUT = '<constraint name="C" type="revolute">'


def _r_rtr(copies, old: str, new: str) -> Path:
    urdf = copies / "r_rtr.urdf"
    text = urdf.read_text()
    assert old in text
    urdf.write_text(text.replace(old, new, 1))
    return copies / "r_rtr.toml"


LAUGHS = ('<!DOCTYPE robot [<!ENTITY a "aaaaaaaaaa">' + "".join(
    f'<!ENTITY {b} "{("&" + a + ";") * 10}">' for a, b in zip("abcdefgh", "bcdefghi")) + ']>\n<robot name="&i;">')


@pytest.mark.parametrize(
    "old, new, code, message",
    [
        ('<origin xyz="0.10 0 0" rpy="0 0 0"/>', '<origin xyz="nan 0 0" rpy="0 0 0"/>', 3, "Pinocchio cannot build"),
        ('<origin xyz="0.10 0 0" rpy="0 0 0"/>', '<origin xyz="inf 0 0" rpy="0 0 0"/>', 3, "Pinocchio cannot build"),
        ('<origin xyz="0.10 0 0" rpy="0 0 0"/>', '<origin xyz="1e300 0 0" rpy="0 0 0"/>', 3, "outside the 1e-50 to 1e+50 m"),
        ('<parent_origin xyz="0.05 0 0"', '<parent_origin xyz="nan 0 0"', 3, "not three finite numbers"),
        ('<parent_axis xyz="0 0 1"/>', '<parent_axis xyz="0 0 0"/>', 3, "is not a direction"),
        ('<parent_origin xyz="0.05 0 0"', '<parent_origin xyz="-0.5 0 0"', 0, ""),  # negative: a valid mirror
        ('<child link="link3"/>   <child_origin', '<child link="link9"/>   <child_origin', 3, "names no link"),
        ('<child link="link3"/>   <child_origin', '<child link="ground"/>   <child_origin', 5, "mobility 3"),
        (R_RTR_CUT, R_RTR_CUT.replace("revolute", "universal"), 3, 'type="universal" is not one of'),
        (R_RTR_CUT, R_RTR_CUT.replace("revolute", "fixed"), 5, "mobility 0 (3 joint freedoms, 3 independent closure"),
        ('<parent_origin xyz="0.05 0 0"', '<parent_origin xyz="0.05 0 0.01"', 6, "not in one plane"),
        ('<joint name="B_slider" type="prismatic">\n    <parent link="link2"/>',
         '<joint name="B_slider" type="prismatic">\n    <parent link="link3"/>', 3, "not connected to the tree"),
        ("</robot>", f'{R_RTR_CUT}<parent link="ground"/><child link="link3"/></constraint></robot>', 3,
         "two <constraint> elements share this name"),
        ('<?xml version="1.0"?>\n', '<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n',
         0, ""),  # declared but not used: harmless
        ('<robot name="r_rtr">', '<!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/passwd">]><robot name="&x;">', 3,
         "external entity"),
        ('<robot name="r_rtr">', LAUGHS, 3, "malformed XML"),  # a billion laughs: refused, not expanded
        # a misspelling inside <constraint> was skipped: origin 0 0 0, link 3 pinned at A, D 50 mm off
        ('<parent_origin xyz="0.05 0 0"', '<parent_orgin xyz="0.05 0 0"', 3, "unknown element <parent_orgin>"),
        ('<parent_origin xyz="0.05 0 0"', '<parent_origin xzy="0.05 0 0"', 3, 'unknown attribute xzy="0.05 0 0"'),
        (R_RTR_CUT, R_RTR_CUT.replace('type=', 'kind="pin" type='), 3, 'unknown attribute kind="pin"'),
        # a joint's zero axis: a numpy warning, then "out of reach for these dimensions" (exit 6)
        ('<axis xyz="1 0 0"/>', '<axis xyz="0 0 0"/>', 3, "the axis of joint B_slider is [0.0, 0.0, 0.0]"),
        # a direction at the edge of float: urdfdom's norm under- or overflows, the axis read as zero
        ('<axis xyz="1 0 0"/>', '<axis xyz="1e-200 0 0"/>', 3, 'xyz="1e-200 0 0" is a direction Pinocchio'),
        ('<axis xyz="1 0 0"/>', '<axis xyz="1e200 1e200 0"/>', 3, 'xyz="1e200 1e200 0" is a direction Pinocchio'),
        # urdfdom skips a misspelled element or attribute: the joint at the identity, the mass at zero
        ('<origin xyz="0.10 0 0" rpy="0 0 0"/>', '<orgin xyz="0.10 0 0" rpy="0 0 0"/>', 3,
         "unknown element <orgin>: did you mean <origin>?"),
        ('<origin xyz="0.10 0 0" rpy="0 0 0"/>', '<origin xzy="0.10 0 0" rpy="0 0 0"/>', 3, "did you mean xyz?"),
        ('<mass value="0.15"/>', '<mass vaule="0.15"/>', 3, '<link name="link3"> <inertial>'),
    ],
    ids=["nan origin", "inf origin", "1e300 origin", "nan cut origin", "zero axis", "negative length",
         "unknown link", "cut to itself", "unknown cut type", "over-constrained", "out of plane",
         "joint cycle", "duplicate cut", "unused external entity", "external entity", "billion laughs",
         "misspelled element", "misspelled attribute", "unknown constraint attribute", "zero joint axis",
         "tiny joint axis", "huge joint axis", "misspelled origin", "swapped xyz",
         "misspelled mass value"],
)
def test_urdf_mistakes(copies, capsys, old, new, code, message):
    got, err = _run(capsys, "solve", _r_rtr(copies, old, new))
    assert got == code, err
    assert message in err
    _one_line_error(got, err, "r_rtr.urdf")


@pytest.mark.parametrize("text, message", [
    ("", "malformed XML"),
    ("\x00\x01<robot>", "malformed XML"),
    ('<?xml version="1.0"?><robot name="x"></robot>', "No link elements"),
    ('<?xml version="1.0"?><robot name="x"><link name="ground"/></robot>', "no joint of the model moves"),
    ('<?xml version="1.0"?><links/>', "expected <robot>"),
])
def test_urdf_with_nothing_to_move(copies, capsys, text, message):
    (copies / "r_rtr.urdf").write_text(text)
    code, err = _run(capsys, "solve", copies / "r_rtr.toml")
    assert code == 3 and message in err
    _one_line_error(code, err, "r_rtr.urdf")


# ------------------------------------------------------------------------- scenes, by mistake
@pytest.mark.parametrize(
    "override, code, message",
    [
        ('drivers.A.angle="nan deg"', 4, "not a finite number"),
        ('drivers.A.speed="inf rpm"', 4, "not a finite number"),
        ('drivers.A.speed="1e308 rpm"', 4, "beyond the 1e+50 (SI)"),
        ('drivers.A.angle="30 parsecs"', 4, "no angle unit"),
        ('drivers.A.angle="30 blorps"', 4, "cannot read quantity"),
        ('drivers.A.speed=12', 4, "has no unit"),
        ('drivers.A.speed="12 m/s"', 4, "no angle unit"),
        ('drivers.Q.angle="1 deg"', 4, "unknown joint"),
        ('drivers={}', 5, "drive that many joints; the scene drives 0 (none)"),
        ('guess.Q="1 deg"', 4, "unknown joint"),
        ('guess.B_slider="20 deg"', 4, "is not a length"),
        ('lock.B="10 deg"', 5, "mobility 0"),
        ('lock.A="10 deg"', 4, "both driven and locked"),
        ('points.B3.link="link9"', 4, "unknown link (in [points.B3]) 'link9'"),
        ('points.B3.at="Z"', 4, "unknown point (in [points.B3] at) 'Z'"),
        ('report.points=["Z"]', 4, "unknown point or frame (in [report] points) 'Z'"),
        ('report.links=["Z"]', 4, "unknown link (in [report] links) 'Z'"),
        ('report.points=1', 4, "report.points: must be a list of names"),
        ('report.links=["link1", 2]', 4, "report.links: must be a list of names"),
        ('robot=["ur5"]', 4, "robot: must be a string"),
        ('title=3', 4, "title: must be a string"),
        ('solver.max_iterations=0', 4, "positive number"),
        ('solver.max_iterations=1000000000', 4, "outside [1, 1000]"),
        ('solver.max_iterations=2.7', 4, "must be a whole number"),  # was cut to 2 in silence
        ('solver.tol=inf', 4, "solver.tol = inf is outside [1e-16, 0.001]"),
        ('solver.tol=0.5', 4, "outside [1e-16, 0.001]"),
        ('solver.max_condition=0.5', 4, "outside [1, inf]"),
        ('solver.tol=1e-16', 0, ""),
        ('nonsense=1', 4, "unknown key(s) nonsense"),
    ],
)
def test_scene_mistakes(r_rtr_scene, capsys, override, code, message):
    got, err = _run(capsys, "solve", r_rtr_scene, "--set", override)
    assert got == code, err
    assert message in err
    _one_line_error(got, err, "r_rtr.toml")


def test_a_tolerance_tighter_than_rounding_says_so(scenes_dir, capsys):
    code, err = _run(capsys, "solve", scenes_dir / "slider_crank.toml", "--set", "solver.tol=1e-16")
    assert code in (0, 6)
    if code:
        assert "rounding level: the tolerance 1e-16 is tighter than floating point allows" in err


@pytest.mark.parametrize(
    "override, message",
    [
        ('rates.damping=[]', "rates.damping: must be a positive number"),
        ('rates.damping="-0"', "rates.damping: must be a positive number"),
        ('rates.max_condition={}', "rates.max_condition: must be a positive number"),
        # out of range: named by file and key like NaN is (before: the API's words, no file, no key;
        # 1e155 an OverflowError traceback, 1e154 denormal rates)
        ('rates.max_condition=0.5', "rates.max_condition: rates.max_condition = 0.5 is outside [1, inf]"),
        ('rates.damping=inf', "rates.damping: rates.damping = inf is outside [1e-05, 1e+50]"),
        ('rates.damping=1e155', "rates.damping: rates.damping = 1e+155 is outside [1e-05, 1e+50]"),
        ('rates.damping=1e-9', "rates.damping: rates.damping = 1e-09 is outside [1e-05, 1e+50]"),
        ('rates.method=1', "rates.method: must be a string"),
        ('move=[]', "move = [] leaves no joint to move"),
        ('task=[]', "task must be an array of tables"),
        ('pose.A="1e60 deg"', "beyond the 1e+50 (SI)"),
    ],
)
def test_task_scene_mistakes(scenes_dir, capsys, override, message):
    got, err = _run(capsys, "solve", scenes_dir / "planar_arm.toml", "--set", override)
    assert got == 4 and message in err
    _one_line_error(got, err, "planar_arm.toml")


def test_sweeping_a_scene_without_drivers(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(f'urdf = "{MODELS / "planar_arm.urdf"}"\n[pose]\nA = "10 deg"\n')
    code, err = _run(capsys, "sweep", scene, "--steps", "3")
    # what to add: the drivers to sweep, or (an arm at its [pose]) a task to follow in time
    assert code == 4 and "add a [drivers.JOINT]" in err and "[[task]]" in err and "pinmech path" in err
    _one_line_error(code, err, "s.toml")


@pytest.mark.parametrize("override", ["sweep.links=1", 'sweep.points=[1]'])
def test_sweep_lists_must_be_names(r_rtr_scene, capsys, override):
    code, err = _run(capsys, "sweep", r_rtr_scene, "--steps", "3", "--set", override)
    assert code == 4 and override.split("=")[0] in err and "must be" in err
    _one_line_error(code, err, "r_rtr.toml")


@pytest.mark.parametrize("tol", ["0", "1", "1e-300", "nan"])
def test_sweep_tolerance_range(r_rtr_scene, capsys, tol):
    code, err = _run(capsys, "sweep", r_rtr_scene, "--steps", "3", "--tol", tol)
    assert code == 2 and "--tol must be between 1e-16 and 0.001" in err


# --------------------------------------------------------------------- hand files, by mistake
@pytest.mark.parametrize(
    "entry, message",
    [
        ('quantity = "points.D.velocity"\nhand = []\nunit = "m/s"', "give one to three printed values"),
        ('quantity = "points.D.velocity"\nhand = ["1e999", "0"]\nunit = "m/s"', "not a finite number as printed"),
        ('quantity = "points.D.velocity"\nhand = ["1e-400", "0"]\nunit = "m/s"', "not a finite number as printed"),
        ('quantity = "points.D.velocity"\nhand = ["1", "0"]\nunit = "0"', "is not a unit"),
        ('quantity = "points.D.velocity"\nhand = ["1", "0"]\nunit = "blorps"', "cannot read quantity"),
        ('quantity = "joints.A.q"\nhand = ["1"]\nunit = "deg"\nkind = "temperature"', "kind = 'temperature' is not one of"),
        ('quantity = "points.D"\nhand = ["1"]\nunit = "m"\nkind = "length"', "is not a number of the result"),
        ('quantity = "points.Z.position"\nhand = ["1", "0"]\nunit = "m"', "no 'Z' in the result"),
        ('quantity = "links.link3.angle"\nhand = ["53.794"]\nunit = "deg"\nknd = "angle"',
         "unknown key 'knd' (did you mean 'kind'?)"),
        ('quantity = "points.D.velocity.x"\nhand = ["0.936", "0.936"]\nunit = "m/s"', "is one component"),
        ('quantity = "points.D.velocity.x"\nhand = ["53.62"]\nunit = "deg/s"\nkind = "angular_velocity"',
         "'points.D.velocity' is a velocity, not an angular velocity"),
        ('quantity = "joints.B_slider.q"\nhand = ["-3.4"]\nunit = "deg"\nkind = "angle"',
         "'joints.B_slider.q' is a length (joint B_slider is prismatic), not an angle"),
        ('quantity = "points.D.velocity"\nhand = ["0.9", "0.1"]\nunit = "rpm"', "unit = 'rpm' says"),
    ],
)
def test_hand_file_mistakes(copies, capsys, entry, message):
    hand = copies / "h.toml"
    hand.write_text(f'scene = "r_rtr.toml"\n[[value]]\n{entry}\n')
    code, err = _run(capsys, "check", hand)
    assert code == 4 and message in err, err
    _one_line_error(code, err, "h.toml")


@pytest.mark.parametrize(
    "values, message",
    [
        ("", "no [[value]] to check"),
        ('[[values]]\nquantity = "points.D.velocity"\nhand = ["0.9", "0.1"]\nunit = "m/s"\n',
         "unknown key 'values' (did you mean [[value]]?)"),
    ],
)
def test_a_hand_file_that_checks_nothing_does_not_pass(copies, capsys, values, message):
    hand = copies / "h.toml"
    hand.write_text(f'scene = "r_rtr.toml"\n{values}')
    code, err = _run(capsys, "check", hand)
    assert code == 4 and message in err, err
    _one_line_error(code, err, "h.toml")


def test_hand_file_values_must_be_tables(copies, capsys):
    hand = copies / "h.toml"
    hand.write_text('scene = "r_rtr.toml"\nvalue = ["points.D.velocity"]\n')
    code, err = _run(capsys, "check", hand)
    assert code == 4 and "values must be tables" in err
    _one_line_error(code, err, "h.toml")


def test_undecodable_hand_file(copies, capsys):
    (copies / "h.toml").write_bytes(b'scene = "r_rtr.toml"\n# \xff\xfe\n')
    code, err = _run(capsys, "check", copies / "h.toml")
    assert code == 4 and "malformed TOML" in err
    _one_line_error(code, err, "h.toml")


# ------------------------------------------------------------------------ the real command
def test_the_installed_command_prints_one_line(tmp_path):
    """The `pinmech` console script itself, on a truncated URDF, with a time limit."""
    (tmp_path / "m.urdf").write_text("<robot name='x'><link name='a'><visual><geometry><box size='1 1")
    scene = tmp_path / "s.toml"
    scene.write_text('urdf = "m.urdf"\n[drivers.A]\nangle = "30 deg"\n')
    command = Path(sys.executable).with_name("pinmech")
    argv = [str(command)] if command.exists() else [sys.executable, "-m", "pinmech"]
    run = subprocess.run([*argv, "solve", str(scene)], capture_output=True, text=True, timeout=60, check=False)
    assert run.returncode == 3
    assert run.stderr.count("\n") == 1 and "Traceback" not in run.stderr and "m.urdf" in run.stderr


def test_every_error_class_has_its_exit_code_documented():
    """The pinmech.cli package's docstring, `pinmech --help` and the docs' table (docs/reference/exit_codes.md,
    generated by scripts/docs_outputs.py) list the exit code of every error class
    (PinmechError and all its subclasses, DrawError of the drawing layer too)."""
    import pinmech.draw  # noqa: F401  (its DrawError)
    from pinmech import cli

    table = (MODELS.parent / "docs" / "_generated" / "exit_codes.md").read_text()
    assert "_generated/exit_codes.md" in (MODELS.parent / "docs" / "reference" / "exit_codes.md").read_text()
    classes, todo = [], [exceptions.PinmechError]
    while todo:
        classes.append(todo.pop())
        todo += classes[-1].__subclasses__()
    assert len(classes) >= 11
    for cls in classes:
        if cls is exceptions.SweepError:  # takes its cause's code
            continue
        if cls.__name__.startswith("_"):  # a private subclass (continuation's _Singular) is its public parent
            assert cls.exit_code == cls.__mro__[1].exit_code
            continue
        assert re.search(rf"\b{cls.exit_code} [a-z]", cli.__doc__), cls
        assert re.search(rf"\b{cls.exit_code} [A-Za-z]", cli.build_parser().epilog), cls
        assert re.search(rf"\| {cls.exit_code} \| `{cls.__name__}`", table), cls


@pytest.mark.parametrize("option", ["--csv", "--json"])
def test_an_output_file_that_cannot_be_written(r_rtr_scene, tmp_path, capsys, option):
    target = tmp_path / "no such folder" / "out.csv"
    code, err = _run(capsys, "sweep", r_rtr_scene, "--steps", "3", option, target)
    assert code == 2 and err.startswith("pinmech: error: ") and err.count("\n") == 1 and "no such folder" in err


# ---------------------------------------------------------------- the Python API's arguments
@pytest.fixture(scope="module")
def r_rtr_analysis():
    import pinmech

    return pinmech.analyse(pinmech.Scene.load(SCENES / "r_rtr.toml"))


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda q, v, a: (q[:2], v, a), r"q must be 5 finite numbers \(SI\), got shape \(2,\)"),
        (lambda q, v, a: (q.reshape(1, -1), v, a), r"q must be 5 finite numbers \(SI\), got shape \(1, 5\)"),
        (lambda q, v, a: (q, ["x"] * 3, a), "v must be real numbers .SI., got text"),
        (lambda q, v, a: (q, v, [0.0, float("nan"), 0.0]), "a must be 3 finite numbers.*non-finite"),
        (lambda q, v, a: (q, v, "0 0 0"), "a must be real numbers .SI., got text"),
    ],
)
def test_evaluate_motion_names_a_wrong_argument(r_rtr_analysis, change, message):
    from pinmech import ModelError, evaluate_motion

    m, sol = r_rtr_analysis.mechanism, r_rtr_analysis.solution
    with pytest.raises(ModelError, match=message):
        evaluate_motion(m, m.model.createData(), *change(sol.q, sol.v, sol.a))


def test_evaluate_motion_wants_a_data_of_the_model(r_rtr_analysis, models_dir):
    import pinocchio as pin

    from pinmech import Mechanism, ModelError, evaluate_motion

    m, sol = r_rtr_analysis.mechanism, r_rtr_analysis.solution
    other = Mechanism.from_urdf(models_dir / "four_bar.urdf").model.createData()
    for data in (None, other, pin.Model().createData()):
        with pytest.raises(ModelError, match="data must be a pin.Data of the mechanism's model"):
            evaluate_motion(m, data, sol.q, sol.v, sol.a)


@pytest.mark.parametrize("values, message", [(["30 deg"], "value 0 of A is '30 deg'"),
                                             ([0.1, float("inf")], "value 1 of A is inf"),
                                             ("30", "values of A must be numbers")])
def test_sweep_driver_values_must_be_numbers(values, message):
    import pinmech

    sweep = pinmech.Sweep.from_scene(pinmech.Scene.load(SCENES / "r_rtr.toml"))
    with pytest.raises(pinmech.ModelError, match=message):
        list(sweep.poses(values))


@pytest.mark.parametrize("call, message", [
    (lambda m: m.set_coordinate(m.neutral(), "B", "x"), "a coordinate must be a finite number"),
    (lambda m: m.set_coordinate(m.neutral(), "B", float("nan")), "a coordinate must be a finite number"),
])
def test_api_coordinates_must_be_numbers(call, message):
    from pinmech import Mechanism, ModelError

    with pytest.raises(ModelError, match=message):
        call(Mechanism.from_urdf(MODELS / "planar_arm.urdf"))


@pytest.mark.parametrize("value", ["30 deg", float("nan"), float("inf"), None, True])
def test_api_locked_values_must_be_finite_numbers(value):
    from pinmech import Mechanism, ModelError

    with pytest.raises(ModelError, match="locked joint 'B' must be held at a finite number"):
        Mechanism.from_urdf(MODELS / "planar_arm.urdf", locked={"B": value})


def test_api_points_given_as_one_string_are_refused():
    # "AB" would otherwise be read as the points "A" and "B".
    import numpy as np

    from pinmech import Mechanism, ModelError, evaluate_motion

    m = Mechanism.from_urdf(MODELS / "planar_arm.urdf")
    with pytest.raises(ModelError, match="points must be a list of names, got the string 'AB'"):
        evaluate_motion(m, m.model.createData(), np.zeros(3), np.zeros(3), np.zeros(3), points="AB")


def test_an_unknown_kind_of_quantity_is_a_unit_error():
    from pinmech import UnitError, to_si

    with pytest.raises(UnitError, match="unknown kind of quantity 'lengthh'"):
        to_si("1 m", "lengthh")


@pytest.mark.parametrize("extra, words", [
    (["--links", "nope", "--plot", "f.png"], "unknown link (in --links) 'nope'"),
    (["--points", "nope", "--plot", "f.png"], "unknown point (in --points) 'nope'"),
    (["--paths", "p.png", "--points", "nope"], "unknown point (in --points) 'nope'"),
])
def test_a_figure_asked_of_unknown_links_or_points_is_refused_before_the_sweep(tmp_path, models_dir, capsys,
                                                                               extra, words):
    """A name the figure cannot draw was a KeyError traceback (exit 1) after the sweep ran."""
    pytest.importorskip("matplotlib")
    argv = ["sweep", str(models_dir / "scenes" / "r_rtr.toml"), "--steps", "5"]
    argv += [str(tmp_path / x) if x.endswith(".png") else x for x in extra]
    assert main(argv) == 4
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not list(tmp_path.iterdir())


def _text_options() -> list[tuple[str, str, list[str]]]:
    """(subcommand, option, the subcommand's required options with a value) for every
    option of every subcommand that takes text."""
    import argparse

    from pinmech.cli.parser import SUBCOMMANDS, build_parser

    found = []
    for command in SUBCOMMANDS:
        sub = next(a for a in build_parser(command)._actions if isinstance(a, argparse._SubParsersAction))
        actions = sub.choices[command]._actions
        required = [[a.option_strings[-1], "out.html"] for a in actions if a.option_strings and a.required]
        for action in actions:
            if action.option_strings and action.nargs != 0 and action.choices is None and action.type in (None, str):
                others = [x for pair in required if pair[0] != action.option_strings[-1] for x in pair]
                found.append((command, action.option_strings[-1], others))
    return found


@pytest.mark.parametrize("command, option, required", _text_options())
@pytest.mark.parametrize("empty", ["", " "])
def test_an_empty_option_is_an_error_not_the_option_left_out(r_rtr_scene, capsys, command, option, required, empty):
    """--angle "" (an unset shell variable) solved the scene's own pose in silence, and
    --plot "" or --certify "" were dropped: every text option of every command, empty, is
    refused in one line naming it, before anything runs."""
    got, err = _run(capsys, command, r_rtr_scene, *required, option, empty)
    assert got == 2 and err == f"pinmech: error: {option} is empty: give it a value, or leave the option out\n"


def test_an_empty_name_in_a_list_option_is_refused(r_rtr_scene, capsys):
    got, err = _run(capsys, "sweep", r_rtr_scene, "--steps", "3", "--points", "A", "", "--paths", "p.png")
    assert got == 2 and err.startswith("pinmech: error: --points has an empty value in ['A', '']")
    assert err.count("\n") == 1


def test_an_empty_file_name_is_refused(capsys):
    got, err = _run(capsys, "solve", "")
    assert got == 2 and err == "pinmech: error: scene is empty: give it a value, or leave the option out\n"
