"""pinmech: kinematics of closed-loop mechanisms and robot arms from URDF, on Pinocchio.

A user's script imports from here only:

    import pinmech
    analysis = pinmech.analyse(pinmech.Scene.load("models/scenes/r_rtr.toml"))
    print(pinmech.to_text(analysis))
"""

from pinmech.analysis import Analysis, analyse
from pinmech.branches import Assembly
from pinmech.check import compare, load_hand_file
from pinmech.closures import Closure
from pinmech.continuation import Route
from pinmech.draw.report_page import HtmlPage, report_html, snapshot
from pinmech.exceptions import (
    AssemblyError,
    CheckMismatch,
    DriverLimitError,
    FrameNotFound,
    IndeterminateForcesError,
    Interrupted,
    LoopClosureError,
    MobilityError,
    ModelError,
    OptionError,
    PinmechError,
    RateOverflowError,
    SceneError,
    SingularPoseError,
    SweepError,
    TaskError,
    UnitError,
)
from pinmech.flywheel import EnergyFluctuation, energy_fluctuation
from pinmech.forces import (
    ForceSolution,
    ForceSolver,
    Load,
    PowerBalance,
    Reaction,
    mechanical_advantage,
)
from pinmech.forces_scene import ForceSettings, force_settings
from pinmech.forces_sweep import SweepForces
from pinmech.linkage import build_urdf, load_linkage
from pinmech.mechanism import JointInfo, Mechanism
from pinmech.mjcf import load_mjcf
from pinmech.motion import CoincidentPoint, Motion, evaluate_motion
from pinmech.path import PathPoint, follow_path
from pinmech.polygon import Polygon, acceleration_polygon, velocity_polygon
from pinmech.report import to_dict, to_json, to_text
from pinmech.results import Accuracy, LoopSolution, RateSolution
from pinmech.scene import Scene
from pinmech.scene_model import Drivers, load_mechanism
from pinmech.sidecar import load_extended_urdf
from pinmech.solve_batch import BatchSolution, BatchSolver
from pinmech.solve_cycle import RangeChunk, solve_range
from pinmech.solve_loops import LoopSolver, Reference
from pinmech.solve_rates import RateSolver, Task
from pinmech.sweep import Sweep, SweepPose
from pinmech.units import to_si

__version__ = "0.1.0"

__all__ = [
    "Accuracy",
    "Analysis",
    "Assembly",
    "AssemblyError",
    "BatchSolution",
    "BatchSolver",
    "CheckMismatch",
    "Closure",
    "CoincidentPoint",
    "DriverLimitError",
    "Drivers",
    "EnergyFluctuation",
    "ForceSettings",
    "ForceSolution",
    "ForceSolver",
    "FrameNotFound",
    "IndeterminateForcesError",
    "HtmlPage",
    "Interrupted",
    "JointInfo",
    "Load",
    "LoopClosureError",
    "LoopSolution",
    "LoopSolver",
    "Mechanism",
    "MobilityError",
    "ModelError",
    "Motion",
    "PathPoint",
    "OptionError",
    "PinmechError",
    "RateOverflowError",
    "PowerBalance",
    "Polygon",
    "RangeChunk",
    "RateSolution",
    "RateSolver",
    "Reaction",
    "Reference",
    "Route",
    "Scene",
    "SceneError",
    "SingularPoseError",
    "Sweep",
    "SweepError",
    "SweepForces",
    "SweepPose",
    "Task",
    "TaskError",
    "UnitError",
    "__version__",
    "acceleration_polygon",
    "analyse",
    "build_urdf",
    "compare",
    "energy_fluctuation",
    "evaluate_motion",
    "follow_path",
    "force_settings",
    "load_extended_urdf",
    "load_hand_file",
    "load_linkage",
    "load_mechanism",
    "load_mjcf",
    "mechanical_advantage",
    "report_html",
    "snapshot",
    "solve_range",
    "to_dict",
    "to_json",
    "to_si",
    "to_text",
    "velocity_polygon",
]
