"""Scenes that are valid TOML but wrong: a key of the wrong type, a list where a table is
due, a unit of the wrong dimension, a negative step, NaN or inf, an empty table.

Random keys and values are written into the bundled scenes (hypothesis, seeded through its
database-free derandomised run), and the scene is read, then solved or swept. The property
is the house's first rule: what comes out is a result or a PinmechError subclass whose
message is one line naming the scene file; never another exception (a TypeError deep in
the solver, a msgspec ValidationError, a KeyError).
"""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pinmech.exceptions import PinmechError, SceneError
from pinmech.io.analysis import analyse
from pinmech.io.check import hand_file
from pinmech.io.scene import KNOWN_KEYS, Scene
from pinmech.io.sweep import Sweep

SCENES = Path(__file__).resolve().parents[1] / "models" / "scenes"
BUNDLED = sorted(p for p in SCENES.glob("*.toml") if not p.name.endswith(".hand.toml"))
#: Scenes quick to solve (no example-robot-data download), for the solve-through property.
QUICK = [SCENES / n for n in ("r_rtr.toml", "slider_crank_dynamic.toml", "four_bar.toml", "planar_arm.toml",
                               "four_bar_drawn.toml")]
#: Keys that appear somewhere in a scene, to write where they do not belong.
KEY_NAMES = sorted(KNOWN_KEYS | {"value", "label", "quantity", "hand", "unit", "kind", "source", "scene","angle", "position", "speed", "velocity", "acceleration", "at", "link", "points",
                                 "links", "limits", "tol", "max_iterations", "max_condition", "method", "damping",
                                 "steps", "from", "to", "start", "batch", "interpolate", "duration", "step",
                                 "scheme", "gain", "massless", "static", "minimum_norm", "flywheel", "direction",
                                 "frame", "components", "reference", "force", "torque", "name", "point", "A", "B"})
#: Quantities of every dimension, and some that are not quantities at all.
WRITTEN = ["30 deg", "-50 rpm", "12 mm", "-1 ms", "0 s", "5 kg", "0.5 N*m", "1 N", "9.81 m/s^2", "2 rad/s^2",
           "nan deg", "inf mm", "1e400 m", "1,5 deg", "30", "", "deg", "0.01 kg*m^2", "1 Hz", "-3 m/s",
           "any", "+", "warn", "error", "exact", "rk4", "predictor", "world", "x", "wz", "D", "link3"]

scalars = st.one_of(
    st.integers(min_value=-10**20, max_value=10**20), st.floats(allow_nan=True, allow_infinity=True),
    st.booleans(), st.sampled_from(WRITTEN), st.text(max_size=6),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=4),
                            st.dictionaries(st.sampled_from(KEY_NAMES), inner, max_size=3)),
    max_leaves=6,
)


def _tables(path: Path) -> dict[str, Any]:
    return tomllib.loads(path.read_text(encoding="utf-8"))


def _places(node: Any, prefix: tuple = (), *, tables: bool = False) -> list[tuple]:
    """Every place in the tables a value sits (keys of tables, indices of arrays), or with
    `tables` every table (where a new key can go), the top level included."""
    here = isinstance(node, dict) if tables else bool(prefix)
    out = [prefix] if here else []
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in items:
        out += _places(value, prefix + (key,), tables=tables)
    return out


@st.composite
def mutated(draw, scenes: list[Path]) -> tuple[Path, dict[str, Any]]:
    """A bundled scene with one to three values replaced, or keys added, at random."""
    path = draw(st.sampled_from(scenes))
    tables = copy.deepcopy(_tables(path))
    for _ in range(draw(st.integers(1, 3))):
        if draw(st.booleans()):
            where = draw(st.sampled_from(_places(tables)))
        else:
            where = draw(st.sampled_from(_places(tables, tables=True))) + (draw(st.sampled_from(KEY_NAMES)),)
        node = tables
        for part in where[:-1]:
            node = node[part]
        node[where[-1]] = draw(values)
    return path, tables


def _said_well(exc: PinmechError, path: Path) -> None:
    """One line; a scene's own mistake names the scene file."""
    message = str(exc)
    assert "\n" not in message.strip(), message
    if type(exc) is SceneError or exc.__class__.__name__ == "UnitError":
        assert str(path) in message or path.name in message, message


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated(BUNDLED))
def test_a_wrong_scene_is_read_into_a_scene_or_refused_by_a_named_error(case):
    path, tables = case
    try:
        Scene.from_tables(tables, path)
    except PinmechError as exc:
        _said_well(exc, path)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated(QUICK))
def test_a_wrong_scene_is_solved_or_refused_by_a_named_error_never_another_exception(case):
    path, tables = case
    try:
        scene = Scene.from_tables(tables, path)
        analysis = analyse(scene)
    except PinmechError as exc:
        _said_well(exc, path)
        return
    assert all(math.isfinite(x) for x in analysis.solution.q)  # a result: finite, or it would have been refused


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated([SCENES / "r_rtr.toml", SCENES / "slider_crank.toml"]))
def test_a_wrong_scene_is_swept_or_refused_by_a_named_error(case):
    path, tables = case
    try:
        sweep = Sweep.from_scene(Scene.from_tables(tables, path))
        for _ in sweep.poses(sweep.default_values(5)):
            pass
    except PinmechError as exc:
        _said_well(exc, path)


HANDS = sorted(SCENES.glob("*.hand.toml"))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated(HANDS))
def test_a_wrong_hand_file_is_read_or_refused_by_a_named_error(case):
    """The same for hand-value files: read into HandValues, or one named error."""
    path, tables = case
    try:
        hand_file(tables, path)
    except PinmechError as exc:
        _said_well(exc, path)


@pytest.mark.parametrize(("key", "value", "blamed", "words"), [
    (("sweep", "steps"), "many", "sweep.steps", "must be int, got 'many'"),          # wrong type
    (("drivers",), ["A"], "drivers", "must be a table"),                             # a list where a table is due
    (("drivers", "A", "speed"), "5 kg", "drivers.A.speed", "not an angular velocity (use e.g. rpm); nor is it a velocity"),  # a wrong dimension
    (("sweep", "step"), "-1 ms", "sweep.step", "must be a positive time"),           # a negative step
    (("guess", "B"), math.nan, "guess.B", "not a finite number"),                    # NaN
    (("solver",), {"tol": math.inf}, "solver.tol", "solver.tol = inf is outside [1e-16, 0.001]"),  # inf
    (("gravity",), {}, "gravity", "give acceleration"),                              # an empty table
    (("points", "B3"), {}, "points.B3", "a point needs exactly"),                    # an empty table
    (("load",), [{"point": "D", "force": ["1 N", "2 N*m"]}], "load[0].force[1]", "'2 N*m'"),
])
def test_each_kind_of_wrong_value_is_one_line_naming_file_and_key(key, value, blamed, words):
    """The class of mistakes the fuzzing finds, one of each, with the key blamed."""
    tables = _tables(SCENES / "r_rtr.toml")
    node = tables
    for part in key[:-1]:
        node = node[part]
    node[key[-1]] = value
    with pytest.raises(SceneError) as caught:
        Scene.from_tables(tables, SCENES / "r_rtr.toml")
    message = str(caught.value)
    assert message.startswith(f"{SCENES / 'r_rtr.toml'}, {blamed}: ") and words in message, message
