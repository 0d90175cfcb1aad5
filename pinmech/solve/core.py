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

The core's import (refused with a `CoreBuildError` beside another Pinocchio than it was
compiled against) and its construction from closures live in pinmech/model/closure_core.py,
where the model's own closure rows are evaluated too.
"""

from __future__ import annotations

import pinocchio as pin

from pinmech.model.closure_core import CUT_CODES, DEFAULT_TOL, CompiledModel, _core, check_pinocchio, compile_loops

__all__ = ["CUT_CODES", "DEFAULT_TOL", "CompiledModel", "ModelShape", "_core", "check_pinocchio", "compile_loops",
           "core_for", "set_certify"]


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


def core_for(solver) -> _core.Core | None:
    """The compiled core of a `LoopSolver` (built once per model and tree; a new tolerance
    is set on it), or None where it has no loops (an open chain: the drivers are the pose)."""
    cached = solver.__dict__.get("_compiled")
    if cached is None or not cached[0].matches(solver.model):
        cached = (ModelShape(solver.model), _build(solver))
        solver.__dict__["_compiled"] = cached
    compiled = cached[1]
    if compiled is not None and compiled.tol != solver.tol:
        compiled.tol = solver.tol
    if compiled is not None:
        set_certify(compiled, getattr(solver, "certify", "every-pose"))
        from pinmech.solve.kernels import kept

        kept(solver.__dict__, compiled, solver.model, getattr(solver, "kernel", "generic"))
    return compiled


def set_certify(compiled: _core.Core, certify: str) -> None:
    """Set a checked certification level (certify.py) on a compiled core."""
    from pinmech.solve.certify import core_level

    level = core_level(certify)
    if compiled.certify_every != level:
        compiled.certify_every = level


def _build(solver) -> _core.Core | None:
    closures = solver.mechanism.closures
    if not closures or solver.model.nv == 0:
        return None
    core = compile_loops(solver.model, closures, solver.mechanism.velocity_scale(), tol=solver.tol,
                         drv_v=solver._drv_v, dep_v=solver._dep_v, drv_q=solver._drv_q,
                         blocks=solver.structure.blocks)[0]
    core.set_pivots([int(v) for v, ok in zip(solver._dep_v, solver.dep_is_scalar) if ok])
    return core
