"""A drawn linkage written back as TOML reads as the same linkage: parse(write(x)) == x.

`LinkageSpec` holds a file as written (quantities as the user's text), so the identity is
exact equality of the typed objects, no tolerance. Hypothesis draws valid specs (names with
quotes, spaces, control characters and non-ASCII letters, every joint form, sliders, slots,
axes, balls, masses); the bundled files are checked too, and the geometry a changed
parameter draws is checked against the file's own construction (distances, closed form).
"""

from __future__ import annotations

import keyword
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pinmech.exceptions import ModelError
from pinmech.model.linkage import linkage_from_spec
from pinmech.model.linkage_spec import LinkageSpec, linkage_spec, read_linkage_spec
from pinmech.model.linkage_write import linkage_toml
from tests.tolerance import rounding

LINKAGES = Path(__file__).resolve().parents[1] / "models" / "linkages"

NAMES = st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=6).filter(lambda n: n != "ground")
PARAM_NAMES = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,4}", fullmatch=True).filter(lambda n: not keyword.iskeyword(n))
WRITTEN = st.one_of(
    st.text(st.characters(blacklist_categories=("Cs",)), max_size=12),
    st.integers(-(2**63), 2**63 - 1),
    st.floats(allow_nan=False),
)
AXES = st.tuples(*[st.floats(-1e3, 1e3)] * 3).filter(lambda a: math.hypot(*a) > 1e-6)


@st.composite
def specs(draw) -> dict:
    """The tables of a valid linkage file (every name it uses given where it must be)."""
    joints = draw(st.lists(NAMES, min_size=2, max_size=5, unique=True))
    table: dict = {}
    for i, name in enumerate(joints):
        form = draw(st.sampled_from(["xy", "xyz", "polar", "compass"][: 2 + min(i, 2)]))
        if form in ("xy", "xyz"):
            table[name] = draw(st.lists(WRITTEN, min_size=len(form), max_size=len(form)))
        elif form == "polar":
            table[name] = {"from": draw(st.sampled_from(joints[:i])), "length": draw(WRITTEN), "angle": draw(WRITTEN)}
        else:
            bases = draw(st.lists(st.sampled_from(joints[:i]), min_size=2, max_size=2, unique=True))
            table[name] = {"from": bases, "lengths": draw(st.lists(WRITTEN, min_size=2, max_size=2)),
                           "side": draw(st.sampled_from(["left", "right"]))}
    some = st.lists(st.sampled_from(joints), unique=True)
    links = draw(st.dictionaries(NAMES, st.lists(st.sampled_from(joints), min_size=1, unique=True),
                                 min_size=1, max_size=3))
    raw = {"joints": table, "links": links, "ground": draw(some), "balls": draw(some),
           "params": draw(st.dictionaries(PARAM_NAMES, WRITTEN, max_size=3)),
           "axes": {n: list(draw(AXES)) for n in draw(some)},
           "colors": draw(st.dictionaries(st.sampled_from(list(links)), NAMES, max_size=2))}
    if draw(st.booleans()):
        raw["title"] = draw(NAMES)
    block = draw(st.sampled_from(list(links)))
    if draw(st.booleans()):
        along = draw(st.one_of(WRITTEN, st.lists(st.sampled_from(joints), min_size=2, max_size=2)))
        raw["sliders"] = {draw(NAMES): {"block": block, "on": "ground", "at": links[block][0], "along": along}}
    pin = links[block][0]
    if draw(st.booleans()) and f"{pin}_block" not in links:
        raw["slots"] = {pin: {"pin": block, "slot": "ground", "along": draw(WRITTEN)}}
    if draw(st.booleans()):
        inertia = {"izz": draw(WRITTEN)} if draw(st.booleans()) else {"inertia": draw(st.lists(WRITTEN, min_size=6,
                                                                                            max_size=6))}
        at = draw(st.one_of(st.sampled_from(joints), st.lists(WRITTEN, min_size=2, max_size=3)))
        raw["masses"] = {block: {"mass": draw(WRITTEN), "at": at, **inertia}}
    return raw


@settings(max_examples=200, deadline=None)
@given(raw=specs())
def test_a_written_spec_reads_back_as_itself(raw):
    spec = linkage_spec(raw, "drawn.toml")
    text = linkage_toml(spec, header="written by a test\nsecond line")
    assert linkage_spec(tomllib.loads(text), "written.toml") == spec, text


@pytest.mark.parametrize("path", sorted(LINKAGES.glob("*.toml")), ids=lambda p: p.stem)
def test_every_bundled_linkage_reads_back_as_itself_and_draws_the_same_pose(path):
    spec, source = read_linkage_spec(path)
    back = linkage_spec(tomllib.loads(linkage_toml(spec)), source)
    assert back == spec
    drawn, again = linkage_from_spec(spec, source), linkage_from_spec(back, source)
    assert drawn.points.keys() == again.points.keys()
    for name, at in drawn.points.items():
        np.testing.assert_array_equal(again.points[name], at)  # the same text read the same way: exact


