"""The drawn-linkage reader's messages name what is wrong and what is valid: a misspelt key
of a construction named as unknown beside the construction's keys, a missing key, a name
no joint has with the joints there are, an unknown point with every name that is one
(points, links, pins)."""

from __future__ import annotations

from pathlib import Path

import pytest

from pinmech.exceptions import FrameNotFound, ModelError
from pinmech.model.linkage import linkage_from_spec
from pinmech.model.linkage_model import load_linkage
from pinmech.model.linkage_spec import linkage_spec

MODELS = Path(__file__).resolve().parents[1] / "models"


def _joints(P: dict, params: dict | None = None) -> dict:
    return {"ground": ["O2", "O4"], "params": params or {"g": "30 deg"},
            "joints": {"O2": ["0 mm", "0 mm"], "O4": ["100 mm", "0 mm"], "A": ["40 mm", "0 mm"],
                       "B": {"from": ["A", "O4"], "lengths": ["120 mm", "80 mm"], "side": "left"}, "P": P},
            "links": {"crank": ["O2", "A"], "coupler": ["A", "B", "P"], "rocker": ["O4", "B"]}}


@pytest.mark.parametrize("P, message", [
    ({"from": ["A", "O4"], "lenghts": ["1 mm", "1 mm"], "side": "left"}, r"unknown key\(s\) lenghts; a compass"),
    ({"from": ["A", "B"], "length": "10 mm", "angel": "g"}, r"unknown key\(s\) angel; a bearing"),
    ({"from": "A", "lenght": "10 mm", "angle": "g"}, r"unknown key\(s\) lenght; a polar"),
    ({"from": ["A", "B"], "length": "10 mm"}, r"missing angle: a bearing"),
    ({"from": ["A", "B", "O2"], "length": "10 mm", "angle": "g"}, r"from names 3 joints: a bearing"),
    ({"from": ["A", "B"], "length": "g", "angle": "g"}, r"'g' is an angle parameter"),
])
def test_a_construction_names_the_key_it_does_not_know(P, message):
    """A misspelt key is named as unknown beside the construction's own keys; a missing one
    is named; an angle param where a length is needed is named."""
    with pytest.raises(ModelError, match=message):
        spec = linkage_spec(_joints(P))
        linkage_from_spec(spec)


@pytest.mark.parametrize("change, message", [
    (lambda t: t["joints"].update(P={"from": ["A", "Q"], "length": "1 mm", "angle": "g"}),
     r"from names 'Q', which is not given above it; joints above: O2, O4, A, B"),
    (lambda t: t["links"].update(coupler=["A", "B", "Q"]), r"names joint 'Q', which \[joints\] does not give "
     r"\(joints: O2, O4, A, B, P\)"),
    (lambda t: t.update(masses={"crank": {"mass": "1 kg", "at": "Q", "izz": "1 kg m^2"}}),
     r"at = 'Q' is not a joint of \[joints\].*joints: O2, O4, A, B, P"),
])
def test_a_name_no_joint_has_is_said_with_the_joints_there_are(change, message):
    raw = _joints({"from": ["A", "B"], "length": "10 mm", "angle": "g"})
    change(raw)
    with pytest.raises(ModelError, match=message):
        linkage_spec(raw)


def test_an_unknown_point_lists_the_pins_too():
    """On the drawn four-bar, [report] points = ["Q"]: the message lists P, the links and
    the pins A, B, O2, O4 (each a valid point)."""
    mech = load_linkage(MODELS / "linkages" / "four_bar.toml")
    with pytest.raises(FrameNotFound) as caught:
        mech.frame_id("Q")
    for name in ("P", "coupler", "A", "B", "O2", "O4"):
        assert name in caught.value.known
        mech.frame_id(name)  # each one listed is found
    assert not any(n.endswith(("__parent", "__child")) for n in caught.value.known)
