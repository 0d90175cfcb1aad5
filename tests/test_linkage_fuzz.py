"""Hostile linkage files: whatever a key holds, loading ends in a Mechanism or a ModelError.

Each example replaces one value of a valid file (the four-bar with a slider-crank's
slider and a slot added) by something a user might type or a fuzzer might make; the
loader must answer with a named error on one line naming the file, never a traceback.
"""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from pinmech.exceptions import ModelError
from pinmech.model.linkage_model import load_linkage

VALID = {
    "ground": '["O2", "O4"]',
    "params": '{ r = "40 mm" }',
    "O2": '["0 mm", "0 mm"]',
    "O4": '["100 mm", "0 mm"]',
    "A": '["r", "0 mm"]',
    "B": '{ from = ["A", "O4"], lengths = ["120 mm", "80 mm"], side = "left" }',
    "crank": '["O2", "A"]',
    "coupler": '["A", "B"]',
    "rocker": '["O4", "B"]',
}

VALUES = st.sampled_from([
    '"0 mm"', '"-5 mm"', '"1e400 mm"', '"nan mm"', '"inf mm"', '"10 deg"', '"10"', '10', '0', '-1', 'true', '""',
    '"r"', '"-r"', '"rr"', '"m"', '"a + 2 mm"', '"1,5 mm"', '[]', '["0 mm"]', '["0 mm", "0 mm", "0 mm"]',
    '["A", "A"]', '["Z"]', '["O2"]', '["O2", "Z"]', '{}', '{ from = "A" }', '{ from = "Z", length = "1 mm", angle = "0 deg" }',
    '{ from = ["A", "A"], lengths = ["1 mm", "1 mm"], side = "left" }',
    '{ from = ["A", "O4"], lengths = ["0 mm", "1 mm"], side = "left" }',
    '{ from = ["A", "O4"], lengths = ["1 mm"], side = "left" }',
    '{ from = ["A", "O4"], lengths = ["120 mm", "80 mm"], side = 3 }',
    '{ r = "x" }', '{ r = 3 }', '"ground"', '[["O2"]]', '1.5', '"O2"',
])


def _text(values: dict[str, str]) -> str:
    return (f"ground = {values['ground']}\nparams = {values['params']}\n[joints]\n"
            + "".join(f"{k} = {values[k]}\n" for k in ("O2", "O4", "A", "B"))
            + "[links]\n" + "".join(f"{k} = {values[k]}\n" for k in ("crank", "coupler", "rocker")))


@settings(max_examples=60, deadline=None)
@given(key=st.sampled_from(sorted(VALID)), value=VALUES, second=st.sampled_from(sorted(VALID)), value2=VALUES)
def test_any_value_is_a_mechanism_or_a_named_error(tmp_path_factory, key, value, second, value2):
    values = dict(VALID)
    values[key] = value
    if second != key:
        values[second] = value2
    path = tmp_path_factory.mktemp("fuzz") / "l.toml"
    path.write_text(_text(values))
    try:
        mech = load_linkage(path)
    except ModelError as exc:
        message = str(exc)
        assert str(path) in message and "\n" not in message, message
    else:
        assert mech.model.nv >= 1
