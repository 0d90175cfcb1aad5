"""The bridge to pinmech's compiled core (pinmech/csrc): the user's own `pin.Model`, taken
by reference, with a `LoopSolver`'s closure rows and assembly blocks, once per solver.

The core reads the model at every call, so a joint or frame placement changed in it
(`model.jointPlacements[j] = ...`) is used at the next call with nothing rebuilt; only a
changed tree (joints or frames added) or another model object builds a new core. It
serves every joint Pinocchio has (mimic, composite, helical, universal, ellipsoid...).
It is the one engine: the closure rows, the Newton of `close`, the predictor-corrector
continuation with every assembly rule (trust region, tangent turn, signature, change
points, folds followed on a joint parameter) are written once, in C++; Python orders
the calls and names what the core reports (continuation.py, cycle.py).

The core is compiled against the Pinocchio of the `libpinocchio` build requirement and
shares `pin`'s Model objects and libraries: both must be the same version (pinned in
pyproject.toml); a mismatch is refused here, at import, with a `CoreBuildError`.
"""

from __future__ import annotations

import importlib.util
import os

import numpy as np
import pinocchio as pin

from pinmech.exceptions import CoreBuildError, ModelError
from pinmech.seeded import Seeded

_REINSTALL = "reinstall pinmech beside this pin (`pip install --force-reinstall --no-deps .` in its checkout)"


def _import_core():
    """pinmech._core, or a CoreBuildError saying what to do."""
    try:
        from pinmech import _core
    except ImportError as error:
        if importlib.util.find_spec("pinmech._core") is None:  # e.g. `python -m pinmech` in a checkout
            raise ImportError(f"pinmech's compiled core is missing from {os.path.dirname(__file__)}, a source "
                              "tree without its build: run pinmech from outside the checkout, or install the "
                              f"checkout with `pip install -e .` ({error})") from error
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


class ModelShape:
    """What a core depends on in a model a user may change: the model object itself and its
    tree (joints, frames, sizes). Not its placements, which the core reads at every call."""

    def __init__(self, model: pin.Model, frame_ids=()) -> None:
        self.model = model
        self.key = _shape(model)

    def matches(self, model: pin.Model) -> bool:
        return model is self.model and _shape(model) == self.key


def _shape(model: pin.Model) -> tuple:
    return model.nq, model.nv, model.njoints, model.nframes, tuple(model.parents)


class CompiledModel:
    """The frames of a `pin.Model` a core names by index.

    Attributes:
        frames: Pinocchio frame id -> its index among the core's frames.
    """

    def __init__(self, model: pin.Model, frame_ids: list[int]) -> None:
        self.frames = {int(fid): i for i, fid in enumerate(dict.fromkeys(int(f) for f in frame_ids))}
        self.frame_ids = list(self.frames)


def core_for(solver) -> _core.Core | None:
    """The compiled core of a `LoopSolver` (built once per model and tree; a new tolerance
    is set on it), or None where it has no loops (an open chain: the drivers are the pose).

    Raises:
        ModelError: the core reads a loop's closure rows otherwise than its Closure states.
    """
    cached = solver.__dict__.get("_compiled")
    if cached is None or not cached[0].matches(solver.model):
        cached = (ModelShape(solver.model), _build(solver))
        solver.__dict__["_compiled"] = cached
    compiled = cached[1]
    if compiled is not None and compiled.tol != solver.tol:
        compiled.tol = solver.tol
    return compiled


def _build(solver) -> _core.Core | None:
    closures = solver.mechanism.closures
    if not closures or solver.model.nv == 0:
        return None
    core = compile_loops(solver.model, closures, solver.mechanism.velocity_scale(), tol=solver.tol,
                         drv_v=solver._drv_v, dep_v=solver._dep_v, drv_q=solver._drv_q,
                         blocks=solver.structure.blocks, source=str(solver.mechanism.source))[0]
    core.set_pivots([int(v) for v, ok in zip(solver._dep_v, solver.dep_is_scalar) if ok])
    return core


def compile_loops(model: pin.Model, closures: list, v_scale: np.ndarray, *, extra_frames: list[int] = (),
                  tol: float = DEFAULT_TOL, drv_v=(), dep_v=(), drv_q=(), blocks=(), source: str = ""):
    """A core of the model with its loop closures (rows as the Closure objects state them)
    and the frames asked, with the drivers' and dependent joints' indices for sweeps:
    (core, its CompiledModel).

    Raises:
        ModelError: the core's closure rows disagree with the Closure objects (`disagreement`).
    """
    compiled = CompiledModel(model, [f for c in closures for f in (c.parent_frame, c.child_frame)]
                             + list(extra_frames))
    for c in closures:  # what the core copies stays as it is
        c.__dict__["_in_use"] = True
    rows6 = [np.ascontiguousarray(c._rows6, dtype=float) for c in closures]
    full = [np.ascontiguousarray(c.selected * c._scale(), dtype=float) for c in closures]
    axes = np.array([c.axis for c in closures], dtype=float).reshape(-1, 3)
    child_axes = np.array([c.child_axis for c in closures], dtype=float).reshape(-1, 3)
    core = _core.Core(
        model, compiled.frame_ids, [CUT_CODES[c.cut_type] for c in closures],
        [compiled.frames[c.parent_frame] for c in closures], [compiled.frames[c.child_frame] for c in closures],
        axes, child_axes, rows6, full, [int(v) for v in drv_v], [int(v) for v in dep_v],
        [int(i) for i, _ in drv_q], [int(c) for _, c in drv_q], np.asarray(v_scale, dtype=float),
        [list(map(int, b.rows)) for b in blocks], [list(map(int, b.cols)) for b in blocks], float(tol),
    )
    gap = disagreement(core, model, closures)
    if gap is not None:
        raise ModelError(f"the compiled core reads the closure rows of loop(s) "
                         f"{', '.join(c.name for c in closures)} otherwise than they are stated (largest difference "
                         f"{gap:.3g} of their size at a test pose, above 1e-12): pinmech cannot solve this cut",
                         path=source or None)
    return core, compiled


def disagreement(core: _core.Core, model: pin.Model, closures: list) -> float | None:
    """None where the core's closure rows and their Jacobian are those the Closure objects
    state, at a seeded random configuration (to 1e-12 of their size; the same formulas in
    another order agree to 1e-15), else the largest difference relative to that size: a
    cut the core would read otherwise is refused, never solved to other numbers."""
    if not closures:
        return None
    rng = Seeded(20261122)
    q = pin.integrate(model, pin.neutral(model), rng.uniform(-1.0, 1.0, model.nv))
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    r = np.concatenate([c.residual(data) for c in closures])
    J = np.vstack([c.jacobian(model, data) for c in closures])
    scale = 1.0 + max(float(np.abs(r).max()), float(np.abs(J).max()))
    gap = max(float(np.abs(core.residual(q) - r).max()), float(np.abs(core.jacobian(False) - J).max())) / scale
    return gap if not gap <= 1e-12 else None
