"""The page's messages, one answer each (JSON-ready dicts): what the websocket carries.

    {"type": "drag", "joint": "B", "x": 0.05, "y": 0.09, "index": 0}  -> a frame (or its error);
        index: the pose shown (the joint put under the mouse at that crank angle)
    {"type": "param", "name": "crank", "value": 0.04}        -> a frame (or its error)
    {"type": "frame"}                                        -> the current frame
    {"type": "motion", "index": 10, "point": "P"}            -> velocity, acceleration
    {"type": "centres", "index": 10}                         -> the instant centres
    {"type": "save", "svg": "<svg...", "png": "data:..."}    -> the files written
    {"type": "synthesise", "kind": "four-bar", "task": "path", "targets": [[x, y], ...], "max_crank": 0.2,
     "bounds": "crank = [...]\n..."}  (task "motion": "poses": [[x, y, angle], ...]; "function":
     "pairs": [[crank turn, output turn or travel], ...], "ground": 0.1)
    {"type": "bounds", ...the same...}                       -> the [bounds] the page proposes
    {"type": "synthesis"} (how far), {"type": "cancel"}, {"type": "adopt", "answer": 0} -> a frame
Positions in metres, angles in radians, world frame; `index` a pose of the turn (0: the drawn pose).
"""

from __future__ import annotations

from pathlib import Path

from pinmech.exceptions import PinmechError


class Saving:
    """Where a session saves: the linkage file, its scene beside it, its figures."""

    def __init__(self, linkage: Path, header: str) -> None:
        self.linkage, self.header = Path(linkage), header
        self.scene = self.linkage.with_name(self.linkage.stem + "_scene.toml")
        self.figure = self.linkage.with_suffix("")

    def save(self, session, message: dict) -> dict:
        from pinmech.draw.design_page.frame import scene_tables
        from pinmech.draw.design_page.save import figure_contents, save_figure, save_linkage, save_scene

        turn = session.turn
        sweep = turn.sweep
        driver = (sweep.driver, float(sweep.start))
        try:
            figure = figure_contents(message.get("svg"), message.get("png"))  # checked before any file is written
            files = [save_linkage(session.spec, self.linkage, self.header),
                     save_scene(scene_tables(turn.linkage, "", driver, session.solver.speed), self.linkage, self.scene)]
            files += save_figure(figure, self.figure)
        except (PinmechError, OSError, ValueError) as exc:
            return {"type": "saved", "ok": False, "error": f"{type(exc).__name__}: {exc}"}
        return {"type": "saved", "ok": True, "files": [str(f) for f in files]}


def answer(session, saving: Saving, message: dict) -> dict:
    """The answer to one message of the page (an unknown or malformed one named as such)."""
    kind = message.get("type") if isinstance(message, dict) else None
    try:
        if kind == "drag":
            return session.drag(str(message["joint"]), float(message["x"]), float(message["y"]),
                                int(message.get("index", 0)))
        if kind == "param":
            return session.param(str(message["name"]), float(message["value"]))
        if kind == "frame":
            return session.solve(session.spec)
        if kind == "motion":
            return session.motion(int(message["index"]), str(message["point"]))
        if kind == "centres":
            return session.centres(int(message["index"]))
        if kind == "save":
            return saving.save(session, message)
        if kind == "bounds":
            from pinmech.draw.design_page.synthesis import bounds_answer

            return bounds_answer(message)
        if kind in ("synthesise", "synthesis", "cancel", "adopt"):
            from pinmech.draw.design_page.synthesis import synthesis_answer

            return synthesis_answer(session, message)
    except (KeyError, TypeError, ValueError) as exc:
        return {"type": "error", "error": f"a malformed {kind!r} message: {type(exc).__name__}: {exc}"}
    return {"type": "error", "error": f"unknown message type {kind!r}"}
