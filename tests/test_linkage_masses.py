"""Masses of a drawn linkage: forces from the masses its file states, never from invented ones.

Expected numbers come from outside pinmech: Newton-Euler written link by link
(scripts/closed_form_forces.py, Norton's matrix method) and the principle of virtual work on
the closed-form kinematics (scripts/closed_form.py). Tolerance: 1e-9 of the largest force or
torque in play, as tests/test_forces.py (the force equations' condition numbers stay below
1e3, rounding ~1e-13); an invented 1 kg link moves the answers by newtons.
"""

from __future__ import annotations

import math
from pathlib import Path

import closed_form as cf
import closed_form_forces as cff
import numpy as np
import pytest

from pinmech import ForceSolver, Scene, analyse
from pinmech.cli import main
from pinmech.exceptions import ModelError
from pinmech.model.linkage import parse_linkage
from pinmech.model.linkage_model import load_linkage
from tests.tolerance import rounding

ROOT = Path(__file__).resolve().parents[1]
LINKAGES = ROOT / "models" / "linkages"
R, L, E = 0.05, 0.15, 0.01  # the slider-crank of models/slider_crank_dynamic.urdf [m]
RTOL = 1e-9


def mm(x: float) -> str:
    return f'"{float(x) * 1000!r} mm"'


def slider_crank(folder: Path, masses: str = "") -> Path:
    """The offset slider-crank drawn with its crank along x (B on y = e), the rod's centre
    of mass 60 mm from A along AB, the crank's 20 mm from O (cff.SLIDER_CRANK_BODIES)."""
    B = np.array([R + math.sqrt(L * L - E * E), E])
    A = np.array([R, 0.0])
    G3 = A + 0.06 * (B - A) / L
    path = folder / "slider_crank.toml"
    path.write_text(f"""ground = ["O"]
[joints]
O = ["0 mm", "0 mm"]
A = [{mm(A[0])}, "0 mm"]
B = [{mm(B[0])}, {mm(B[1])}]
G2 = ["20 mm", "0 mm"]
G3 = [{mm(G3[0])}, {mm(G3[1])}]
[links]
crank = ["O", "A"]
rod = ["A", "B"]
piston = ["B"]
[sliders]
slide = {{ block = "piston", on = "ground", at = "B", along = "0 deg" }}
{masses}""")
    return path


STATED = """[masses]
crank = { mass = "0.4 kg", at = "G2", izz = "2e-4 kg*m^2" }
rod = { mass = "600 g", at = "G3", izz = "1.5e-3 kg*m^2" }
piston = { mass = "0.5 kg", at = "B", izz = "1e-4 kg*m^2" }
"""


def scene(folder: Path, linkage: Path, extra: str = "", deg: float = 45.0, rpm: float = 3000.0,
          driver: str = "O") -> Path:
    path = folder / "scene.toml"
    path.write_text(f'linkage = "{linkage}"\n[drivers.{driver}]\nangle = "{deg!r} deg"\nspeed = "{rpm!r} rpm"\n{extra}')
    return path


GRAVITY_AND_GAS = """[gravity]
acceleration = "9.81 m/s^2"
direction = [0, -1, 0]
[[load]]
name = "gas"
link = "piston"
force = ["-200 N", "0 N"]
"""


def force(f, joint: str, by: str, on: str) -> np.ndarray:
    """F_by,on [N] (x, y) from the reaction at `joint`, whichever way pinmech states it."""
    r = f.reactions[joint]
    assert {r.by, r.on} == {by, on}
    return r.force[:2] if (r.by, r.on) == (by, on) else -r.force[:2]


