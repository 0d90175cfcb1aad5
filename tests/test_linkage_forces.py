"""Forces on linkages drawn in TOML (pinmech/model/linkage_urdf.py): the drawing gives no masses,
so forces name the links that need one; declared massless, statics is virtual work."""

from __future__ import annotations

import math
from pathlib import Path

import closed_form as cf
import numpy as np
import pytest

import pinmech
from pinmech.exceptions import ModelError

LINKAGES = Path(__file__).resolve().parents[1] / "models" / "linkages"


def _scene(tmp_path: Path, linkage: str, driver: str, extra: str = "") -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(f'linkage = "{(LINKAGES / linkage).as_posix()}"\n[drivers.{driver}]\nangle = "60 deg"\n'
                    f'speed = "30 rpm"\n{extra}', encoding="utf-8")
    return path


@pytest.mark.parametrize(("linkage", "driver", "links"), [
    ("four_bar.toml", "O2", ["crank", "coupler", "rocker"]),
    ("inverted_slider_crank.toml", "A", ["crank", "guide"]),
    ("rsur.toml", "R1", ["crank", "coupler", "rocker"]),
])
def test_forces_on_a_drawing_name_the_links_without_mass(tmp_path, linkage, driver, links):
    """A drawing has no masses: a torque from placeholder masses would be a number nobody
    gave. Forces are refused up front, naming the links (exit 3 on the command line)."""
    gravity = '[gravity]\nacceleration = "9.81 m/s^2"\ndirection = [0, -1, 0]\n'
    scene = pinmech.Scene.load(_scene(tmp_path, linkage, driver, gravity))
    with pytest.raises(ModelError, match=r"have no mass under the linkage.s \[masses\]") as info:
        pinmech.analyse(scene)
    assert all(name in str(info.value) for name in links)


def test_a_massless_drawing_in_statics_is_virtual_work(tmp_path):
    """The drawn four-bar, every link massless, a torque T on the rocker, at rest: the crank
    holds it with tau = -T omega4 / omega2 (virtual work), the ratio from Norton's closed
    form. Tolerance 1e-9 of T: rounding and the closure tolerance (1e-13) only."""
    torque = 2.0
    extra = ('[forces]\nstatic = true\nmassless = ["crank", "coupler", "rocker"]\n'
             f'[[load]]\nname = "brake"\nlink = "rocker"\ntorque = "{torque} N*m"\n')
    analysis = pinmech.analyse(pinmech.Scene.load(_scene(tmp_path, "four_bar.toml", "O2", extra)))
    k = cf.four_bar(math.radians(60.0), 1.0, 0.0, 0.04, 0.12, 0.08, 0.10)
    np.testing.assert_allclose(analysis.forces.effort[0], -torque * float(k.omega4), rtol=0, atol=1e-9 * torque)
