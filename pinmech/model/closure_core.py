"""The closure rows of a model's loop cuts, evaluated by pinmech's compiled core, the one
place they are written (pinmech/csrc/closure.cpp): residual, Jacobian, drift, each cut's
pose error and the rows' change under frame translations or motions.

A `Closure` (closures.py) states a cut: its frames, type, axes and row basis. The core
reads the user's own `pin.Model` at every call (a placement changed in it is used at the
next call); `ClosureRows` is a core with a cut list and no drivers, for the code that
needs the rows outside a solver (building a model, mobility, forces, sensitivities);
`compile_loops` builds the core a solver drives (pinmech/solve/core.py).

The core is compiled against the Pinocchio of the `libpinocchio` build requirement and
shares `pin`'s Model objects and libraries: both must be the same version (pinned in
pyproject.toml); a mismatch is refused here, at import, with a `CoreBuildError`.
"""

from __future__ import annotations

import importlib.util
import os

import numpy as np
import pinocchio as pin

from pinmech.exceptions import CoreBuildError
from pinmech.model.closures import Closure

_REINSTALL = "reinstall pinmech beside this pin (`pip install --force-reinstall --no-deps .` in its checkout)"


def _import_core():
    """pinmech._core, or a CoreBuildError saying what to do."""
    try:
        from pinmech import _core
    except ImportError as error:
        if importlib.util.find_spec("pinmech._core") is None:  # e.g. `python -m pinmech` in a checkout
            raise ImportError(f"pinmech's compiled core is missing from {os.path.dirname(os.path.dirname(__file__))}, "
                              "a source tree without its build: run pinmech from outside the checkout, or install "
                              f"the checkout with `pip install -e .` ({error})") from error
        # there, but it does not load: a library of another pin/Boost than it was linked to
        raise CoreBuildError(f"pinmech's compiled core does not load beside pin {pin.__version__} ({error}): "
                             f"{_REINSTALL}", loaded=pin.__version__) from error
    check_pinocchio(_core.PINOCCHIO_VERSION, pin.__version__)
    return _core


def check_pinocchio(built: str, loaded: str) -> None:
    """Raise CoreBuildError unless the core was compiled against the Pinocchio `pin` loads
    (the core shares pin's Model objects: their layout is that version's)."""
    if built != loaded:
        raise CoreBuildError(f"pinmech's compiled core was built against Pinocchio {built} but pin {loaded} is "
                             f"installed: install pin=={built}, or {_REINSTALL}", built=built, loaded=loaded)


_core = _import_core()
CUT_CODES = {"revolute": 0, "prismatic": 1, "spherical": 2, "fixed": 3}
DEFAULT_TOL = _core.DEFAULT_TOL


class CompiledModel:
    """The frames of a `pin.Model` a core names by index.

    Attributes:
        frames: Pinocchio frame id -> its index among the core's frames.
    """

    def __init__(self, model: pin.Model, frame_ids: list[int]) -> None:
        self.frames = {int(fid): i for i, fid in enumerate(dict.fromkeys(int(f) for f in frame_ids))}
        self.frame_ids = list(self.frames)


def compile_loops(model: pin.Model, closures: list[Closure], v_scale: np.ndarray, *, extra_frames: list[int] = (),
                  tol: float = DEFAULT_TOL, drv_v=(), dep_v=(), drv_q=(), blocks=(), selected: bool = False):
    """A core of the model with its loop closures (the rows their Closure objects state;
    with `selected`, every selected row before the basis reduces them, and the closures
    stay free to take a basis) and the frames asked, with the drivers' and dependent
    joints' indices for sweeps: (core, its CompiledModel)."""
    compiled = CompiledModel(model, [f for c in closures for f in (c.parent_frame, c.child_frame)]
                             + list(extra_frames))
    if not selected:
        for c in closures:  # what the core copies stays as it is
            c.__dict__["_in_use"] = True
    full = [np.ascontiguousarray(c.selected_rows6, dtype=float) for c in closures]
    rows6 = full if selected else [np.ascontiguousarray(c.rows6, dtype=float) for c in closures]
    axes = np.array([c.axis for c in closures], dtype=float).reshape(-1, 3)
    child_axes = np.array([c.child_axis for c in closures], dtype=float).reshape(-1, 3)
    core = _core.Core(
        model, compiled.frame_ids, [CUT_CODES[c.cut_type] for c in closures],
        [compiled.frames[c.parent_frame] for c in closures], [compiled.frames[c.child_frame] for c in closures],
        axes, child_axes, rows6, full, [int(v) for v in drv_v], [int(v) for v in dep_v],
        [int(i) for i, _ in drv_q], [int(c) for _, c in drv_q], np.asarray(v_scale, dtype=float),
        [list(map(int, b.rows)) for b in blocks], [list(map(int, b.cols)) for b in blocks], float(tol),
    )
    return core, compiled


