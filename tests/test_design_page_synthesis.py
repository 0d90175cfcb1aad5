"""Synthesis on the design page: every task (path through targets, motion through poses,
function through input-output pairs) of every kind the synthesis files hold (four-bar,
slider-crank, inverted slider-crank), built as a synthesis file the synthesis reader
accepts, its mistakes named; a function searched from the page and adopted meets its pairs.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("starlette")

from pinmech.design.synthesis.file import load_synthesis  # noqa: E402
from pinmech.draw.design_page.session import Session, read_design_file  # noqa: E402
from pinmech.draw.design_page.synthesis import close_run, synthesis_answer  # noqa: E402
from pinmech.draw.design_page.synthesis_task import KINDS, TASKS, Request, checked_toml  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: Five points of an arc (radius 40 mm about (60, 20) mm), a pose's angle its tangent's.
ARC = [(0.06 + 0.04 * math.cos(t), 0.02 + 0.04 * math.sin(t), t + math.pi / 2) for t in np.linspace(0, 2, 5)]


def _message(kind: str, task: str) -> dict:
    pairs = [[math.radians(20 * i), -0.01 * i if kind == "slider-crank" else math.radians(12 * i)] for i in range(5)]
    return {"type": "synthesise", "kind": kind, "task": task, "targets": [p[:2] for p in ARC],
            "poses": [list(p) for p in ARC], "pairs": pairs, "ground": 0.1, "max_crank": 0.1}


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("task", TASKS)
def test_each_task_of_each_kind_is_a_file_the_synthesis_reader_reads_back(kind, task, tmp_path):
    file = tmp_path / "page.toml"
    file.write_text(checked_toml(Request(_message(kind, task)), file))
    spec = load_synthesis(file)
    assert (spec.topology, spec.task) == (kind, task)
    if task == "function":  # the pairs, turns from the first, in SI
        assert np.allclose(spec.targets, _message(kind, task)["pairs"], atol=1e-8)
    else:  # the places to the micrometre written (edits.DECIMALS), the angles to 1e-6 deg
        assert np.allclose(spec.targets, [p[:2] for p in ARC], atol=1e-6)
    if task == "motion":
        assert np.allclose(np.unwrap(spec.angles), [p[2] for p in ARC], atol=1e-7)


@pytest.mark.parametrize("change, said", [
    ({"targets": [[0.0, 0.0], [0.01, 0.0]]}, "at least 3 targets (now 2)"),
    ({"bounds": "crank = [\"10 mm\", \"80 mm\"]"}, "missing"),
    ({"bounds": "crank = [10 mm"}, "the bounds are not TOML"),
    ({"kind": "watt"}, "kind must be one of"),
    # rows of the wrong length were reshaped into other targets in silence (6 numbers: 3 points)
    ({"targets": [[0.0, 0.0, 0.0], [0.01, 0.01, 0.0]]}, "targets must be rows of 2 numbers, got of shape (2, 3)"),
    ({"targets": [0.0, 0.0, 0.01, 0.01, 0.02, 0.0]}, "targets must be rows of 2 numbers, got of shape (6,)"),
    ({"targets": [[0.0, 0.0], [0.01], [0.02, 0.0]]}, "targets must be rows of 2 numbers, got not numbers in rows"),
    ({"targets": "0,0 1,1 2,0"}, "targets must be rows of 2 numbers"),
    ({"task": "motion", "poses": [[0.0, 0.0], [0.01, 0.01], [0.02, 0.0]]}, "poses must be rows of 3 numbers"),
    ({"task": "function", "pairs": [[0.1, 0.2, 0.3]] * 3}, "pairs must be rows of 2 numbers"),
])
def test_a_request_the_reader_refuses_is_its_named_error_on_the_page(change, said):
    spec, source, _, _ = read_design_file(ROOT / "models" / "linkages" / "four_bar.toml")
    session = Session(spec, source)
    try:
        answer = synthesis_answer(session, {**_message("four-bar", "path"), **change})
    finally:
        close_run(session)
    assert not answer["running"] and said in answer["error"] and answer["error"].startswith("SceneError")


@pytest.mark.slow
def test_a_slider_crank_function_searched_on_the_page_meets_its_pairs_once_adopted():
    # The offset slider-crank (crank r = 40, rod l = 130, offset e = 50 mm): the block at
    # x(t) = r cos t + sqrt(l^2 - (r sin t - e)^2) (Norton 4.13); pairs from t = 20 deg.
    r, length, e = 0.04, 0.13, 0.05
    x = lambda t: r * math.cos(t) + math.sqrt(length**2 - (r * math.sin(t) - e) ** 2)
    turns = np.radians([0, 30, 60, 90, 120, 150])
    start = math.radians(20)
    pairs = [[t, x(start + t) - x(start)] for t in turns]
    spec, source, _, _ = read_design_file(ROOT / "models" / "linkages" / "four_bar.toml")
    session = Session(spec, source)
    try:
        message = {"type": "synthesise", "kind": "slider-crank", "task": "function", "pairs": pairs,
                   "max_crank": 0.1}
        assert synthesis_answer(session, message)["running"]
        answer = synthesis_answer(session, {"type": "synthesis"})
        while answer.get("running"):
            time.sleep(0.5)
            answer = synthesis_answer(session, {"type": "synthesis"})
        assert answer["answers"], answer
        frame = synthesis_answer(session, {"type": "adopt", "answer": 0})
        assert frame["ok"]
        turn = session.turn
        traced = answer["answers"][0]["traced"]
        block = turn.path(traced)[:, 0]
        driven = turn.values - turn.values[0]  # the answer is drawn at its first pair's pose
        travel = np.interp(turns, driven, block) - block[0]
        # the search meets each pair within 1e-3 mm of travel (its reported error); the
        # turn's 1-degree poses interpolated linearly add r dt^2 / 8 = 1.5e-6 m
        assert np.abs(travel - np.array(pairs)[:, 1]).max() < 1e-5
    finally:
        close_run(session)
