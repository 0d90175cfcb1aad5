"""The URDF written from a drawn linkage: outside text (the file's path, the names in it)
never changes the XML's structure.

The check is structural, by an independent XML parser (the standard library's): the
generated text parses, and its links and joints are exactly those the linkage file lists;
the mechanism then moves as the four-bar's closed form (scripts/closed_form.py) to 1e-10 m
and rad, as in tests/test_linkage.py (positions close to ~1e-13 of a 0.1 m mechanism).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import closed_form as cf
from pinmech import LoopSolver
from pinmech.cli import main
from pinmech.exceptions import ModelError
from pinmech.model.linkage import parse_linkage
from pinmech.model.linkage_model import load_linkage
from pinmech.model.linkage_urdf import linkage_urdf

FOUR_BAR = """ground = ["O2", "O4"]
[joints]
O2 = ["0 mm", "0 mm"]
O4 = ["100 mm", "0 mm"]
A = ["40 mm", "0 mm"]
B = { from = ["A", "O4"], lengths = ["120 mm", "80 mm"], side = "left" }
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
"""
LINKS = {"ground", "crank", "coupler", "rocker"}
#: folder names a user may have, each of which broke or rewrote the URDF when written into its comment
FOLDERS = ["a--b", "x-", 'inject--><link name="evil"/><joint name="j" type="fixed"><parent link="ground"/>'
           '<child link="evil"/></joint><!--', "<&\"']]>", "pi\u00f1\u00f3n"]


def _write(folder: Path, text: str = FOUR_BAR, name: str = "four_bar.toml") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def _rocker_angle_at(mech, theta2: float) -> float:
    solver = LoopSolver(mech, ["O2"])
    q = mech.reference
    for value in np.linspace(0.0, theta2, 5)[1:]:
        q = solver.solve([value], guess=q).q
    data = mech.model.createData()
    import pinocchio as pin

    pin.framesForwardKinematics(mech.model, data, q)
    x = data.oMf[mech.links["rocker"]].rotation[:, 0]
    return math.atan2(x[1], x[0])


@pytest.mark.parametrize("folder", FOLDERS)
def test_a_folder_name_never_shapes_the_urdf(tmp_path, folder):
    """A folder with '--' made the comment malformed ('build' wrote XML nothing reads, exit 0;
    'solve' blamed the TOML); one with '-->' injected a link and a joint."""
    path = _write(tmp_path / folder)
    text, _ = linkage_urdf(parse_linkage(path))
    root = ET.fromstring(text)
    assert {link.get("name") for link in root.iter("link")} == LINKS
    assert {j.get("name") for j in root.iter("joint")} == {"O2", "A", "O4"}
    mech = load_linkage(path)
    assert set(mech.links) == LINKS and "evil" not in mech.points
    ref = cf.four_bar(0.4, 1.0, 0.0, 0.04, 0.12, 0.08, 0.10, branch=+1)
    np.testing.assert_allclose(_rocker_angle_at(mech, 0.4), ref.theta4, atol=1e-10)


@pytest.mark.parametrize("folder", FOLDERS)
def test_build_writes_xml_any_parser_reads(tmp_path, folder, capsys):
    path = _write(tmp_path / folder)
    out = tmp_path / "out.urdf"
    assert main(["build", str(path), "-o", str(out)]) == 0
    root = ET.parse(out).getroot()
    assert {link.get("name") for link in root.iter("link")} == LINKS


def test_names_with_markup_characters_are_escaped(tmp_path):
    """Link and joint names with < & " ' and '-->' reach the model as written."""
    odd = 'cou<p>&\\"l\'er-->'  # as TOML writes it (a basic string, the quote escaped)
    text = FOUR_BAR.replace("coupler", f'"{odd}"').replace('"A"', '"A&<"').replace("A = [", '"A&<" = [')
    path = _write(tmp_path, text)
    root = ET.fromstring(linkage_urdf(parse_linkage(path))[0])
    assert {link.get("name") for link in root.iter("link")} == {"ground", "crank", 'cou<p>&"l\'er-->', "rocker"}
    mech = load_linkage(path)
    assert 'cou<p>&"l\'er-->' in mech.links and "A&<" in mech.joints


@pytest.mark.parametrize("name", ["\\u0001", "a\\u0000b", " ", "x\\ny"])
def test_a_name_xml_cannot_hold_is_refused(tmp_path, name):
    path = _write(tmp_path, FOUR_BAR.replace("coupler", f'"{name}"'))
    with pytest.raises(ModelError, match=r"four_bar\.toml: the link name .* control character"):
        parse_linkage(path)
