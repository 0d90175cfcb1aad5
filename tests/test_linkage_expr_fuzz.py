"""Drawn-linkage expressions fuzzed against Python's own arithmetic on the allowed subset.

Hypothesis writes random expressions of the grammar in `pinmech.model.linkage_expr` (parameters,
plain numbers, + - * /, parentheses, one sign at a time; a length in every sum's terms and
at most one in a product, division by plain numbers): each must read as exactly the value
Python's `eval` gives on the same text with the parameters bound to the same floats. Both
do the same IEEE operations in the same order, so the check is exact equality (rtol 0):
any misreading (a sign, a precedence, an associativity) changes the value.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pinmech.exceptions import ModelError
from pinmech.model.linkage_expr import length

PARAMS = {"a": 0.03, "b": 0.012, "crank_2": 0.0405}
_numbers = st.sampled_from(["2", "0.5", "3", "1.25", "4.0", "1e-1", "7"])


@st.composite
def _length_expr(draw, depth: int = 3) -> str:
    """A text that is a length: a parameter, a signed length, a sum of lengths, a length
    times or over a plain number, a plain number times a length, or one in parentheses."""
    if depth == 0:
        return draw(st.sampled_from(sorted(PARAMS)))
    kind = draw(st.sampled_from(["name", "sign", "sum", "times", "over", "ntimes", "paren"]))
    inner = _length_expr(depth - 1)
    if kind == "name":
        return draw(st.sampled_from(sorted(PARAMS)))
    if kind == "sign":
        body = draw(inner)
        body = body if body[0] not in "+-" else f"({body})"
        return draw(st.sampled_from(["-", "+"])) + body
    if kind == "sum":
        right = draw(inner)
        right = right if right[0] not in "+-" else f"({right})"
        return f"{draw(inner)} {draw(st.sampled_from(['+', '-']))} {right}"
    if kind in ("times", "over"):
        return f"({draw(inner)}) {'*' if kind == 'times' else '/'} {draw(_numbers)}"
    if kind == "ntimes":
        return f"{draw(_numbers)}*({draw(inner)})"
    return f"({draw(inner)})"


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_length_expr())
def test_an_expression_reads_as_python_computes_it(text):
    expected = eval(text, {"__builtins__": {}}, dict(PARAMS))  # the same floats, the same order
    np.testing.assert_allclose(length(text, PARAMS, "f.toml", "[joints] A x"), expected, rtol=0, atol=0)


@pytest.mark.parametrize("text", ["3m", "3.0m", "-2m", "1e3mm", "1inch", " 2m "])
def test_a_number_glued_to_a_parameter_named_like_a_unit_is_ambiguous(text):
    """`"3m"` with a parameter `m`: 3 metres to pint, 3*m to a reader; like `"3 m"`, not guessed
    (it was read as 3 metres in silence)."""
    params = {"m": 0.005, "mm": 0.5, "inch": 0.3}
    with pytest.raises(ModelError, match="ambiguous"):
        length(text, params, "f.toml", "[joints] A x")


def test_a_number_glued_to_a_unit_that_is_no_parameter_is_a_quantity():
    """`"15mm"` without a parameter `mm` is 15 mm (exact binary arithmetic aside: 1e-18 m)."""
    assert math.isclose(length("15mm", {"m": 0.005}, "f.toml", "k"), 0.015, rel_tol=0, abs_tol=1e-18)
