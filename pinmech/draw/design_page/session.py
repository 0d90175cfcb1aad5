"""One page's design session: the linkage being designed, its last valid turn, and the
answers to the page's messages (drag, parameter, pose details, save), each a JSON-ready
dict. A change that cannot be drawn or solved answers with its named error, and the last
valid linkage stays the session's.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from pinmech.exceptions import PinmechError
from pinmech.model.linkage import linkage_params
from pinmech.model.linkage_entries import Compass, Polar
from pinmech.model.linkage_spec import GROUND, LinkageSpec
from pinmech.draw.design_page.edits import move_joint, set_param
from pinmech.draw.design_page.frame import Turn, TurnSolver, angle_text


class Session:
    """The linkage on the page.

    Args:
        spec: the linkage as read.
        source: its file (the save goes back there unless told otherwise).
        driver: the driven joint (default: the tree's first joint).
        speed: the driver's speed as text ("60 rpm"): velocities and accelerations.
    """

    def __init__(self, spec: LinkageSpec, source: str, *, driver: str | None = None, speed: str = "60 rpm") -> None:
        self.source, self.solver = source, TurnSolver(driver, speed)
        self.spec: LinkageSpec = spec
        self.turn: Turn | None = None
        self.count, self._diagnostics = 0, None
        self.first = self.solve(spec)
        if not self.first["ok"]:
            raise PinmechError(self.first["error"])

    def close(self) -> None:
        """Stop the page's synthesis, if one runs (its files removed)."""
        from pinmech.draw.design_page.synthesis import close_run

        close_run(self)
        self.solver.close()

    # ------------------------------------------------------------------ changes
    def solve(self, spec: LinkageSpec, check=None) -> dict:
        """The frame of `spec` (kept as the session's linkage), or its error (the last kept).

        Args:
            check: called with the new turn before it is kept; raises PinmechError to refuse it.
        """
        started = time.perf_counter()
        try:
            turn = self.solver.solve(spec, self.source)
            if check is not None:
                check(turn)
            frame = turn_frame(turn, spec)
        except PinmechError as exc:
            self.solver.rollback()
            return {"type": "frame", "ok": False, "error": f"{type(exc).__name__}: {exc}"}
        self.spec, self.turn, self._diagnostics = spec, turn, None
        self.count += 1
        frame["id"], frame["ms"] = self.count, 1e3 * (time.perf_counter() - started)
        return frame

    def diagnostics(self) -> dict:
        """The diagnostics of the current turn (computed once per turn), tagged with its frame's id."""
        from pinmech.draw.design_page.diagnostics import turn_diagnostics

        if self._diagnostics is None:
            started = time.perf_counter()
            try:
                found = turn_diagnostics(self.turn)
            except PinmechError as exc:
                found = {"applicable": False, "reason": f"{type(exc).__name__}: {exc}"}
            self._diagnostics = {"type": "diagnostics", "id": self.count, "diagnostics": found,
                                 "ms": 1e3 * (time.perf_counter() - started)}
        return self._diagnostics

    def drag(self, joint: str, x: float, y: float, index: int = 0) -> dict:
        """Joint `joint` dragged to (x, y) [m] with the linkage shown at pose `index` (0: the
        drawn pose; another: its drawn place moved so that at that pose it is at (x, y),
        `edits_posed`, or the drag refused saying so)."""
        from pinmech.draw.design_page.edits_posed import landed, move_joint_posed, refusal

        to = np.array([x, y], dtype=float)
        posed = index != 0
        if posed and not self._solved(index):  # never taken as a drag at the drawn pose in silence
            count = 0 if self.turn is None else len(self.turn.values)
            return {"type": "frame", "ok": False,
                    "error": f"AssemblyError: {self.source}: {joint} cannot be dragged at pose {index}: the turn's "
                             f"poses are 0 to {count - 1} and the linkage is drawn only where it was solved"}
        try:
            if posed:
                spec = move_joint_posed(self.spec, self.turn, joint, index, to, self.source)
            else:
                spec = move_joint(self.spec, joint, to, self.turn.linkage.points, self.source)
        except PinmechError as exc:
            return {"type": "frame", "ok": False, "error": f"{type(exc).__name__}: {exc}"}
        if not posed:
            return self.solve(spec)
        angle = angle_text(float(self.turn.values[index] - self.turn.values[0]), self.turn.sweep.is_angular)

        def check(turn) -> None:
            if not landed(turn, joint, index, to):
                raise refusal(joint, f"the crank's {angle} from the drawn pose", self.source)

        return self.solve(spec, check)

    def param(self, name: str, value_m: float) -> dict:
        """Parameter `name` set to a length [m]."""
        try:
            spec = set_param(self.spec, name, float(value_m), self.source)
        except (PinmechError, TypeError, ValueError) as exc:
            return {"type": "frame", "ok": False, "error": f"{type(exc).__name__}: {exc}"}
        return self.solve(spec)

    # ------------------------------------------------------------------ one pose
    def motion(self, index: int, point: str) -> dict:
        """Velocity [m/s] and classical acceleration [m/s^2] of a drawn point at pose `index`."""
        turn = self.turn
        if not self._solved(index) or point not in turn.names:
            return {"type": "motion", "ok": False, "index": index, "point": point}
        k = turn.names.index(point)
        return {"type": "motion", "ok": True, "index": index, "point": point,
                "position": turn.position[index, k].tolist(), "velocity": turn.velocity[index, k].tolist(),
                "acceleration": turn.acceleration[index, k].tolist()}

    def centres(self, index: int) -> dict:
        """Every instant centre at pose `index` (world [m], or a direction at infinity)."""
        from pinmech.solve.diagnostics import design_at, design_dict

        if not self._solved(index):
            return {"type": "centres", "ok": False, "index": index}
        sweep = self.turn.sweep
        design = design_at(sweep.mechanism, list(sweep.drivers.names), self.turn.q[index],
                           self._rates(index), None, sweep.is_angular)
        found = design_dict(design).get("instant_centres", []) if design.applicable else []
        return {"type": "centres", "ok": True, "index": index, "centres": found}

    def _solved(self, index: int) -> bool:
        turn = self.turn
        return turn is not None and 0 <= index < len(turn.values) and index not in turn.errors

    def _rates(self, index: int) -> np.ndarray:
        """Joint rates at pose `index` for unit driver speed (the centres' velocities)."""
        sweep = self.turn.sweep
        k = list(sweep.drivers.names).index(sweep.driver)
        v, _, _ = sweep.solver.rates(self.turn.q[index], np.eye(len(sweep.drivers.names))[k],
                                     np.zeros(len(sweep.drivers.names)))
        return v


def turn_frame(turn: Turn, spec: LinkageSpec) -> dict:
    """What the page draws of a solved turn: JSON-ready, lengths [m], angles [rad]."""
    linkage, sweep = turn.linkage, turn.sweep
    names = turn.names
    ground = set(linkage.links.get(GROUND, ()))
    kinds = {n: "compass" if isinstance(e, Compass) else "polar" if isinstance(e, Polar) else "point"
             for n, e in spec.joints.items()}
    first_error = min(turn.errors) if turn.errors else None
    return {
        "type": "frame", "ok": True, "title": linkage.title,
        "driver": {"name": sweep.driver, "angular": sweep.is_angular, "values": turn.values.tolist()},
        "joints": [{"name": n, "at": linkage.points[n][:2].tolist(), "ground": n in ground,
                    "pin": n not in linkage.point_links, "kind": kinds.get(n, "point")} for n in names],
        "links": [{"name": k, "points": [n for n in v if n in names], "ground": k == GROUND}
                  for k, v in linkage.links.items() if k not in linkage.hidden],
        "slides": _slides(linkage),
        "solved": (~np.isnan(turn.q).any(axis=1)).tolist(),
        "paths": {n: np.nan_to_num(turn.path(n)).ravel().tolist() for n in names},
        "stopped": None if first_error is None else {"index": first_error, "why": _said(turn.errors[first_error])},
        "folds": list(turn.folds.values()),
        "params": {n: v for n, v in linkage_params(spec, linkage.source).items()},
    }


def _said(exc: Exception) -> str:
    return f"{type(exc).__name__}: {exc}"


def _slides(linkage) -> list[dict]:
    """Slides on the ground: a line through the block's pin along the slide [m]."""
    out = []
    for block, edge in linkage.blocks.items():
        if GROUND in edge.links and edge.direction is not None:
            out.append({"name": edge.name, "at": edge.at[:2].tolist(), "along": edge.direction[:2].tolist()})
    return out


def is_synthesis_file(path: str | Path) -> bool:
    """Whether a TOML file is a synthesis file (it states a `task`)."""
    import tomllib

    try:
        return "task" in tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return False


def read_design_file(path: str | Path) -> tuple[LinkageSpec, str, str | None, str]:
    """A linkage file, or a scene that names one: (spec, the linkage file, the driver, its speed).

    Raises:
        ModelError, SceneError: the file's mistakes (one line naming the file and the key).
    """
    import tomllib

    from pinmech.model.linkage_spec import read_linkage_spec

    path = Path(path)
    try:
        tables = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        tables = {}
    if "task" in tables and "topology" in tables or "task" in tables and "targets" in tables:
        from pinmech.exceptions import SceneError

        raise SceneError("is a synthesis file: open it with open_synthesis", path=str(path))
    if "linkage" in tables and isinstance(tables["linkage"], str):
        from pinmech.io.scene import Scene

        scene = Scene.load(path)
        linkage_file = scene.model_file("linkage")
        drivers = scene.file.drivers or {}
        driver = next(iter(drivers), None)
        speed = getattr(drivers[driver], "speed", None) if driver else None
        spec, source = read_linkage_spec(linkage_file)
        return spec, source, driver, speed if isinstance(speed, str) else "60 rpm"
    spec, source = read_linkage_spec(path)
    return spec, source, None, "60 rpm"
