"""A loop solver's options and shared pieces: the tolerances and limits (the compiled
core's constants), their ranges, the lock that serializes a solver's calls, and the
reference pose that names an assembly."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from pinmech.exceptions import OptionError
from pinmech.solve.core import _core

#: Default closure tolerance (dimensionless: metres per metre of mechanism, or radians).
DEFAULT_TOL = _core.DEFAULT_TOL
#: Largest Newton step of one joint [rad, or mechanism sizes for a prismatic joint].
MAX_STEP = _core.MAX_NEWTON_STEP
#: Default largest condition number accepted before a pose is called singular. Near a
#: singularity accelerations lose accuracy like eps x condition^3 (tests/test_singular.py),
#: so 1e4 keeps every acceleration pinmech gives to about 1e-3 relative or better.
DEFAULT_MAX_CONDITION = 1e4
#: With the default tolerance or a tighter one, a pose that ends between this residual and
#: the tolerance gets one more Newton step: it costs one kinematics pass and lands at
#: rounding level, so results do not depend on how close the guess happened to be.
POLISH = _core.POLISH
#: The ranges of the solver's options, for the Python API as for a scene's [solver] table.
SOLVER_RANGES = {"tol": (1e-16, 1e-3), "max_iterations": (1, 1000), "max_condition": (1.0, math.inf)}

_Method = TypeVar("_Method", bound=Callable[..., Any])


def serialized(method: _Method) -> _Method:
    """A solver method that holds the solver's lock: threads sharing one solver take turns
    (its Pinocchio `Data` and buffers hold one pose at a time), the same thread re-enters.
    It first reads again what the user may have changed in the model (`refresh`, where
    the solver has one)."""
    @functools.wraps(method)
    def locked(self, *args, **kwargs):
        if self.lock._is_owned():  # called from within the solver: held and refreshed already
            return method(self, *args, **kwargs)
        with self.lock:
            refresh = getattr(self, "refresh", None)
            if refresh is not None:
                refresh()
            return method(self, *args, **kwargs)
    return locked  # type: ignore[return-value]


def checked_option(name: str, value: Any) -> float | int:
    """A solver option within `SOLVER_RANGES` (a number, not NaN; max_iterations whole).

    Raises:
        OptionError: naming the option, the value and the range.
    """
    low, high = SOLVER_RANGES[name]
    whole = name == "max_iterations"
    try:
        number = float(value) if isinstance(value, (int, float, np.number)) and not isinstance(value, bool) else math.nan
    except OverflowError:  # an int beyond float64
        number = math.inf
    ok = low <= number <= high and (not whole or number == int(number))  # NaN is in no range
    if not ok:
        kind = "a whole number" if whole else "a number"
        raise OptionError(f"{name} = {value!r} must be {kind} in [{low:g}, {high:g}]", option=name, value=value)
    return int(number) if whole else number


@dataclass(frozen=True)
class Reference:
    """The pose that names the assembly: the drivers' values [rad or m], the closed q,
    its assembly signature, whether other poses must keep it (False: "any"), and the
    Newton iterations that closed it from its guess."""

    driver_q: np.ndarray
    q: np.ndarray
    signs: tuple[int, ...]
    keep: bool = True
    iterations: int = 0

    def __post_init__(self) -> None:
        """The arrays are read-only copies: the solver goes on from them, so a write into
        the ones the API returns must not change its reference."""
        for name in ("driver_q", "q"):
            array = np.array(getattr(self, name), dtype=float)
            array.flags.writeable = False
            object.__setattr__(self, name, array)


class SolverOptions:
    """A solver's options (a loop solver's, a rate solver's), each checked when set, also
    later: the numbers against SOLVER_RANGES, the dial and the kernel against their names."""

    @property
    def tol(self) -> float:
        """Closure tolerance (dimensionless, of each loop's size), in SOLVER_RANGES."""
        return self._tol

    @tol.setter
    def tol(self, value: float) -> None:
        self._tol = checked_option("tol", value)

    @property
    def max_iterations(self) -> int:
        """Newton iteration cap, in SOLVER_RANGES."""
        return self._max_iterations

    @max_iterations.setter
    def max_iterations(self, value: int) -> None:
        self._max_iterations = checked_option("max_iterations", value)

    @property
    def max_condition(self) -> float:
        """Largest condition number accepted before a pose is singular, in SOLVER_RANGES."""
        return self._max_condition

    @max_condition.setter
    def max_condition(self, value: float) -> None:
        self._max_condition = checked_option("max_condition", value)

    @property
    def certify(self) -> str:
        """The certification dial (certify.py): "every-pose", "every-K", "ends" or "none"."""
        return self._certify

    @certify.setter
    def certify(self, value: str) -> None:
        from pinmech.solve.certify import checked_certify

        self._certify = checked_certify(value)

    @property
    def kernel(self) -> str:
        """The kinematic passes (kernels.py): "generic", "generated" or "auto"."""
        return self._kernel

    @kernel.setter
    def kernel(self, value: str) -> None:  # "GENERATED" ran the generic passes in silence
        from pinmech.solve.kernels import checked_kernel

        self._kernel = checked_kernel(value)
