"""Numbers handed to the Python API, read once at its edge: a named error, never numpy's.

`np.asarray("x", dtype=float)` raises numpy's ValueError, a dict a TypeError, a huge int
an OverflowError, a 1-D array where a 2-D one is wanted an IndexError deep inside; each
argument is converted here and refused with the argument's name and what it was given.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from pinmech.exceptions import ModelError


def float_array(value: Any, name: str, shape: tuple[int | None, ...]) -> np.ndarray:
    """`value` as a float64 array of `shape` (None: any length on that axis), every entry
    finite.

    Raises:
        ModelError: naming `name`, the shape wanted and what was given.
    """
    wanted = " x ".join("N" if n is None else str(n) for n in shape)
    try:
        out = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        out = None
    ok = (out is not None and out.ndim == len(shape)
          and all(n is None or n == m for n, m in zip(shape, out.shape)) and bool(np.all(np.isfinite(out))))
    if not ok:
        got = f"shape {out.shape}" if out is not None else type(value).__name__
        raise ModelError(f"{name} must be {wanted} finite numbers, got {got} ({value!r:.60})")
    return out


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
