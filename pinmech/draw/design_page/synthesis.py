"""Synthesis from the page: targets clicked on the drawing become a path-synthesis file,
`pinmech synth` runs it in a child process (so that cancel stops it at once, and the page
stays live), and its answers (the linkage files it writes, each checked by the engine)
are solved as turns and drawn; adopting one makes it the page's linkage.

The search's region is set from the targets: both ground pivots within twice the targets'
span of their centre, the crank up to the page's limit, every other length up to three
spans.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from pinmech.draw.design_page.edits import millimetres
from pinmech.outputs import write_whole

KINDS = ("four-bar", "slider-crank")
GENERATIONS = 120  # at most, on each assembly: a page's search answers in seconds
_RUNS: dict[int, SynthesisRun] = {}  # session id -> its run


def synthesis_toml(kind: str, targets: np.ndarray, max_crank: float) -> str:
    """A path-synthesis file for the coupler point through `targets` [m] (N, 2) in order."""
    centre = targets.mean(axis=0)
    span = max(float(np.ptp(targets, axis=0).max()), 0.02)
    box = lambda c: f'{{ x = ["{millimetres(c[0] - 2 * span)}", "{millimetres(c[0] + 2 * span)}"], ' \
                    f'y = ["{millimetres(c[1] - 2 * span)}", "{millimetres(c[1] + 2 * span)}"] }}'
    length = lambda low, high: f'["{millimetres(low)}", "{millimetres(high)}"]'
    lines = ['title = "Through the targets clicked on the design page"', 'task = "path"', f'topology = "{kind}"',
             "seed = 1", "population = 15", f"generations = {GENERATIONS}", "keep = 3", "", "targets = ["]
    lines += [f'  ["{millimetres(x)}", "{millimetres(y)}"],' for x, y in targets] + ["]", "", "[bounds]",
                                                                                   f"O2 = {box(centre)}"]
    if kind == "four-bar":
        lines += [f"O4 = {box(centre)}", f"coupler = {length(span / 5, 3 * span)}",
                  f"rocker = {length(span / 5, 3 * span)}"]
    else:
        lines += [f'slide = {{ angle = ["-90 deg", "90 deg"], offset = {length(-2 * span, 2 * span)} }}',
                  f"rod = {length(span / 5, 3 * span)}"]
    lines += [f"crank = {length(min(span / 10, max_crank / 2), max_crank)}",
              f"point = {{ along = {length(-2 * span, 2 * span)}, across = {length(-2 * span, 2 * span)} }}",
              "", "[constraints]", 'transmission = "25 deg"', 'direction = "either"']
    return "\n".join(lines) + "\n"


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
    targets = np.asarray(message["targets"], dtype=float).reshape(-1, 2)
    choice = str(message.get("kind", "four-bar"))
    if choice not in KINDS:
        return {"type": "synthesis", "error": f"kind must be one of {', '.join(KINDS)}, got {choice!r}"}
    if len(targets) < 3 or not np.all(np.isfinite(targets)):
        return {"type": "synthesis", "error": f"click at least 3 targets on the drawing (now {len(targets)})"}
    max_crank = float(message.get("max_crank", 0.2))
    if not max_crank > 0:
        return {"type": "synthesis", "error": f"the crank's limit must be positive, got {max_crank} m"}
    if run is not None:
        run.close()
    _RUNS[id(session)] = SynthesisRun(synthesis_toml(choice, targets, max_crank))
    return {"type": "synthesis", "progress": f"searching ({len(targets)} targets)...", "running": True}


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
    from pinmech.exceptions import PinmechError

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
    from pinmech.exceptions import PinmechError
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
        error = max(entry.get("errors_mm", [float("nan")]))
        out.append({"summary": f"{i}: {entry.get('grashof', '')}, targets met within {error:.3g} mm",
                    "path": [None if np.isnan(p[0]) else p for p in turn.path("P").tolist()],
                    "points": at, "links": [list(v) for k, v in turn.linkage.links.items() if k != "ground"]})
    return out
