"""Lengths of a drawn linkage written with parameters: one reading, or a named error.

Expected values are the arithmetic done by hand on a = 30 mm, b = 12 mm (exact in binary to
well below 1e-15 m); the check is to 1e-15 m absolute, far below any misreading (a sign or
a precedence error moves the point by at least 6 mm).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pinmech.exceptions import ModelError
from pinmech.model.linkage import parse_linkage
from tests.tolerance import rounding

A_MM, B_MM = 30.0, 12.0


def drawn(tmp_path: Path, x: str, params: str = 'a = "30 mm", b = "12 mm"') -> Path:
    """A crank O-A whose A is drawn at x = the text under test (y = 0)."""
    path = tmp_path / "expr.toml"
    path.write_text(f'ground = ["O"]\nparams = {{ {params} }}\n[joints]\nO = ["0 mm", "0 mm"]\n'
                    f'A = [{x!r}, "0 mm"]\n[links]\ncrank = ["O", "A"]\n'.replace("'", '"'))
    return path


@pytest.mark.parametrize("text, expected_mm", [
    ("a", A_MM),
    ("-a", -A_MM),
    ("+a", A_MM),
    ("\u2212a", -A_MM),                    # a typographic minus is a minus
    ("a + 2*b", A_MM + 2 * B_MM),          # * before +
    ("a - b/2", A_MM - B_MM / 2),
    ("-a*2", -2 * A_MM),
    ("2*(a - b)", 2 * (A_MM - B_MM)),
    ("a/4*2", A_MM / 4 * 2),               # left to right
    ("-(-a)", A_MM),                       # a sign before parentheses: one sign each, as the grammar has it
    ("a - (-b)", A_MM + B_MM),
    ("15 mm", 15.0),
])
def test_an_expression_reads_as_arithmetic_says(tmp_path, text, expected_mm):
    x = parse_linkage(drawn(tmp_path, text)).points["A"][0]
    np.testing.assert_allclose(x, expected_mm * 1e-3, rtol=0, atol=rounding(0.1))


@pytest.mark.parametrize("text, words", [
    ("+-a", "two signs"),
    ("--a", "two signs"),
    ("-+a", "two signs"),
    ("a - -b", "a sign right after"),
    ("a + -b", "a sign right after"),
    ("a**2", "'**'"),
    ("2**1000*a", "'**'"),
    ("2 a", "ambiguous"),                   # 2 years to pint, 2*a to a reader
    ("a b", "ambiguous"),
    ("c", "'c' is not a parameter"),
    ("2*c", "'c' is not a parameter"),
    ("a/0", "division by zero"),
    ("a/(2 - 2)", "division by zero"),
    ("a*b", "area"),
    ("a/b", "dividing by a length"),
    ("a + 2", "a length and a plain number"),
    ("2*3", "more than one number"),
    ("1e300*a*1e300", "beyond"),
    ("a + 1 mm", "mixes the parameter"),
    ("__import__(a).getcwd()", "only parameters"),
    ("a.real", "only parameters"),
    ("a if b else a", "only parameters"),
])
def test_an_unclear_expression_is_a_named_error(tmp_path, text, words):
    path = drawn(tmp_path, text)
    with pytest.raises(ModelError) as err:
        parse_linkage(path)
    message = str(err.value)
    assert str(path) in message and "[joints] A x" in message and "\n" not in message, message
    assert words in message, message


def test_a_parameter_may_use_the_ones_before_it(tmp_path):
    path = drawn(tmp_path, "c", params='a = "30 mm", b = "12 mm", c = "a + b"')
    np.testing.assert_allclose(parse_linkage(path).points["A"][0], (A_MM + B_MM) * 1e-3, rtol=0, atol=rounding(0.1))


@pytest.mark.parametrize("params, words", [
    ('"in" = "1 mm"', "parameter name 'in'"),       # an inch to pint, a keyword to Python
    ('"my-len" = "1 mm"', "parameter name 'my-len'"),
    ('a = "-b", b = "1 mm"', "'b' is not a parameter"),  # only earlier parameters
    ('b = "1 mm", a = "--b"', "two signs"),
])
def test_a_bad_parameter_is_a_named_error(tmp_path, params, words):
    path = drawn(tmp_path, "0 mm", params=params)
    with pytest.raises(ModelError, match=r"expr\.toml") as err:
        parse_linkage(path)
    assert words in str(err.value), str(err.value)
