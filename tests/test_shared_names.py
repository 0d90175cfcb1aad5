"""Names shared between joints, bodies and sites (every MuJoCo Menagerie file names its
joints after their bodies): each route that looks a frame up by name finds the one meant.

The four-bar of models/mjcf/four_bar.xml with its joints named after their bodies and a
site named after the coupler body; references are the closed-form four-bar (Norton,
Design of Machinery, §4.5), derived apart from Pinocchio.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from closed_form import four_bar

from pinmech.cli import main

pytest.importorskip("matplotlib", reason='plots need pip install "pinmech[plot]"')

#: Places drawn [mm]: loops closed to 1e-13 of a 0.1 m mechanism: 1e-6 mm leaves 1e5.
PLACE_TOL_MM = 1e-6
#: The coupler's site, in the coupler body's frame (x along A -> B) [m].
SITE = np.array([0.06, 0.03])

_XML = """<mujoco model="shared names">
  <compiler angle="radian"/>
  <worldbody>
    <body name="crank">
      <joint name="crank" type="hinge" axis="0 0 1"/>
      <body name="coupler" pos="0.04 0 0" euler="0 0 0.6341838408240407">
        <joint name="coupler" type="hinge" axis="0 0 1"/>
        <site name="coupler" pos="0.06 0.03 0"/>
      </body>
    </body>
    <body name="rocker" pos="0.1 0 0" euler="0 0 1.0946772658831">
      <joint name="rocker" type="hinge" axis="0 0 1"/>
    </body>
  </worldbody>
  <equality><connect name="B" body1="coupler" body2="rocker" anchor="0.12 0 0"/></equality>
</mujoco>
"""


def _scene(tmp_path: Path) -> Path:
    (tmp_path / "fb.xml").write_text(_XML)
    scene = tmp_path / "fb.toml"
    scene.write_text('mjcf = "fb.xml"\n[drivers.crank]\nangle = "0 deg"\nspeed = "60 rpm"\n')
    return scene


def _site(theta_deg: np.ndarray) -> np.ndarray:
    """The coupler site [mm]: closed-form A and coupler angle theta3 (open assembly)."""
    fb = four_bar(np.radians(theta_deg), 0.0, 0.0, 0.04, 0.12, 0.08, 0.10)
    c, s = np.cos(fb.theta3), np.sin(fb.theta3)
    return 1000 * np.column_stack([fb.A[:, 0] + c * SITE[0] - s * SITE[1], fb.A[:, 1] + s * SITE[0] + c * SITE[1]])


def test_timing_marks_of_a_site_named_like_its_body_and_joint(tmp_path, figures):
    """`--timing-marks` on the site 'coupler' (also a body and a joint): marks at the
    closed-form site every 30 deg (it raised Pinocchio's "Several frames match")."""
    assert main(["sweep", str(_scene(tmp_path)), "--steps", "50", "--points", "coupler",
                 "--paths", str(tmp_path / "p.png"), "--timing-marks"]) == 0
    ax = figures[0].axes[0]
    (marks,) = [line for line in ax.get_lines() if line.get_gid() == "timing coupler"]
    labels = [t.get_text() for t in ax.texts if t.get_gid() == "timing coupler"]
    angles = sorted(float(a.rstrip("°")) for t in labels for a in t.split(", "))
    assert angles == list(range(0, 360, 30))
    np.testing.assert_allclose(np.column_stack(marks.get_data()), _site(np.array(angles)), rtol=0,
                               atol=PLACE_TOL_MM)


@pytest.mark.parametrize("model, section, name", [
    ('linkage = "{root}/models/linkages/watt.toml"', "drivers", "D"),   # a drawn loop's closing pin
    ('linkage = "{root}/models/linkages/watt.toml"', "lock", "B"),
    ('urdf = "{root}/models/four_bar.urdf"', "lock", "B"),              # a <constraint>
    ('urdf = "{root}/models/four_bar.urdf"', "drivers", "B"),
])
def test_a_loop_cut_named_as_a_joint_is_called_a_cut_in_the_scene(tmp_path, capsys, model, section, name):
    """Driving or locking a loop's cut said "unknown joint" (a [lock] blamed the generated or
    bundled model file): the scene's key is named, and the name is called a loop cut."""
    root = Path(__file__).resolve().parents[1]
    scene = tmp_path / "cut.toml"
    value = 'angle = "30 deg"' if section == "drivers" else ''
    body = f'[drivers.O2]\nangle = "30 deg"\n[lock]\n{name} = "3 deg"\n' if section == "lock" else \
        f'[drivers.{name}]\n{value}\n'
    scene.write_text(model.format(root=root) + "\n" + body)
    assert main(["solve", str(scene)]) == 4
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith(f"pinmech: error: {scene}")
    assert f"[{section}]) '{name}' is a loop cut" in err, err


def test_a_mobility_error_says_which_locks_took_the_freedoms(tmp_path, capsys):
    """The Watt six-bar (mobility 1) with O4 held by [lock] cannot move: the message said
    "mobility 0 (4 joint freedoms ...): drive that many joints", silent on the lock."""
    root = Path(__file__).resolve().parents[1]
    scene = tmp_path / "held.toml"
    scene.write_text(f'linkage = "{root}/models/linkages/watt.toml"\n[drivers.O2]\nangle = "30 deg"\n'
                     '[lock]\nO4 = "20 deg"\n')
    assert main(["solve", str(scene)]) == 5
    err = capsys.readouterr().err
    assert "once [lock] holds O4" in err and "it cannot move" in err, err


def test_a_pin_of_three_links_named_as_drawn_points_to_its_joints(tmp_path, capsys):
    """Jansen's pin A joins three links, so the model has A_lower and A_upper: `[guess] A`
    said only "unknown joint 'A'", leaving the newcomer to guess the split."""
    root = Path(__file__).resolve().parents[1]
    scene = tmp_path / "jansen.toml"
    scene.write_text(f'linkage = "{root}/models/linkages/jansen.toml"\n[drivers.O]\nangle = "60 deg"\n'
                     '[guess]\nA = "10 deg"\n')
    assert main(["solve", str(scene)]) == 4
    err = capsys.readouterr().err
    assert "did you mean A_lower or A_upper?" in err, err


@pytest.mark.parametrize("value", ['["+", "-"]', "{ a = 1 }"])
def test_an_assembly_sign_that_is_a_list_or_table_is_a_scene_error(tmp_path, capsys, value):
    """`[assembly] B = ["+", "-"]` raised TypeError (unhashable) out of pinmech."""
    root = Path(__file__).resolve().parents[1]
    scene = tmp_path / "asm.toml"
    scene.write_text(f'urdf = "{root}/models/four_bar.urdf"\n[drivers.O2]\nangle = "30 deg"\n[assembly]\nB = {value}\n')
    assert main(["solve", str(scene)]) == 4
    assert "use one of" in capsys.readouterr().err
