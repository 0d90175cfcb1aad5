"""The drivers' values as a loop solver takes them: in SI, in the drivers' order (by
position or by name), checked once at the edge; the rest of a turn; the joints whose
single coordinate can parametrize a path."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import pinocchio as pin

from pinmech.arguments import not_real
from pinmech.exceptions import MobilityError, UnitError
from pinmech.model.mechanism import Mechanism

def turn_remainder(x0: float, x1: float) -> float:
    """x1 - x0 less its whole turns [rad], with the sign of x1 - x0: the rest of the way
    once the turns repeat. The angles are reduced by sin and cos, whose argument
    reduction is exact: x1 - x0 itself, rounded to the spacing of x1, lost the pose
    (0.06 rad at 1e15 rad, and the loop was left open by 0.03 of its size)."""
    reduced = math.remainder(math.atan2(math.sin(x1), math.cos(x1)) - math.atan2(math.sin(x0), math.cos(x0)),
                             2 * math.pi)
    if reduced * (x1 - x0) < 0:
        reduced += math.copysign(2 * math.pi, x1 - x0)
    return reduced


def index_view(indices: np.ndarray) -> slice | np.ndarray:
    """A slice when the indices are contiguous (a view, cheaper than fancy indexing)."""
    if len(indices) and np.array_equal(indices, np.arange(indices[0], indices[-1] + 1)):
        return slice(int(indices[0]), int(indices[-1]) + 1)
    return indices


def one_coordinate(model: pin.Model, v: int) -> bool:
    """Velocity index v moves one coordinate alone: a one-freedom joint, or a one-freedom
    joint inside a composite (MJCF's several hinges in one body), which the
    continuation can hold fixed as its curve's parameter."""
    for joint in model.joints[1:]:
        if joint.idx_v <= v < joint.idx_v + joint.nv:
            if joint.nv == 1:
                return True
            if joint.shortname() != "JointModelComposite":
                return False
            offset = joint.idx_v
            for part in joint.extract().joints:
                if offset <= v < offset + part.nv:
                    return part.nv == 1
                offset += part.nv
    return False


def ordered_values(values: Sequence[float] | Mapping[str, float] | None, drivers: tuple[str, ...],
                   mobility: int) -> np.ndarray:
    """Driver values [rad or m, or their rates] in the order of `drivers`: a sequence in
    that order or a mapping by name (missing names are 0; None: all 0).

    Raises:
        MobilityError: an unknown driver name, or not one finite value per driver.
        UnitError: values that are not real numbers in SI (quantities, text).
    """
    if (type(values) is np.ndarray and values.shape == (len(drivers),) and values.dtype == float
            and math.isfinite(sum(values.tolist()))):
        return values  # already in order (a sweep's arrays: no conversion)
    if values is None:
        return np.zeros(len(drivers))
    if isinstance(values, Mapping):
        unknown = set(values) - set(drivers)
        if unknown:
            raise MobilityError(f"{', '.join(sorted(unknown))} is not a driver ({', '.join(drivers)})",
                                mobility=mobility, drivers=len(drivers))
        values = [values.get(n, 0.0) for n in drivers]
    wrong = not_real(values)
    if wrong:
        hint = ": convert quantities first, e.g. pinmech.to_si('30 deg', 'angle')" if wrong == "text" else ""
        raise UnitError(f"driver values of {', '.join(drivers)} must be real numbers in SI (rad or m), "
                        f"got {wrong}, which pinmech does not cast{hint}")
    try:
        out = np.asarray(values, dtype=float).reshape(-1)
    except (TypeError, ValueError, OverflowError):
        raise UnitError(f"driver values of {', '.join(drivers)} must be numbers in SI (rad or m), "
                        f"got {values!r:.80}: convert quantities first, e.g. pinmech.to_si('30 deg', "
                        f"'angle')") from None
    if out.shape != (len(drivers),) or not math.isfinite(sum(out.tolist())):
        raise MobilityError(f"expected {len(drivers)} finite driver value(s), got {values!r}",
                            mobility=mobility, drivers=len(drivers))
    return out


def check_mobility(mechanism: Mechanism, drivers: tuple[str, ...]) -> None:
    """Raise MobilityError unless the drivers are distinct and as many as the mobility."""
    if len(set(drivers)) != len(drivers):
        raise MobilityError(f"a joint is driven twice: {', '.join(drivers)}",
                            mobility=mechanism.mobility, drivers=len(drivers))
    mobility = mechanism.mobility
    if mobility != len(drivers):
        raise MobilityError(
            f"{mechanism.source}: the mechanism has {mechanism.model.nv} joint freedoms and "
            f"{mechanism.constraint_rows} independent closure equations, so mobility {mobility}; "
            f"{len(drivers)} driver(s) given ({', '.join(drivers) or 'none'})",
            mobility=mobility, drivers=len(drivers))
