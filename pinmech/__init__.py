"""pinmech: kinematics of closed-loop mechanisms and robot arms from URDF, on Pinocchio.

A user's script imports from here only:

    import pinmech
    analysis = pinmech.analyse(pinmech.Scene.load("models/scenes/r_rtr.toml"))
    print(pinmech.to_text(analysis))
"""

from importlib import import_module as _import_module

from pinmech.exceptions import (
    AssemblyError,
    BalanceError,
    CheckMismatch,
    CoreBuildError,
    DiagnosticError,
    DriverLimitError,
    FrameNotFound,
    IndeterminateForcesError,
    Interrupted,
    LimitError,
    LoopClosureError,
    MobilityError,
    ModelError,
    OptionError,
    OptionRefused,
    PinmechError,
    RateOverflowError,
    SceneError,
    SingularPoseError,
    SweepError,
    SynthesisError,
    TaskError,
    UnitError,
)

#: The rest of the public API, by module: imported on first use (`pinmech.Sweep` imports
#: pinmech.io.sweep then), so `pinmech solve` or a script that needs one module does not pay
#: for the others' imports (forces, drawing, linkage files, MJCF, sweeps...).
_LAZY = {
    "pinmech.io.analysis": ("analyse",),
    "pinmech.io.analysis_result": ("Analysis",),
    "pinmech.solve.branches": ("Assembly",),
    "pinmech.io.check": ("compare", "load_hand_file"),
    "pinmech.model.closures": ("Closure",),
    "pinmech.model.closure_core": ("ClosureRows", "closure_rows"),
    "pinmech.solve.continuation": ("Route",),
    "pinmech.draw.report_page": ("HtmlPage", "report_html", "snapshot"),
    "pinmech.solve.flywheel": ("EnergyFluctuation", "energy_fluctuation"),
    "pinmech.solve.forces": ("ForceSolution", "ForceSolver", "Load", "PowerBalance", "Reaction", "mechanical_advantage"),
    "pinmech.io.forces_scene": ("ForceSettings", "force_settings"),
    "pinmech.draw.forces_sweep": ("SweepForces",),
    "pinmech.model.linkage": ("Linkage", "linkage_from_spec", "linkage_params"),
    "pinmech.model.linkage_model": ("build_urdf", "linkage_mechanism", "load_linkage"),
    "pinmech.model.linkage_spec": ("LinkageSpec", "linkage_spec", "read_linkage_spec"),
    "pinmech.model.linkage_write": ("linkage_toml",),
    "pinmech.model.mechanism": ("JointInfo", "Mechanism"),
    "pinmech.model.mjcf": ("load_mjcf",),
    "pinmech.solve.motion": ("CoincidentPoint", "Motion", "evaluate_motion"),
    "pinmech.solve.sweep_frames": ("FramePaths", "frame_paths"),
    "pinmech.solve.path": ("PathPoint", "follow_path"),
    "pinmech.draw.polygon": ("Polygon", "acceleration_polygon", "velocity_polygon"),
    "pinmech.io.report": ("to_dict", "to_json", "to_text"),
    "pinmech.solve.results": ("Accuracy", "LoopSolution", "RateSolution"),
    "pinmech.io.scene": ("Scene",),
    "pinmech.io.scene_model": ("Drivers", "load_mechanism"),
    "pinmech.model.sidecar": ("load_extended_urdf",),
    "pinmech.solve.batch": ("BatchSolution", "BatchSolver"),
    "pinmech.solve.cycle": ("RangeChunk", "solve_range"),
    "pinmech.solve.loops": ("LoopSolver", "Reference"),
    "pinmech.solve.rates": ("RateBatch", "RateSolver", "Task"),
    "pinmech.design.study.run": ("StudyResult", "study"),
    "pinmech.design.study.file": ("StudySpec", "load_study"),
    "pinmech.design.synthesis.file": ("SynthesisSpec", "load_synthesis"),
    "pinmech.design.synthesis.result": ("SynthesisResult",),
    "pinmech.design.synthesis.search": ("synthesise",),
    "pinmech.design.workspace.run": ("WorkspaceResult",),
    "pinmech.design.workspace.actuator": ("ActuatorResult",),
    "pinmech.design.workspace.file": ("WorkspaceSpec", "load_workspace"),
    "pinmech.io.sweep": ("Sweep", "SweepPose"),
    "pinmech.units": ("to_si",),
}
_MODULE_OF = {name: module for module, names in _LAZY.items() for name in names}


def __getattr__(name: str):
    """A public name of a module not imported yet (PEP 562): import it, then keep the name
    here as an eager import would."""
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module 'pinmech' has no attribute {name!r}")
    value = getattr(_import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_MODULE_OF))


__version__ = "0.1.0"

__all__ = [
    "Accuracy",
    "ActuatorResult",
    "Analysis",
    "Assembly",
    "AssemblyError",
    "BalanceError",
    "BatchSolution",
    "BatchSolver",
    "CheckMismatch",
    "Closure",
    "ClosureRows",
    "CoincidentPoint",
    "CoreBuildError",
    "DiagnosticError",
    "DriverLimitError",
    "Drivers",
    "EnergyFluctuation",
    "ForceSettings",
    "ForceSolution",
    "ForceSolver",
    "FrameNotFound",
    "FramePaths",
    "HtmlPage",
    "IndeterminateForcesError",
    "Interrupted",
    "JointInfo",
    "LimitError",
    "Linkage",
    "LinkageSpec",
    "Load",
    "LoopClosureError",
    "LoopSolution",
    "LoopSolver",
    "Mechanism",
    "MobilityError",
    "ModelError",
    "Motion",
    "OptionError",
    "OptionRefused",
    "PathPoint",
    "PinmechError",
    "Polygon",
    "PowerBalance",
    "RangeChunk",
    "RateBatch",
    "RateOverflowError",
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
    "SynthesisError",
    "SweepForces",
    "SweepPose",
    "StudyResult",
    "StudySpec",
    "Task",
    "TaskError",
    "UnitError",
    "WorkspaceResult",
    "WorkspaceSpec",
    "__version__",
    "acceleration_polygon",
    "analyse",
    "build_urdf",
    "closure_rows",
    "compare",
    "energy_fluctuation",
    "evaluate_motion",
    "follow_path",
    "force_settings",
    "frame_paths",
    "load_extended_urdf",
    "load_hand_file",
    "linkage_from_spec",
    "linkage_mechanism",
    "linkage_params",
    "linkage_spec",
    "linkage_toml",
    "load_linkage",
    "load_mechanism",
    "load_mjcf",
    "mechanical_advantage",
    "report_html",
    "snapshot",
    "solve_range",
    "study",
    "load_study",
    "synthesise",
    "load_synthesis",
    "SynthesisSpec",
    "SynthesisResult",
    "load_workspace",
    "read_linkage_spec",
    "to_dict",
    "to_json",
    "to_si",
    "to_text",
    "velocity_polygon",
]
