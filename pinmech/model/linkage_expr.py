"""Lengths of a drawn linkage written with its parameters: `"crank"`, `"-a"`, `"2*a + b/2"`.

A length in a linkage file is either one quantity with its unit (`"15 mm"`, read by
`pinmech.units.to_si`) or an arithmetic expression over the file's `[params]` and plain
numbers. The expression is read by Python's `ast` and only this grammar is evaluated:

    expr   := term (("+" | "-") term)*          both sides lengths
    term   := factor (("*" | "/") factor)*      at most one length in a product; divide by numbers only
    factor := ["+" | "-"] atom                  one sign, never two ("--a", "+-a", "a - -b"; "a - (-b)" has one)
    atom   := PARAM | NUMBER | "(" expr ")"

Everything else is refused with a `ModelError` naming the file, the key and the text:
`**`, implicit multiplication (`"2 a"` or `"2a"` would be 2 years to pint: written with a parameter's
name as its unit it is ambiguous), unknown names, division by zero, a result that is not a
length or not finite, or a magnitude beyond `units.MAX_MAGNITUDE`.
"""

from __future__ import annotations

import ast
import functools
import keyword
import math
import re
import warnings
from typing import Any

from pinmech.exceptions import ModelError, UnitError
from pinmech.units import MAX_MAGNITUDE, to_si

#: Longer texts are not read as expressions (a guard on the parser's work and depth).
MAX_TEXT = 200
_BINARY = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/"}
#: A number then a name, with or without a space between: "2 a", "3m", "1e3mm".
_NUMBER_AND_NAME = re.compile(r"(?P<number>[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?)\s*(?P<name>[^\W\d]\w*)")


class _Refused(Exception):
    """Why an expression is not read (turned into a ModelError by `length`)."""


def check_param_name(name: str, source: str) -> None:
    """A parameter is named as an identifier that is not a Python keyword (`in` is an inch).

    Raises:
        ModelError: naming the file and the parameter.
    """
    if not name.isidentifier() or keyword.iskeyword(name):
        raise ModelError(f"parameter name {name!r} must be letters, digits and _ (not starting with a digit, "
                         "not a word such as 'in' or 'and'), so that expressions can use it",
                         path=source, element=f"[params] {name}")


@functools.lru_cache(maxsize=4096)
def _is_angle_text(value: str) -> bool:
    try:
        to_si(value, "angle")
    except UnitError:
        return False
    return True


def is_angle(value: Any) -> bool:
    """Whether a `[params]` value is one quantity with an angle's unit ("25 deg", "0.4 rad")."""
    return isinstance(value, str) and _is_angle_text(value)


def length(value: Any, params: dict[str, float], source: str, where: str) -> float:
    """A length [m]: a quantity with its unit, or an expression over `params` [m].

    Raises:
        ModelError: anything but one quantity or one expression of the grammar above.
    """
    if not isinstance(value, str):
        return _quantity(value, source, where)
    text = value.strip().replace("\u2212", "-")  # a typographic minus sign is a minus sign
    tree, named = _parse(text)
    if not named:
        _refuse_unit_named_as_param(text, params, source, where)
        try:
            return _quantity(value, source, where)
        except ModelError:
            used = sorted(set(re.findall(r"[A-Za-z_]\w*", text)) & set(params))
            if not used:
                raise
            raise ModelError(f"{value!r} mixes the parameter(s) {', '.join(used)} with quantities: an expression "
                             "holds parameters, plain numbers, + - * / and parentheses (put '1 mm' in [params])",
                             path=source, element=where) from None
    try:
        result, is_length = _evaluate(tree.body, params, text.encode())
    except _Refused as exc:
        raise ModelError(f"{value!r}: {exc}", path=source, element=where) from None
    if not is_length:
        raise ModelError(f"{value!r} is a plain number, not a length: use a parameter or a unit", path=source,
                         element=where)
    if not math.isfinite(result) or abs(result) > MAX_MAGNITUDE:
        raise ModelError(f"{value!r} is {result:.3g} m, beyond the {MAX_MAGNITUDE:g} m pinmech computes with",
                         path=source, element=where)
    return result


