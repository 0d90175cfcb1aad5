"""A published worked example of dynamic force analysis, checked at its printed precision.

Marghitu, "Mechanisms and Robots Analysis with MATLAB" (Springer 2009), ch. 4: the R-RRT
slider-crank (AB = BC = 1 m, 1 kg links, I = m (L^2 + h^2)/12, g = 10 m/s^2, 100 N on
the slider against its motion, crank at 45 deg and 1 rad/s) gives the joint force of the
crank on the rod in closed form: F12 = (-(400 + 7 sqrt 2)/4, (5/4)(84 + sqrt 2)) N. The
printed expressions are exact, so pinmech must meet them to rounding: 1e-12 relative to
the force (its own equation residual is ~1e-16; the inertias are the book's formula to
15 digits).
"""

from __future__ import annotations

import math

import pinmech
from pinmech.cli import main
from tests.tolerance import REGULAR, closure


def test_the_books_joint_force_of_the_crank_on_the_rod(scenes_dir):
    analysis = pinmech.analyse(pinmech.Scene.load(scenes_dir / "marghitu_slider_crank.toml"))
    F12 = analysis.forces.reactions["B"].force
    expected = (-(400 + 7 * math.sqrt(2)) / 4, 5 / 4 * (84 + math.sqrt(2)))
    size = math.hypot(*expected)
    assert abs(F12[0] - expected[0]) < closure(size, REGULAR)
    assert abs(F12[1] - expected[1]) < closure(size, REGULAR)


def test_pinmech_check_passes_the_published_values(scenes_dir, capsys):
    assert main(["check", str(scenes_dir / "marghitu_slider_crank.hand.toml")]) == 0
    assert "4 ok, 0 within rounding, 0 mismatch" in capsys.readouterr().out
