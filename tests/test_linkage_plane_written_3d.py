"""A planar linkage written in 3-D (a third "0 mm", the default axis +z written out) is the
planar linkage it draws: its ground pin's driver value is the crank's angle from world x.

Before, either made the file "spatial", whose joint coordinates count from the drawing: a
crank drawn at 30 deg and driven to "60 deg" stood at 90 deg, exit 0. References: the
closed-form four-bar (Norton, Design of Machinery, §4.5; scripts/closed_form.py), derived
apart from Pinocchio. Tolerance 1e-12 m: loops closed to 1e-13 of a 0.1 m mechanism.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from closed_form import four_bar

from pinmech.cli import main
from tests.tolerance import REGULAR, closure

PLACE_TOL_M = closure(0.1, REGULAR)
A, B, C, D = 0.04, 0.12, 0.08, 0.10  # crank, coupler, rocker, ground [m]

_FILE = """ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"{z}]
O4 = ["100 mm", "0 mm"{z}]
A  = {{ from = "O2", length = "40 mm", angle = "30 deg" }}
B  = {{ from = ["A", "O4"], lengths = ["120 mm", "80 mm"], side = "left" }}
[links]
crank   = ["O2", "A"]
coupler = ["A", "B"]
rocker  = ["O4", "B"]
{axes}
"""


@pytest.mark.parametrize("z, axes", [
    ("", ""),                                               # planar as written
    ("", "[axes]\nO2 = [0, 0, 1]"),                         # the default axis written out
    (', "0 mm"', ""),                                       # z = 0 written out
    (', "0 mm"', "[axes]\nO2 = [0, 0, 2]\nO4 = [0, 0, 1]"),
])
def test_a_planar_linkage_written_in_3d_is_driven_from_world_x(tmp_path, capsys, z, axes):
    (tmp_path / "fb.toml").write_text(_FILE.format(z=z, axes=axes))
    scene = tmp_path / "s.toml"
    scene.write_text('linkage = "fb.toml"\n[drivers.O2]\nangle = "60 deg"\n[report]\npoints = ["A", "B"]\n')
    assert main(["solve", str(scene), "--json"]) == 0
    points = json.loads(capsys.readouterr().out)["points"]
    fb = four_bar(np.radians([60.0]), 0.0, 0.0, A, B, C, D)  # B above O2-O4: the drawn (open) assembly
    np.testing.assert_allclose(points["A"]["position"], [A * math.cos(math.radians(60)),
                                                         A * math.sin(math.radians(60)), 0.0], rtol=0, atol=PLACE_TOL_M)
    np.testing.assert_allclose(points["B"]["position"][:2], [D + C * math.cos(fb.theta4[0]), C * math.sin(fb.theta4[0])],
                               rtol=0, atol=PLACE_TOL_M)