@functools.lru_cache(maxsize=4096)
def _parse(text: str) -> tuple[ast.Expression | None, bool]:
    """The expression's tree, or None when the text is no expression (a quantity "15 mm"),
    and whether it names anything (a parameter). Kept per text: a study redraws a linkage
    for every variant, and the trees are only read."""
    if len(text) > MAX_TEXT:
        return None, False
    try:
        with warnings.catch_warnings():  # "15mm": Python's SyntaxWarning, on stderr, is no message of ours
            warnings.simplefilter("ignore", SyntaxWarning)
            tree = ast.parse(text, mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return None, False
    return tree, any(isinstance(n, ast.Name) for n in ast.walk(tree))


def quantity_si(value: Any, kind: str, source: str, where: str) -> float:
    """A quantity as written ("15 mm", "30 deg") in SI: `units.to_si`, kept per text (a
    redrawing reads the same texts again).

    Raises:
        ModelError: naming the file and the key.
    """
    try:
        if isinstance(value, (str, int, float)) and not isinstance(value, bool):
            return _si(value, kind)
        return to_si(value, kind, where=where)
    except UnitError:
        try:
            to_si(value, kind, where=where)  # the message, with the key it was written under
        except UnitError as exc:
            raise ModelError(str(exc), path=source) from exc
        raise


@functools.lru_cache(maxsize=4096)
def _si(value: str | int | float, kind: str) -> float:
    return to_si(value, kind)


def _quantity(value: Any, source: str, where: str) -> float:
    return quantity_si(value, "length", source, where)


def _refuse_unit_named_as_param(text: str, params: dict[str, float], source: str, where: str) -> None:
    """`"2 a"` with a parameter `a`: 2 years to pint, 2*a to a reader; neither is guessed."""
    glued = _NUMBER_AND_NAME.fullmatch(text)  # "2 a", and "3m" (3 metres to pint) beside a parameter m
    words = [glued["number"], glued["name"]] if glued else text.split()
    if len(words) == 2 and words[1] in params:
        number, name = words
        raise ModelError(f"{text!r} is ambiguous: '{name}' is a parameter and a unit; write "
                         f"'{number}*{name}' for the parameter times {number}, or the quantity with "
                         "another spelling of its unit", path=source, element=where)


def _evaluate(node: ast.AST, params: dict[str, float], text: bytes) -> tuple[float, bool]:
    """The value of a node of `text` (its UTF-8 bytes) and whether it is a length [m] (else a
    plain number)."""
    if isinstance(node, ast.Name):
        if node.id not in params:
            known = ", ".join(params) or "none"
            raise _Refused(f"'{node.id}' is not a parameter (params: {known})")
        return params[node.id], True
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise _Refused(f"{node.value!r} is not a number")
        try:
            number = float(node.value)
        except OverflowError:
            raise _Refused("a number too large for a float") from None
        if not math.isfinite(number):
            raise _Refused(f"{number!r} is not a finite number")
        return number, False
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub)):
        if isinstance(node.operand, ast.UnaryOp) and not _bracketed(node.operand, text):
            raise _Refused("two signs in a row: write one sign")
        value, is_length = _evaluate(node.operand, params, text)
        return (-value if isinstance(node.op, ast.USub) else value), is_length
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        return _binary(node, params, text)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
        raise _Refused("'**' (a power) is not a length: write products out")
    raise _Refused("only parameters, numbers, + - * / and parentheses are read")


def _bracketed(node: ast.AST, text: bytes) -> bool:
    """Whether `node` of `text` opens right after a "(": `-(-a)` and `a - (-b)` hold one sign
    each, `--a` and `a - -b` two in a row (ast drops the parentheses)."""
    return text[: node.col_offset].rstrip().endswith(b"(")


def _binary(node: ast.BinOp, params: dict[str, float], text: bytes) -> tuple[float, bool]:
    symbol = _BINARY[type(node.op)]
    if symbol in "+-" and isinstance(node.right, ast.UnaryOp) and not _bracketed(node.right, text):
        raise _Refused(f"a sign right after '{symbol}': write one sign")
    (a, a_len), (b, b_len) = _evaluate(node.left, params, text), _evaluate(node.right, params, text)
    if symbol in "+-":
        if a_len != b_len:
            raise _Refused(f"'{symbol}' between a length and a plain number: give both a unit or a parameter")
        result, is_length = (a + b if symbol == "+" else a - b), a_len
    elif symbol == "*":
        if a_len and b_len:
            raise _Refused("a length times a length is an area, not a length")
        result, is_length = a * b, a_len or b_len
    else:
        if b_len:
            raise _Refused("dividing by a length gives no length: divide by plain numbers")
        if b == 0:
            raise _Refused("division by zero")
        result, is_length = a / b, a_len
    if not math.isfinite(result) or abs(result) > MAX_MAGNITUDE:
        raise _Refused(f"{result:.3g} is beyond the {MAX_MAGNITUDE:g} pinmech computes with")
    return result, is_length
