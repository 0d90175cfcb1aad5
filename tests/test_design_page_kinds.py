"""Every kind of planar linkage on the design page (four-bar, slider-crank, inverted
slider-crank, Watt and Stephenson six-bars, with or without [params]): it opens, a joint
dragged lands under the mouse, it is diagnosed, and it is saved into the user's own file
with every comment kept and only the dragged values changed; `pinmech sweep` of the saved
files draws the page's curves.
"""

from __future__ import annotations

import csv
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("starlette")

from pinmech.draw.design_page.messages import Saving  # noqa: E402
from pinmech.draw.design_page.save import leading_comments  # noqa: E402
from pinmech.draw.design_page.session import Session, read_design_file  # noqa: E402
from pinmech.model.linkage import linkage_from_spec  # noqa: E402
from pinmech.model.linkage_spec import read_linkage_spec  # noqa: E402

LINKAGES = Path(__file__).resolve().parents[1] / "models" / "linkages"
#: A dragged place is written to 1e-3 mm (edits.DECIMALS): within about 1e-6 m of the mouse.
DRAG_TOL = 2e-6
#: The page's curve and the sweep's CSV are the same poses of the same files; the CSV prints
#: 12 significant digits of positions ~0.1 m (1e-13 m). 1e-9 m is the page's promise.
CURVE_TOL = 1e-9

#: (file, the joint dragged, its construction, a loop kind the diagnostics must name)
KINDS = [
    ("four_bar.toml", "B", "Compass", "four-bar"),
    ("slider_crank.toml", "A", "tuple", "slider-crank"),
    ("inverted_slider_crank.toml", "D", "Polar", "inverted slider-crank"),
    ("crank_shaper.toml", "B", "tuple", "inverted slider-crank"),
    ("watt.toml", "D", "Compass", "four-bar"),
    ("watt_params.toml", "O6", "tuple", "four-bar"),
    ("stephenson.toml", "C", "Compass", "four-bar"),
    ("stephenson_params.toml", "P", "Compass", "four-bar"),
]


def _comments(text: str) -> list[str]:
    """Every comment of a TOML file (none of these files has a # inside a string)."""
    return [line[line.index("#"):].rstrip() for line in text.splitlines() if "#" in line]


def _sweep(scene: Path, tmp_path: Path) -> list[dict]:
    out = tmp_path / "sweep.csv"
    subprocess.run([sys.executable, "-m", "pinmech", "sweep", str(scene), "--csv", str(out)], check=True,
                   capture_output=True, timeout=120)
    with out.open() as f:
        return list(csv.DictReader(f))


@pytest.mark.parametrize("file, joint, construction, loop", KINDS)
def test_each_kind_opens_drags_is_diagnosed_and_saves_into_its_own_file(file, joint, construction, loop, tmp_path):
    copy = tmp_path / file
    shutil.copy(LINKAGES / file, copy)
    original = copy.read_text()
    spec, source, driver, speed = read_design_file(copy)
    session = Session(spec, source, driver=driver, speed=speed)
    at = session.turn.linkage.points[joint][:2]
    to = at + [0.0021234, -0.0013456]
    frame = session.drag(joint, *to)
    assert frame["ok"], frame.get("error")
    assert type(session.spec.joints[joint]).__name__ == construction
    panel = session.diagnostics()["diagnostics"]
    assert panel["applicable"] and loop in [x["kind"] for x in panel["loops"]]

    saving = Saving(copy, leading_comments(copy))
    assert saving.save(session, {"type": "save"})["ok"]
    saved = copy.read_text()
    assert _comments(saved) == _comments(original)  # every comment, in its order
    changed = [(a, b) for a, b in zip(original.splitlines(), saved.splitlines()) if a != b]
    assert len(saved.splitlines()) == len(original.splitlines()) and 1 <= len(changed) <= 2
    again, _ = read_linkage_spec(copy)
    assert np.linalg.norm(linkage_from_spec(again, str(copy)).points[joint][:2] - to) < DRAG_TOL

    rows = _sweep(saving.scene, tmp_path)
    for name in session.turn.names:
        drawn = session.turn.path(name)
        solved = ~np.isnan(drawn[:, 0])
        swept = np.array([[float(r[f"{name}.x [m]"]), float(r[f"{name}.y [m]"])] for r in rows])
        assert len(swept) == solved.sum() and np.abs(swept - drawn[solved]).max() < CURVE_TOL


def test_a_value_beside_a_comment_with_a_hash_in_a_string_is_rewritten_and_both_kept(tmp_path):
    copy = tmp_path / "four_bar.toml"
    text = (LINKAGES / "four_bar.toml").read_text()
    copy.write_text(text.replace('title = "Four-bar linkage, drawn"', 'title = "Four-bar #1"   # the # is text'))
    spec, source, _, _ = read_design_file(copy)
    session = Session(spec, source)
    session.drag("P", 0.101, 0.031)
    Saving(copy, leading_comments(copy)).save(session, {"type": "save"})
    saved = copy.read_text()
    assert 'title = "Four-bar #1"   # the # is text' in saved
    assert re.search(r'^P  = \["101 mm", "31 mm"\]    # a coupler point, drawn where it is at this pose$', saved,
                     re.MULTILINE)
