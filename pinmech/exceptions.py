"""Errors raised by pinmech: one base class, one named subclass per failure.

Every error keeps the offending numbers as attributes and puts them in its message,
so the CLI can print one line and a script can inspect what went wrong.
"""

from __future__ import annotations

from typing import Any


class PinmechError(Exception):
    """Base class of every error pinmech raises on purpose."""

    exit_code = 2


class ModelError(PinmechError):
    """A URDF file or one of its `<constraint>` elements is malformed or inconsistent."""

    exit_code = 3

    def __init__(self, message: str, *, path: str | None = None, element: str | None = None):
        where = ", ".join(x for x in (path, element) if x)
        super().__init__(f"{where}: {message}" if where else message)
        self.path = path
        self.element = element


class SceneError(PinmechError):
    """A scene or hand-value file is malformed, or names something the model lacks."""

    exit_code = 4

    def __init__(self, message: str, *, path: str | None = None, key: str | None = None):
        where = ", ".join(x for x in (path, key) if x)
        super().__init__(f"{where}: {message}" if where else message)
        self.path = path
        self.key = key


class UnitError(SceneError):
    """A quantity is written with an unknown unit, or a unit of the wrong dimension."""


class FrameNotFound(SceneError):
    """A joint, link, point or frame name is not in the model."""

    def __init__(self, kind: str, name: str, known: list[str], *, path: str | None = None, cuts: tuple = ()):
        listed = ", ".join(known[:20]) + (", ..." if len(known) > 20 else "")
        if name in cuts:  # a joint of the user's file, but the loop's cut: say so, not "unknown"
            super().__init__(f"{kind} '{name}' is a loop cut (the joint that closes a loop): its coordinate "
                             f"follows the loop and cannot be driven, held or set; name a joint of the tree "
                             f"({listed})", path=path)
        else:
            split = [k for k in known if k.startswith(f"{name}_")]
            hint = (f"; did you mean {' or '.join(split)}? (a drawn pin joining several links is one joint per "
                    "link after the first, named PIN_LINK)" if split and "joint" in kind else "")
            super().__init__(f"unknown {kind} '{name}'{hint} (the model has: {listed})", path=path)
        self.kind = kind
        self.name = name
        self.known = known


class MobilityError(PinmechError):
    """The drivers do not match the mechanism's mobility (degrees of freedom)."""

    exit_code = 5

    def __init__(self, message: str, *, mobility: int, drivers: int):
        super().__init__(message)
        self.mobility = mobility
        self.drivers = drivers


class LoopClosureError(PinmechError):
    """Newton could not close the loops: the pose is out of reach for these dimensions.

    Attributes:
        residual: closure residual reached (dimensionless, position rows divided by the
            mechanism's length scale).
        iterations: Newton iterations spent.
        partial: the last iterate (configuration vector), for inspection.
    """

    exit_code = 6

    def __init__(self, message: str, *, residual: float, iterations: int, partial: Any = None):
        super().__init__(message)
        self.residual = residual
        self.iterations = iterations
        self.partial = partial


class SingularPoseError(PinmechError):
    """A Jacobian is singular (or too ill-conditioned) at the pose: rates are undefined.

    Attributes:
        condition: condition number of the Jacobian (inf at an exact singularity).
        sigma_min: its smallest singular value.
    """

    exit_code = 7

    def __init__(self, message: str, *, condition: float, sigma_min: float, partial: Any = None):
        super().__init__(message)
        self.condition = condition
        self.sigma_min = sigma_min
        self.partial = partial


class TaskError(PinmechError):
    """An end-effector rate task is inconsistent or over-determined."""

    exit_code = 8


class CheckMismatch(PinmechError):
    """Hand values disagree with pinmech (raised by the CLI after printing the table)."""

    exit_code = 1


class SweepError(PinmechError):
    """A pose of a sweep failed: names the driver value and carries the original error.

    Attributes:
        driver: the swept joint.
        value: its coordinate at the failing pose [rad or m].
        cause: the LoopClosureError or SingularPoseError raised there.
    """

    def __init__(self, message: str, *, driver: str, value: float, cause: PinmechError):
        super().__init__(message)
        self.driver = driver
        self.value = value
        self.cause = cause
        self.exit_code = cause.exit_code


class AssemblyError(PinmechError):
    """A pose is not on the assembly (branch) asked for, or cannot be reached on it.

    Attributes:
        expected: the assembly signature asked (one sign per loop block, see branches.py).
        found: the signature found (empty where no pose was found).
        drivers: the driver joints' names.
        value: their values where it happened [rad or m].
    """

    exit_code = 10

    def __init__(self, message: str, *, expected: tuple, found: tuple, drivers: tuple = (),
                 value: tuple = ()):
        super().__init__(message)
        self.expected = tuple(expected)
        self.found = tuple(found)
        self.drivers = tuple(drivers)
        self.value = tuple(value)


class DriverLimitError(PinmechError):
    """The drivers cannot go further on this assembly: a fold (a non-Grashof crank's limit
    angle, a rocker's extreme, a piston's stroke), located to rounding.

    Attributes:
        limit: the drivers' values at the fold [rad or m].
        drivers: the driver joints' names.
    """

    exit_code = 11

    def __init__(self, message: str, *, limit: tuple, drivers: tuple = ()):
        super().__init__(message)
        self.limit = tuple(limit)
        self.drivers = tuple(drivers)


