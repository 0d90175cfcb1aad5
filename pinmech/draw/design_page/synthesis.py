"""Synthesis from the page: targets, poses or input-output pairs become a synthesis file
(`synthesis_task`, checked by the synthesis reader), `pinmech synth` runs it in a child
process (so that cancel stops it at once, and the page stays live), and its answers (the
linkage files it writes, each checked by the engine) are solved as turns and drawn;
adopting one makes it the page's linkage.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from pinmech.draw.design_page.synthesis_task import Request, checked_toml, default_bounds, describe
from pinmech.exceptions import PinmechError
from pinmech.outputs import write_whole

_RUNS: dict[int, SynthesisRun] = {}  # session id -> its run


class SynthesisRun:
    """One `pinmech synth` child process and the private folder of its answers.

    Args:
        text: the synthesis file's text (written in the folder), or None with `file`.
        file: a user's synthesis file, run where it is (its relative paths kept).
    """

    def __init__(self, text: str | None = None, file: Path | None = None) -> None:
        self._folder = tempfile.TemporaryDirectory(prefix="pinmech-page-synth-")
        self.folder = Path(self._folder.name)
        if file is None:
            file = self.folder / "targets.toml"
            write_whole(file, text)
        self.started = time.monotonic()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "pinmech", "synth", str(Path(file).resolve()), "--out", str(self.folder / "answer")],
            cwd=Path(file).resolve().parent, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self.answers: list[dict] | None = None
        self.specs: list = []

    def cancel(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait(timeout=10)

    def close(self) -> None:
        self.cancel()
        self._folder.cleanup()


def synthesis_answer(session, message: dict) -> dict:
    """The answer to "synthesise" (start), "synthesis" (how far), "cancel" and "adopt"."""
    kind, run = message["type"], _RUNS.get(id(session))
    if kind == "synthesise":
        return _start(session, message, run)
    if run is None and kind == "synthesis":  # the page asks on opening: nothing yet
        return {"type": "synthesis", "running": False, "progress": ""}
    if run is None:
        return {"type": "synthesis", "error": "no synthesis has been run on this page"}
    if kind == "cancel":
        run.cancel()
        return {"type": "synthesis", "progress": "cancelled", "running": False}
    if kind == "adopt":
        index = int(message["answer"])
        if not 0 <= index < len(run.specs):
            return {"type": "synthesis", "error": f"there is no answer {index + 1}"}
        return session.solve(run.specs[index])
    return _progress(session, run)


def _start(session, message: dict, run: SynthesisRun | None) -> dict:
    try:
        request = Request(message)
        text = checked_toml(request, Path("the page's synthesis"))
    except (PinmechError, TypeError, ValueError) as exc:
        return {"type": "synthesis", "error": f"{type(exc).__name__}: {exc}", "running": False}
    if run is not None:
        run.close()
    _RUNS[id(session)] = SynthesisRun(text)
    return {"type": "synthesis", "progress": f"searching ({describe(request)})...", "running": True}


def bounds_answer(message: dict) -> dict:
    """The answer to "bounds": the `[bounds]` the page proposes for the request's targets."""
    try:
        return {"type": "bounds", "text": default_bounds(Request(message))}
    except (PinmechError, ValueError) as exc:
        return {"type": "bounds", "error": f"{type(exc).__name__}: {exc}"}


def _progress(session, run: SynthesisRun) -> dict:
    elapsed = time.monotonic() - run.started
    code = run.process.poll()
    if code is None:
        return {"type": "synthesis", "progress": f"searching... {elapsed:.0f} s", "running": True}
    if run.answers is None:
        run.answers = _answers(session, run, code)
    if code != 0 and not run.answers:
        said = (run.process.stderr.read() if run.process.stderr else "").strip().splitlines()
        return {"type": "synthesis", "running": False, "answers": [],
                "error": f"pinmech synth: {said[-1] if said else f'exit code {code}'}"}
    return {"type": "synthesis", "running": False, "answers": run.answers,
            "progress": f"{len(run.answers)} answer(s) in {elapsed:.0f} s"}


def open_synthesis(file: Path) -> tuple[SynthesisRun, list[dict]]:
    """`pinmech design SYNTHESIS.toml`: the file's search run to its end (the terminal told
    how long it took), and its answers; the first one is the page's linkage.

    Raises:
        PinmechError: the search failed or found no linkage (pinmech synth's last line quoted).
    """
    run = SynthesisRun(file=file)
    run.process.wait()
    answer = _progress(None, run)
    if not run.specs:
        run.close()
        raise PinmechError(answer.get("error") or f"{file}: the synthesis found no linkage to open")
    return run, answer


def close_run(session) -> None:
    """Stop the session's search, if any, and remove its folder."""
    run = _RUNS.pop(id(session), None)
    if run is not None:
        run.close()


def adopt_run(session, run: SynthesisRun) -> None:
    """Make `run` the session's synthesis (its answers listed on the page)."""
    _RUNS[id(session)] = run


def _answers(session, run: SynthesisRun, code: int) -> list[dict]:
    """Each linkage the search wrote: its turn solved, its coupler point's curve and its drawing."""
    from pinmech.draw.design_page.frame import TurnSolver
    from pinmech.model.linkage_spec import read_linkage_spec

    report = run.folder / "answer.json"
    found = json.loads(report.read_text(encoding="utf-8")).get("linkages", []) if report.is_file() else []
    out, solver = [], TurnSolver()
    for i, entry in enumerate(found, start=1):
        path = run.folder / f"answer_{i}.toml"
        try:
            spec, source = read_linkage_spec(path)
            turn = solver.solve(spec, str(path))
        except PinmechError:
            continue
        run.specs.append(spec)
        at = {n: turn.position[0, k].tolist() for k, n in enumerate(turn.names)}
        traced = "P" if "P" in turn.names else turn.names[-1]  # a function's answer: its output's pin
        out.append({"summary": f"{i}: {entry.get('grashof', '')}, {_met(entry)}", "traced": traced,
                    "path": [None if np.isnan(p[0]) else p for p in turn.path(traced).tolist()],
                    "points": at, "links": [list(v) for k, v in turn.linkage.links.items() if k != "ground"]})
    return out


def _met(entry: dict) -> str:
    """How closely an answer meets its targets, in the report's own unit (mm or deg)."""
    for key, unit in (("errors_mm", "mm"), ("errors_deg", "deg")):
        if entry.get(key):
            return f"targets met within {max(entry[key]):.3g} {unit}"
    return "targets met (no error reported)"
