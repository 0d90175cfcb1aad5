"""Which kinematic passes a solver's compiled core runs: Pinocchio's generic algorithms
(`kernel="generic"`, the default) or a kernel generated from the same algorithms for the
model (`kernel="generated"`: kernel_build.py makes it, the core loads it), or for a long
design run "auto" (`resolved`: generated where it pays, measured).

The generated kernel writes the same numbers the generic passes write (the joints' world
placements, their Jacobians, velocities and accelerations), summed in another order: the
answers agree to rounding (tests/test_kernels.py), and the core's checks of every pose
(residual, condition number, assembly signature) run on them unchanged. Where no kernel
can be built (no compiler, no `pinmech[fast]`), one line on stderr says why and the
generic passes run. A kernel made for other joints never runs: the core refuses it
(`Core.kernel_stale`) and `kept` sets the kernel of the joints the model has now.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

from pinmech.exceptions import OptionError

if TYPE_CHECKING:
    import pinocchio as pin

#: The kinds of kinematic passes a solver may run ("auto": generated for a long design run
#: where the kernel generator is built here already, else generic; see `resolved`).
KERNELS = ("generic", "generated", "auto")

#: Poses from which "auto" runs the generated kernel. Measured (docs/explanation/kernels.md):
#: loading a cached kernel costs 2-25 ms (a warm or a fresh process), generating one 0.1-2 s,
#: and it saves 0.3 us (P1) to 3 us (the 16-loop chain) a pose: a run of 10^5 poses gains
#: at least 30 ms on P1, more than a cached kernel's loading costs, and a chain's gains pay
#: for a generation too.
AUTO_POSES = 100_000

_said: set[str] = set()  # the fallback lines printed in this process (each once)


def checked_kernel(kernel: object) -> str:
    """`kernel` if it is one of KERNELS, else an OptionError naming them."""
    if kernel not in KERNELS:
        raise OptionError(f"kernel = {kernel!r} must be one of {', '.join(KERNELS)}", option="kernel", value=kernel)
    return str(kernel)


def resolved(kernel: str, poses: int) -> str:
    """The passes a run of about `poses` poses takes: `kernel` itself, or for "auto" the
    generated kernel where the run has at least AUTO_POSES poses and the kernel generator is
    built on this machine already (its one-time build is never started by "auto"), else generic."""
    if kernel != "auto":
        return kernel
    if poses < AUTO_POSES:
        return "generic"
    from pinmech.solve.kernel_build import generator_built

    return "generated" if generator_built() else "generic"


def kept(owner: dict, core, model: pin.Model, kernel: str) -> None:
    """Set the passes `kernel` asks on `core` once per core and choice (`owner`: the solver's
    __dict__, which remembers it), and again where the model's joints changed in place since
    its kernel was made (a joint's type or axis: the old kernel would answer for the old joints)."""
    if owner.get("_kernel_set") != (id(core), kernel) or core.kernel_stale:
        attach(core, model, kernel)
        owner["_kernel_set"] = (id(core), kernel)


def attach(core, model: pin.Model, kernel: str) -> str | None:
    """Set the passes `kernel` asks on `core` (a compiled Core of `model`): the generated
    kernel's path, or None where the generic passes run (asked, or no kernel could be built).
    "auto" here, where the run's length is not known (one analysis, one sweep), is generic:
    a sweep of a few hundred poses saves less than loading a kernel costs."""
    if kernel != "generated":
        if core.kernel_path:
            core.clear_kernel()
        return None
    from pinmech.solve.kernel_build import KernelUnavailable, build_kernel, describe

    try:
        build = build_kernel(model)
    except KernelUnavailable as why:
        _say(f"pinmech: {why}; the generic kinematic passes run")
        return None
    if not build.cached:
        _say(f"pinmech: {describe(build)}")
    core.set_kernel(str(build.path))
    return str(build.path)


def _say(line: str) -> None:
    if line not in _said:
        _said.add(line)
        print(line, file=sys.stderr)