class ClosureRows:
    """The stacked closure rows of `closures` on `model` (dimensionless: positions over each
    loop's size), on a core of their own. Each method takes the configuration q (nq,).

    Attributes:
        slices: each closure's rows in the stack.
    """

    def __init__(self, model: pin.Model, closures: list[Closure], selected: bool = False) -> None:
        self.model, self.closures = model, list(closures)
        self.core = compile_loops(model, self.closures, np.ones(model.nv), selected=selected)[0]
        sizes = [c.selected.shape[0] if selected else c.rows for c in self.closures]
        ends = np.cumsum([0, *sizes])
        self.slices = [slice(int(a), int(b)) for a, b in zip(ends[:-1], ends[1:])]
        self.rows = int(ends[-1])

    def matches(self, model: pin.Model, closures: list[Closure]) -> bool:
        """Whether these are the rows of `closures` on `model` as it is (its tree unchanged)."""
        return (model is self.model and self.core.same_structure and len(closures) == len(self.closures)
                and all(a is b for a, b in zip(closures, self.closures)))

    def residual(self, q: np.ndarray) -> np.ndarray:
        """The rows' values (rows,) at q."""
        return self.core.residual(q) if self.closures else np.zeros(0)

    def jacobian(self, q: np.ndarray, newton: bool = False) -> np.ndarray:
        """(rows, nv) at q: the velocity rows' map from joint velocities; with `newton`,
        the exact derivative of `residual` (the same once the loops are closed)."""
        if not self.closures:
            return np.zeros((0, self.model.nv))
        self.core.residual(q)
        return self.core.jacobian(newton)

    def drift(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The acceleration rows at zero joint accelerations (rows,) at (q, v) [1/s^2]."""
        return self.core.drift(q, v) if self.closures else np.zeros(0)

    def full_residual(self, q: np.ndarray) -> float:
        """The largest of every selected row at q, those the basis reduced away too."""
        if not self.closures:
            return 0.0
        self.core.residual(q)
        return float(self.core.full_residual())

    def errors6(self, q: np.ndarray) -> np.ndarray:
        """(cuts, 6) each cut's pose error at q before selection and scale: C's position in
        P [m], then its orientation error [rad; a revolute cut: the sine of its axes' angle]."""
        return self.core.errors6(q) if self.closures else np.zeros((0, 6))

    def translation_rows(self, q: np.ndarray) -> np.ndarray:
        """(rows, 3) at q: the rows' change per world translation [m] of each cut's child
        frame (of its parent frame: minus it)."""
        if not self.closures:
            return np.zeros((0, 3))
        self.core.residual(q)
        return self.core.translation_rows()


def cut_rows_change(closure: Closure, order: int, P: np.ndarray, C: np.ndarray, dP: np.ndarray,
                    dC: np.ndarray) -> np.ndarray:
    """The change of a cut's velocity (order 1) or acceleration (order 2) rows along a change
    of its frames' world motions. P, C (8, 3): rows x, v, w, acc, alpha, then the rotation's
    rows; dP, dC (6, 3): dx, dv, dw, dacc, dalpha and the frame's turn dtheta (world axes)."""
    return _core.cut_rows_change(np.ascontiguousarray(closure.rows6), int(order), np.ascontiguousarray(P),
                                 np.ascontiguousarray(C), np.ascontiguousarray(dP), np.ascontiguousarray(dC))


def closure_rows(mech) -> ClosureRows:
    """The closure rows of a Mechanism's closures (built once per model tree and closure list)."""
    return cached_rows(mech, mech.model, mech.closures)


def cached_rows(owner: object, model: pin.Model, closures: list[Closure]) -> ClosureRows:
    """The closure rows of `closures` on `model`, kept on `owner` (built again where the model,
    its tree or the closure list changed)."""
    cached = owner.__dict__.get("_closure_rows")
    if cached is None or not cached.matches(model, closures):
        cached = ClosureRows(model, closures)
        owner.__dict__["_closure_rows"] = cached
    return cached
