"""Which kinematic passes a solver's compiled core runs: Pinocchio's generic algorithms
(`kernel="generic"`, the default) or a kernel generated from the same algorithms for the
model (`kernel="generated"`: kernel_build.py makes it, the core loads it).

The generated kernel writes the same numbers the generic passes write (the joints' world
placements, their Jacobians, velocities and accelerations), summed in another order: the
answers agree to rounding (tests/test_kernels.py), and the core's checks of every pose
(residual, condition number, assembly signature) run on them unchanged. Where no kernel
can be built (no compiler, no `pinmech[fast]`), one line on stderr says why and the
generic passes run.
"""

from __future__ import annotations

import sys

import pinocchio as pin

from pinmech.exceptions import OptionError

#: The kinds of kinematic passes a solver may run.
KERNELS = ("generic", "generated")

_said: set[str] = set()  # the fallback lines printed in this process (each once)


def checked_kernel(kernel: object) -> str:
    """`kernel` if it is one of KERNELS, else an OptionError naming them."""
    if kernel not in KERNELS:
        raise OptionError(f"kernel = {kernel!r} must be one of {', '.join(KERNELS)}", option="kernel", value=kernel)
    return str(kernel)


def kept(owner: dict, core, model: pin.Model, kernel: str) -> None:
    """Set the passes `kernel` asks on `core` once per core and choice (`owner`: the solver's
    __dict__, which remembers it), and again where the model's joints changed in place since
    its kernel was made (a joint's type or axis: the old kernel would answer for the old joints)."""
    if owner.get("_kernel_set") != (id(core), kernel) or core.kernel_stale:
        attach(core, model, kernel)
        owner["_kernel_set"] = (id(core), kernel)


def attach(core, model: pin.Model, kernel: str) -> str | None:
    """Set the passes `kernel` asks on `core` (a compiled Core of `model`): the generated
    kernel's path, or None where the generic passes run (asked, or no kernel could be built)."""
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
