"""pinmech: kinematics of closed-loop mechanisms and robot arms from URDF, on Pinocchio.

A user's script imports from here only:

    import pinmech
    analysis = pinmech.analyse(pinmech.Scene.load("models/scenes/r_rtr.toml"))
    print(pinmech.to_text(analysis))
"""

from pinmech.analysis import Analysis, Drivers, analyse, load_mechanism
from pinmech.check import compare, load_hand_file
from pinmech.closures import Closure
from pinmech.exceptions import (
    CheckMismatch,
    FrameNotFound,
    LoopClosureError,
    MobilityError,
    ModelError,
    PinmechError,
    SceneError,
    SingularPoseError,
    SweepError,
    TaskError,
    UnitError,
)
from pinmech.mechanism import JointInfo, Mechanism
from pinmech.motion import CoincidentPoint, Motion, evaluate_motion
from pinmech.report import to_dict, to_json, to_text
from pinmech.results import Accuracy, LoopSolution, RateSolution
from pinmech.scene import Scene
from pinmech.solve_loops import LoopSolver
from pinmech.solve_rates import RateSolver, Task
from pinmech.units import to_si

__version__ = "0.1.0"

__all__ = [
    "Accuracy",
    "Analysis",
    "CheckMismatch",
    "Closure",
    "CoincidentPoint",
    "Drivers",
    "FrameNotFound",
    "JointInfo",
    "LoopClosureError",
    "LoopSolution",
    "LoopSolver",
    "Mechanism",
    "MobilityError",
    "ModelError",
    "Motion",
    "PinmechError",
    "RateSolution",
    "RateSolver",
    "Scene",
    "SceneError",
    "SingularPoseError",
    "SweepError",
    "Task",
    "TaskError",
    "UnitError",
    "__version__",
    "analyse",
    "compare",
    "evaluate_motion",
    "load_hand_file",
    "load_mechanism",
    "to_dict",
    "to_json",
    "to_si",
    "to_text",
]