class IndeterminateForcesError(SingularPoseError):
    """The driver efforts and constraint forces are not determined at a pose: redundant
    (over-constrained) loops, or a dead centre of the drivers. Exit code 7, as a singular pose.

    Attributes:
        unknowns: driver efforts plus independent cut rows.
        equations: joint equations (the model's degrees of freedom).
    """

    def __init__(self, message: str, *, condition: float, sigma_min: float, unknowns: int, equations: int):
        super().__init__(message, condition=condition, sigma_min=sigma_min)
        self.unknowns = unknowns
        self.equations = equations


class OptionError(PinmechError):
    """A solver option given through the Python API is out of its range (as the scene's
    [solver] table is checked): a NaN, an infinity or a tolerance that closes nothing.

    Attributes:
        option: the option's name ("tol", "max_iterations", "max_condition").
        value: the value given.
    """

    exit_code = 2

    def __init__(self, message: str, *, option: str, value: Any):
        super().__init__(message)
        self.option = option
        self.value = value


class RateOverflowError(PinmechError):
    """Driver rates so large that velocities or accelerations overflow float64 (a speed of
    1e160 rad/s squares to infinity): nothing finite can be stated."""

    exit_code = 2


class BalanceError(PinmechError):
    """Forces that fail their own checks beyond rounding: the virtual power of the driver,
    gravity and loads differs from the kinetic rate, or the joint equations are not met
    (a term the model computes one way and the check another). Never printed as an answer.

    Attributes:
        power_residual: the power balance's relative residual.
        equation_residual: the joint equations' relative residual.
        bound: what rounding allows at this condition number.
    """

    exit_code = 13

    def __init__(self, message: str, *, power_residual: float, equation_residual: float, bound: float):
        super().__init__(message)
        self.power_residual = power_residual
        self.equation_residual = equation_residual
        self.bound = bound


class CoreBuildError(PinmechError, ImportError):
    """pinmech's compiled core does not fit the installed `pin`: it was compiled against
    another Pinocchio (or Boost) than the one `pin` loads. Raised at import.

    Attributes:
        built: the Pinocchio version the core was compiled against ("" if unknown).
        loaded: the version the installed `pin` loads.
    """

    exit_code = 2

    def __init__(self, message: str, *, built: str = "", loaded: str = ""):
        super().__init__(message)
        self.built = built
        self.loaded = loaded


class Interrupted(KeyboardInterrupt):
    """The run was stopped by a signal: Ctrl-C (SIGINT), SIGTERM or SIGHUP (the terminal
    closed). A KeyboardInterrupt, so code that stops on Ctrl-C stops on all three.

    Attributes:
        signum: the signal's number.
        exit_code: 128 + signum, as a shell reports a process a signal stopped (130 for Ctrl-C).
    """

    def __init__(self, signum: int):
        import signal

        self.signum = int(signum)
        self.exit_code = 128 + self.signum
        super().__init__(f"interrupted by {signal.Signals(self.signum).name}")


class LimitError(PinmechError):
    """A solved pose puts a joint beyond its URDF `<limit>`, and limits were asked to be
    errors (`--limits error`); by default they are reported as warnings.

    Attributes:
        violations: the `LimitViolation`s (joint, value, lower, upper; SI).
    """

    exit_code = 12

    def __init__(self, message: str, *, violations: list[Any]):
        super().__init__(message)
        self.violations = violations


class DiagnosticError(PinmechError):
    """A design diagnostic (transmission angle, Grashof class, limit positions, instant
    centres) asked of a mechanism it does not apply to (a spatial one, a joint that is
    not a pin or a slide), or one that cannot be stated to its bound at this pose.

    Attributes:
        path: the model file.
    """

    exit_code = 14

    def __init__(self, message: str, *, path: str | None = None):
        super().__init__(f"{path}: {message}" if path else message)
        self.path = path


class OptionRefused(PinmechError):
    """A command was given an option it cannot honour for this scene (a figure of a swept
    mechanism asked of a task scene, a figure setting without its figure): refused before
    anything runs, never ignored in silence.

    Attributes:
        options: the command-line options refused ("--paths", ...).
        scene: the scene file.
    """

    exit_code = 2

    def __init__(self, message: str, *, options: list[str], scene: str | None = None):
        super().__init__(f"{scene}: {message}" if scene else message)
        self.options = options
        self.scene = scene


class MissingTool(PinmechError):
    """An option needs an external program that is not installed (`animate --mp4` without
    ffmpeg): said before anything is computed, with what to install.

    Attributes:
        tool: the program ("ffmpeg").
        option: the option that needs it ("--mp4").
    """

    exit_code = 2

    def __init__(self, message: str, *, tool: str, option: str):
        super().__init__(message)
        self.tool = tool
        self.option = option



class SynthesisError(PinmechError):
    """A dimensional synthesis found no linkage that meets its targets without a defect
    (branch, circuit, order) and within its constraints: the candidates rejected, by cause.

    Attributes:
        path: the synthesis file.
        rejected: the candidates rejected, by cause ({cause: count}).
    """

    exit_code = 15

    def __init__(self, message: str, *, path: str | None = None, rejected: dict[str, int] | None = None):
        super().__init__(f"{path}: {message}" if path else message)
        self.path = path
        self.rejected = dict(rejected or {})


class ClusterError(PinmechError):
    """A Dask scheduler named by its address cannot be used: the address is not one, nothing
    answers there within seconds, what answers is no scheduler, or the scheduler was lost
    during the run (no output is then written).

    Attributes:
        address: the scheduler's address as given.
    """

    exit_code = 2

    def __init__(self, message: str, *, address: str):
        super().__init__(f"scheduler {address}: {message}")
        self.address = address
