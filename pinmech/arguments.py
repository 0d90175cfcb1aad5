"""Numbers handed to the Python API, read once at its edge: a named error, never numpy's.

`np.asarray("x", dtype=float)` raises numpy's ValueError, a dict a TypeError, a huge int
an OverflowError, a 1-D array where a 2-D one is wanted an IndexError deep inside; each
argument is converted here and refused with the argument's name and what it was given.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from pinmech.exceptions import ModelError


_FLOAT64 = np.dtype(np.float64)  # numpy's one instance of it (an `is` test: no conversion)


def float_array(value: Any, name: str, shape: tuple[int | None, ...], source: str | None = None) -> np.ndarray:
    """`value` as a float64 array of `shape` (None: any length on that axis), every entry
    finite: the one check of an array argument of the Python API. Complex, boolean or text
    values are refused, never cast (numpy would drop an imaginary part, read True as 1).

    Raises:
        ModelError: naming `name`, the shape wanted and what was given (`source`: the model file).
    """
    if (type(value) is np.ndarray and value.dtype is _FLOAT64 and len(shape) == 1  # one pose's vector:
            and value.shape == shape and all_finite(value.tolist())):  # plain floats, no numpy calls
        return value
    wrong = not_real(value)
    if wrong:
        raise ModelError(f"{name} must be real numbers (SI), got {wrong}: pinmech does not cast them", path=source)
    try:
        out = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(f"{name} must be {_shape_words(shape)} numbers (SI), got {value!r:.80}",
                         path=source) from None
    right = out.ndim == len(shape) and all(n is None or n == k for n, k in zip(shape, out.shape))
    if not right or not np.all(np.isfinite(out)):
        raise ModelError(f"{name} must be {_shape_words(shape)} finite numbers (SI), got shape {out.shape}"
                         + ("" if not right else " with a non-finite number"), path=source)
    return out


def all_finite(values: list[float]) -> bool:
    """Whether every float of `values` is finite: their sum is (one pass in C), unless it
    overflowed, when each is looked at (a NaN or an infinity makes the sum NaN or infinite)."""
    total = sum(values)
    return total - total == 0.0 or all(map(math.isfinite, values))


def _shape_words(shape: tuple[int | None, ...]) -> str:
    if len(shape) == 1 and shape[0] is not None:
        return str(shape[0])
    return "an (" + ", ".join("N" if n is None else str(n) for n in shape) + ") array of"


_NOT_REAL = {"b": "booleans", "c": "complex numbers", "U": "text", "S": "text", "M": "dates", "m": "time spans"}


def not_real(x: Any) -> str:
    """What in `x` (an array, a list of numbers or of rows) is not a real number, numpy
    would cast in silence (a complex's imaginary part dropped, True read as 1): "booleans",
    "complex numbers", "text"; "" when it holds real numbers (or is no array at all)."""
    if isinstance(x, np.ndarray) and x.dtype.kind in "fiu":
        return ""
    try:
        kind = np.asarray(x).dtype.kind
    except (TypeError, ValueError):
        return ""  # ragged or odd: the conversion that follows names it
    if kind in _NOT_REAL:
        return _NOT_REAL[kind]
    items = x.tolist() if isinstance(x, np.ndarray) else x
    rows = items if isinstance(items, (list, tuple)) else [items]
    for row in rows:
        for v in row if isinstance(row, (list, tuple, np.ndarray)) else [row]:
            if isinstance(v, (bool, np.bool_)):
                return "booleans"
            if isinstance(v, (complex, np.complexfloating)):
                return "complex numbers"
    return ""


def real_number(value: Any, name: str) -> float:
    """A finite real number (not a bool), as a float.

    Raises:
        ModelError: naming `name` and the value.
    """
    try:
        number = float(value) if not isinstance(value, (bool, complex, str)) else None
    except (TypeError, ValueError, OverflowError):
        number = None
    if number is None or not np.isfinite(number):
        raise ModelError(f"{name} must be a finite number, got {value!r:.60}")
    return number


def file_path(value: Any, what: str, error: type[Exception] = ModelError) -> Path:
    """A str or os.PathLike as a Path; else `error` naming `what` and the value."""
    if isinstance(value, (str, os.PathLike)) and not isinstance(value, bytes):
        return Path(value)
    raise error(f"{what} must be a file path (str or pathlib.Path), got {type(value).__name__} {value!r:.60}")


def names(value: Any, what: str) -> tuple[str, ...]:
    """A list or tuple of joint names (strings), as a tuple; else ModelError naming `what`."""
    if isinstance(value, (list, tuple)) and all(isinstance(n, str) for n in value):
        return tuple(value)
    raise ModelError(f"{what} must be a list of joint names (strings), got {value!r:.60}")


def instance_of(value: Any, kind: type, what: str) -> Any:
    """`value` if it is a `kind`; else a ModelError naming `what` and what it got (a
    `pinmech.Scene` given as a path string, an Analysis as a dict)."""
    if isinstance(value, kind):
        return value
    raise ModelError(f"{what} must be a pinmech.{kind.__name__}, got {type(value).__name__} {value!r:.60}"
                     + (f" (load it first: pinmech.{kind.__name__}.load(...))" if kind.__name__ == "Scene" else ""))