def test_forces_without_stated_masses_are_refused(tmp_path, capsys):
    """Every link carried 1 kg at its frame origin, nobody's: 'pinmech forces' printed
    torques from them, exit 0. Now one line naming the links and where masses go."""
    assert main(["forces", str(ROOT / "models/scenes/four_bar_drawn.toml"), "--static"]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "crank, coupler, rocker have no mass" in err and "[masses]" in err
    path = scene(tmp_path, slider_crank(tmp_path), GRAVITY_AND_GAS)
    assert main(["forces", str(path)]) == 3
    err = capsys.readouterr().err
    assert "have no mass" in err and all(link in err for link in ("crank", "rod", "piston"))


@pytest.mark.parametrize("deg", [45.0, 160.0, 290.0])
def test_stated_masses_give_the_newton_euler_forces(tmp_path, deg):
    """The drawn slider-crank with its masses stated (one in grams) at 3000 rpm, gravity and
    200 N of gas: the driver torque and every pin force are Norton's."""
    path = scene(tmp_path, slider_crank(tmp_path, STATED), GRAVITY_AND_GAS, deg=deg)
    f = analyse(Scene.load(path)).forces
    h = cff.slider_crank_forces(math.radians(deg), 100 * math.pi, 0.0, R, L, E, *cff.SLIDER_CRANK_BODIES,
                                gravity=(0.0, -9.81), load_B=(-200.0, 0.0))
    scale = float(np.abs(h.F12).max())
    np.testing.assert_allclose(f.effort[0], h.T, atol=RTOL * scale)
    np.testing.assert_allclose(force(f, "O", "ground", "crank"), h.F12, atol=RTOL * scale)
    np.testing.assert_allclose(force(f, "A", "crank", "rod"), h.F23, atol=RTOL * scale)
    np.testing.assert_allclose(force(f, "B", "rod", "piston"), h.F34, atol=RTOL * scale)
    np.testing.assert_allclose(force(f, "slide", "ground", "piston")[1], h.N14, atol=RTOL * scale)


def test_the_torque_from_stated_masses_meets_virtual_power(tmp_path):
    """T omega = sum of m a_G . v_G + I alpha omega - m g . v_G - F_gas . v_B, every term
    from the closed-form kinematics (no Newton-Euler, no pinmech)."""
    deg, omega = 75.0, 100 * math.pi
    path = scene(tmp_path, slider_crank(tmp_path, STATED), GRAVITY_AND_GAS, deg=deg)
    T = analyse(Scene.load(path)).forces.effort[0]
    th = math.radians(deg)
    k = cf.slider_crank(th, omega, 0.0, R, L, E)
    beta, w3, a3 = float(k.beta), float(k.omega_rod), float(k.alpha_rod)
    u2, u3 = np.array([math.cos(th), math.sin(th)]), np.array([math.cos(beta), math.sin(beta)])
    perp = cf.perp
    vA, aA = omega * R * perp(u2), -omega**2 * R * u2
    vG2, aG2 = omega * 0.02 * perp(u2), -omega**2 * 0.02 * u2
    vG3, aG3 = vA + w3 * 0.06 * perp(u3), aA + a3 * 0.06 * perp(u3) - w3**2 * 0.06 * u3
    vB, aB = np.array([float(k.v_B), 0.0]), np.array([float(k.a_B), 0.0])
    g = np.array([0.0, -9.81])
    power = sum(m * (a - g) @ v for m, a, v in ((0.4, aG2, vG2), (0.6, aG3, vG3), (0.5, aB, vB)))
    power += 1.5e-3 * a3 * w3 - np.array([-200.0, 0.0]) @ vB  # crank: alpha = 0; the piston does not turn
    np.testing.assert_allclose(T * omega, power, rtol=1e-10)  # the sum's rounding, a few 1e-14 of its terms


def test_massless_links_carry_only_the_loads(tmp_path):
    """[forces] massless = every link, with gravity on and a torque of 2 N m on the rocker of
    the drawn four-bar, in statics: by virtual work T2 = -M4 omega4/omega2 (Norton's closed
    form for the ratio). Before, the invented 1 kg links added their weights."""
    deg = 60.0
    extra = ('[forces]\nmassless = ["crank", "coupler", "rocker"]\nstatic = true\n'
             '[gravity]\nacceleration = "9.81 m/s^2"\ndirection = [0, -1, 0]\n'
             '[[load]]\nname = "brake"\nlink = "rocker"\nforce = ["0 N", "0 N"]\ntorque = "2 N*m"\n')
    path = scene(tmp_path, LINKAGES / "four_bar.toml", extra, deg=deg, rpm=0.0, driver="O2")
    T = analyse(Scene.load(path)).forces.effort[0]
    ratio = cf.four_bar(math.radians(deg), 1.0, 0.0, 0.04, 0.12, 0.08, 0.10, branch=+1).omega4
    np.testing.assert_allclose(T, -2.0 * ratio, rtol=1e-9)


def test_a_slot_block_needs_no_mass():
    """The drawn R-RTR's pin-in-slot hides a block, massless by construction (a slot's pin
    has no body of its own): with crank and guide declared massless nothing is missing (it
    was refused as 'B_block have no mass'). (Forces through the slot's slide, a prismatic
    loop cut, are a separate matter: issue 22, item 2.)"""
    mech = load_linkage(LINKAGES / "inverted_slider_crank.toml")
    assert "B_block" in mech.massless_links
    ForceSolver(mech, ["A"], massless=["crank", "guide"])  # raises on a missing mass
    with pytest.raises(ModelError, match=r"guide have no mass under the linkage's \[masses\]"):
        ForceSolver(mech, ["A"], massless=["crank"])


def test_a_link_listed_massless_with_a_stated_mass_is_refused(tmp_path, capsys):
    path = scene(tmp_path, slider_crank(tmp_path, STATED), '[forces]\nmassless = ["rod"]\nstatic = true\n')
    assert main(["forces", str(path)]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "rod listed in [forces] massless" in err and "0.6 kg" in err


def test_the_urdf_holds_the_stated_masses_only(tmp_path):
    """The generated URDF's inertials are the stated ones (mass, centre in the link's frame)."""
    import pinocchio as pin

    mech = load_linkage(slider_crank(tmp_path, STATED))
    masses = {n: mech.model.inertias[mech.model.frames[f].parentJoint] for n, f in mech.links.items() if n != "ground"}
    np.testing.assert_allclose([masses[n].mass for n in ("crank", "rod", "piston")], [0.4, 0.6, 0.5], rtol=rounding(1.0))
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.reference)
    rod = data.oMi[mech.model.frames[mech.links["rod"]].parentJoint]
    B = np.array([R + math.sqrt(L * L - E * E), E, 0.0])
    expected = np.array([R, 0.0, 0.0]) + 0.06 * (B - np.array([R, 0.0, 0.0])) / L
    np.testing.assert_allclose(rod.act(masses["rod"].lever), expected, atol=rounding(R + L))
    np.testing.assert_allclose(masses["rod"].inertia[2, 2], 1.5e-3, rtol=rounding(1.0))


@pytest.mark.parametrize("masses, words", [
    ('ground = { mass = "1 kg", at = "O", izz = "0 kg*m^2" }', "[masses] ground: names no moving link"),
    ('wheel = { mass = "1 kg", at = "O", izz = "0 kg*m^2" }', "[masses] wheel: names no moving link"),
    ('rod = { mass = "1 kg", at = "G3" }', "[masses] rod: give exactly at, izz, mass"),
    ('rod = { mass = "0.6", at = "G3", izz = "0 kg*m^2" }', "'0.6' has no unit"),
    ('rod = { mass = "0.6 N", at = "G3", izz = "0 kg*m^2" }', "is not a mass"),
    ('rod = { mass = "0 kg", at = "G3", izz = "0 kg*m^2" }', "a mass is positive"),
    ('rod = { mass = "-1 kg", at = "G3", izz = "0 kg*m^2" }', "a mass is positive"),
    ('rod = { mass = "1 kg", at = "Q", izz = "0 kg*m^2" }', "at = 'Q' is not a joint"),
    ('rod = { mass = "1 kg", at = ["1 mm", "2 mm", "3 mm"], izz = "0 kg*m^2" }', "is [x, y]"),
    ('rod = { mass = "1 kg", at = "G3", izz = "-1 kg*m^2" }', "negative"),
    ('rod = { mass = "1 kg", at = "G3", izz = "1 kg" }', "is not a moment of inertia"),
])
def test_a_bad_mass_is_a_named_error(tmp_path, masses, words):
    path = slider_crank(tmp_path, "[masses]\n" + masses + "\n")
    with pytest.raises(ModelError) as err:
        parse_linkage(path)
    assert str(path) in str(err.value) and words in str(err.value), str(err.value)


def test_a_spatial_linkage_states_the_whole_tensor(tmp_path):
    """In 3-D a lone izz would leave Ixx, Iyy to invention; a tensor breaking the triangle
    inequality (no body has it) is refused; a physical one is taken as written."""
    base = slider_crank(tmp_path).read_text().replace('O = ["0 mm", "0 mm"]', 'O = ["0 mm", "0 mm", "0 mm"]')
    path = tmp_path / "spatial.toml"
    path.write_text(base + '[masses]\nrod = { mass = "1 kg", at = "G3", izz = "1e-4 kg*m^2" }\n')
    assert not parse_linkage(path).spatial  # z = 0 written out and a planar izz: the planar linkage
    lifted = base.replace('O = ["0 mm", "0 mm", "0 mm"]', 'O = ["0 mm", "0 mm", "0 mm"]\nQ = ["0 mm", "0 mm", "5 mm"]')
    path.write_text(lifted + '[masses]\nrod = { mass = "1 kg", at = "G3", izz = "1e-4 kg*m^2" }\n')
    with pytest.raises(ModelError, match=r"\[masses\] rod: give exactly at, inertia, mass"):
        parse_linkage(path)
    tensor = '["1e-4 kg*m^2", "1e-4 kg*m^2", "3e-4 kg*m^2", "0 kg*m^2", "0 kg*m^2", "0 kg*m^2"]'
    path.write_text(base + f'[masses]\nrod = {{ mass = "1 kg", at = "G3", inertia = {tensor} }}\n')
    with pytest.raises(ModelError, match=r"\[masses\] rod: .* is no body's"):
        parse_linkage(path)
    path.write_text(base + f'[masses]\nrod = {{ mass = "1 kg", at = "G3", inertia = {tensor.replace("3e-4", "2e-4")} }}\n')
    stated = parse_linkage(path).masses["rod"]
    np.testing.assert_allclose(stated.inertia, np.diag([1e-4, 1e-4, 2e-4]), rtol=rounding(1.0))