def test_a_changed_parameter_moves_every_joint_drawn_from_it():
    """The four-bar draws A = [crank, 0] and B by compass at 120 mm from A and 80 mm from
    O4 = (100 mm, 0), left of A -> O4. With crank = 55 mm: A = (55 mm, 0), and B is where the
    two circles meet, checked by its distances (to 1e-12 m: a few ulps of 0.1 m)."""
    spec, source = read_linkage_spec(LINKAGES / "four_bar.toml")
    changed = spec.with_params(crank=0.055)
    assert changed.params["crank"] == "0.055 m" and changed.joints == spec.joints
    points = linkage_from_spec(changed, source).points
    np.testing.assert_allclose(points["A"], [0.055, 0.0], rtol=0, atol=rounding(0.1))
    np.testing.assert_allclose(np.linalg.norm(points["B"] - points["A"]), 0.120, rtol=0, atol=rounding(0.2))
    np.testing.assert_allclose(np.linalg.norm(points["B"] - points["O4"]), 0.080, rtol=0, atol=rounding(0.2))
    (ux, uy), (wx, wy) = points["O4"] - points["A"], points["B"] - points["A"]
    assert ux * wy - uy * wx > 0  # B left of A -> O4
    with pytest.raises(ModelError, match=r"'rod' is not a parameter \(params: crank\)"):
        spec.with_params(rod=0.1)


def test_the_pins_are_the_joints_two_or_more_links_share():
    spec, _ = read_linkage_spec(LINKAGES / "four_bar.toml")
    assert isinstance(spec, LinkageSpec)
    assert spec.pins == ("O2", "O4", "A", "B")  # P is a point of the coupler alone


@pytest.mark.parametrize("old, new, words", [
    ('A  = ["crank", "0 mm"]', 'A  = [true, "0 mm"]', ["[joints] A: x: must be a quantity", "got True"]),
    ('title = "Four-bar linkage, drawn"', "title = 3", ["title: must be text, got 3"]),
    ('crank = "40 mm"', "crank = [1]", ["[params] crank: must be a quantity", "got [1]"]),
    ('lengths = ["120 mm", "80 mm"]', 'lengths = ["120 mm", false]', ["[joints] B: lengths 1: must be a quantity"]),
    ('rocker  = ["O4", "B"]', 'rocker  = ["O4", "B"]\n[masses]\nrocker = { mass = "1 kg", at = 5, izz = "0 kg*m^2" }',
     ["[masses] rocker: at: the centre of mass is a joint's name or [x, y]", "got 5"]),
])
def test_a_value_of_the_wrong_type_is_one_line_naming_the_file_and_the_key(tmp_path, old, new, words):
    text = (LINKAGES / "four_bar.toml").read_text()
    assert old in text
    path = tmp_path / "typed.toml"
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ModelError) as err:
        read_linkage_spec(path)
    message = str(err.value)
    assert message.startswith(f"{path}, ") and "\n" not in message, message
    for word in words:
        assert word in message, message


def test_a_spec_built_in_code_is_validated_and_draws_as_the_file_does():
    """The four-bar built from Python objects, as a synthesis would: the same drawn pose as
    the bundled file (the same texts read the same way: exact), and a name no joint has is
    refused as in a file."""
    from pinmech.model.linkage_entries import Compass

    built = LinkageSpec(
        title="Four-bar linkage, drawn", ground=("O2", "O4"), params={"crank": "40 mm"},
        joints={"O2": ("0 mm", "0 mm"), "O4": ("100 mm", "0 mm"), "A": ("crank", "0 mm"),
                "B": Compass(bases=("A", "O4"), lengths=("120 mm", "80 mm"), side="left"), "P": ("100 mm", "30 mm")},
        links={"crank": ("O2", "A"), "coupler": ("A", "B", "P"), "rocker": ("O4", "B")})
    spec, source = read_linkage_spec(LINKAGES / "four_bar.toml")
    assert built == spec
    for name, at in linkage_from_spec(spec, source).points.items():
        np.testing.assert_array_equal(linkage_from_spec(built).points[name], at)
    with pytest.raises(ModelError, match=r"\[links\] rocker: names joint 'Q', which \[joints\] does not give"):
        LinkageSpec(joints=built.joints, links={**built.links, "rocker": ("O4", "Q")})


def test_a_spec_built_in_code_has_its_types_checked_as_a_file_has():
    """A value of the wrong type given in code (a number where a joint's name is due, a
    boolean where a length is due) is the same one-line ModelError a file gets, naming the
    key: building a spec in code is no way around the file's checks. A dict written where a
    construction is due is read as the construction itself (`from` = its base)."""
    from pinmech.model.linkage_entries import Polar

    joints = {"O": ("0 mm", "0 mm"), "A": {"from": "O", "length": "40 mm", "angle": "30 deg"}}
    spec = LinkageSpec(ground=("O",), joints=joints, links={"crank": ("O", "A")})
    assert spec.joints["A"] == Polar(base="O", length="40 mm", angle="30 deg")
    with pytest.raises(ModelError, match=r"^<linkage>, title: must be text, got 3$"):
        LinkageSpec(title=3, ground=("O",), joints=joints, links={"crank": ("O", "A")})
    with pytest.raises(ModelError, match=r"\[joints\] O: y: must be a quantity .*, got False"):
        LinkageSpec(ground=("O",), joints={**joints, "O": ("0 mm", False)}, links={"crank": ("O", "A")})
