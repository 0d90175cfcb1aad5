"""The design page's engine side (pinmech design): Barker's table, drags that keep the
drawing's constructions, the errors of a drag that cannot be drawn, the files it saves,
and a server that listens on 127.0.0.1 only and refuses requests without its token.
The page in a real browser: tests/test_design_page_browser.py."""

from __future__ import annotations

import json
import shutil
import tomllib
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("starlette")
pytest.importorskip("uvicorn")

from pinmech.draw.design_page.edits import move_joint  # noqa: E402
from pinmech.draw.design_page.messages import Saving  # noqa: E402
from pinmech.draw.design_page.save import leading_comments  # noqa: E402
from pinmech.draw.design_page.server import PageServer  # noqa: E402
from pinmech.draw.design_page.session import Session, read_design_file  # noqa: E402
from pinmech.model.linkage import linkage_from_spec  # noqa: E402
from pinmech.model.linkage_spec import read_linkage_spec  # noqa: E402
from pinmech.solve.barker import barker_class  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FOUR_BAR = ROOT / "models" / "linkages" / "four_bar.toml"
#: A dragged place is written to 1e-3 mm (edits.DECIMALS): each compass length within
#: 0.5e-6 m, so the joint lands within about 1e-6 m of the mouse (lengths ~0.1 m, angles O(1)).
DRAG_TOL = 2e-6


# ---------------------------------------------------------------- Barker (Norton table 2-4)
@pytest.mark.parametrize("lengths, name, code", [
    ((100, 40, 120, 80), "I-2", "GCRR"),    # the bundled crank-rocker: the input shortest
    ((40, 100, 120, 80), "I-1", "GCCC"),    # the ground shortest: a drag-link (double crank)
    ((100, 80, 40, 120), "I-3", "GRCR"),    # the coupler shortest: a Grashof double rocker
    ((100, 80, 120, 40), "I-4", "GRRC"),    # the output shortest
    ((200, 60, 80, 90), "II-1", "RRR1"),    # s + l = 260 > 170, the ground longest
    ((60, 200, 80, 90), "II-2", "RRR2"),
    ((100, 80, 50, 70), "III-3", "SRCR"),   # s + l = 150 = p + q, the coupler shortest
    ((100, 40, 100, 40), "III-5", "S2X"),   # a parallelogram: two equal pairs
    ((50, 50, 50, 50), "III-6", "S3X"),     # a rhombus: all four equal
])
def test_barker_class_is_norton_table(lengths, name, code):
    found = barker_class(*lengths)
    assert (found.name, found.code) == (name, code)


def test_barker_refuses_a_zero_length():
    with pytest.raises(ValueError, match="positive"):
        barker_class(100, 0, 120, 80)


# ---------------------------------------------------------------- drags
def test_dragged_compass_joint_lands_on_the_mouse_and_stays_a_compass():
    spec, source = read_linkage_spec(FOUR_BAR)
    points = linkage_from_spec(spec, source).points
    to = np.array([0.0712345, 0.0934567])
    moved = move_joint(spec, "B", to, points, source)
    assert type(moved.joints["B"]).__name__ == "Compass"
    assert np.linalg.norm(linkage_from_spec(moved, source).points["B"] - to) < DRAG_TOL


def test_dragged_compass_joint_across_its_base_line_changes_side():
    spec, source = read_linkage_spec(FOUR_BAR)
    points = linkage_from_spec(spec, source).points
    moved = move_joint(spec, "B", np.array([0.07, -0.09]), points, source)  # below A -> O4
    assert moved.joints["B"].side == "right"
    assert np.linalg.norm(linkage_from_spec(moved, source).points["B"] - [0.07, -0.09]) < DRAG_TOL


def test_a_coordinate_written_as_a_parameter_moves_the_parameter():
    spec, source = read_linkage_spec(FOUR_BAR)
    points = linkage_from_spec(spec, source).points
    moved = move_joint(spec, "A", np.array([0.03, 0.01]), points, source)
    assert moved.params["crank"] == "30 mm" and moved.joints["A"] == ("crank", "10 mm")


def test_a_drag_that_cannot_be_drawn_names_its_error_and_keeps_the_last_drawing():
    spec, source, _, _ = read_design_file(FOUR_BAR)
    session = Session(spec, source)
    before = session.spec
    answer = session.drag("A", 0.5, 0.0)  # |A O4| = 0.4 m > 0.12 + 0.08 m: B cannot be drawn
    assert not answer["ok"]
    assert answer["error"].startswith("ModelError") and "[joints] B" in answer["error"]
    assert "do not meet" in answer["error"]
    assert session.spec is before


def test_the_turn_of_a_non_grashof_drawing_stops_at_its_fold():
    spec, source, driver, speed = read_design_file(ROOT / "models" / "linkages" / "stephenson.toml")
    frame = Session(spec, source, driver=driver, speed=speed).first
    assert frame["stopped"]["why"].startswith("DriverLimitError")
    stop = frame["stopped"]["index"]
    assert all(frame["solved"][:stop]) and not any(frame["solved"][stop:])


# ---------------------------------------------------------------- saving
def test_saved_linkage_reads_back_as_the_page_holds_it(tmp_path):
    copy = tmp_path / "four_bar.toml"
    shutil.copy(FOUR_BAR, copy)
    spec, source, _, _ = read_design_file(copy)
    session = Session(spec, source)
    session.drag("B", 0.0712345, 0.0934567)
    saving = Saving(copy, leading_comments(copy))
    answer = saving.save(session, {"type": "save", "svg": "<svg xmlns='http://www.w3.org/2000/svg'/>"})
    assert answer["ok"], answer
    again, _ = read_linkage_spec(copy)
    assert again == session.spec
    assert copy.read_text().startswith("# The bundled crank-rocker four-bar")
    scene = tomllib.loads(saving.scene.read_text())
    assert scene["linkage"] == "four_bar.toml" and list(scene["drivers"]) == ["O2"]
    assert (tmp_path / "four_bar.svg").read_text().startswith("<svg")
    assert not list(tmp_path.glob("*.partial")) and not list(tmp_path.glob(".*tmp*"))


@pytest.mark.parametrize("figure, said", [
    ({"svg": "<svg/>", "png": "data:image/png;base64,!!!!"}, "base64 data is malformed"),
    ({"svg": "<svg/>", "png": "data:image/png;base64,R0lGODlh"}, "not a PNG"),
    ({"svg": "<svg/>", "png": "http://example.com/a.png"}, "not a data:image/png;base64 URL"),
    ({"svg": 12}, "SVG that is not text (a int)"),
    ({"svg": "<svg/>", "png": ["x"]}, "PNG that is not a data URL (a list)"),
])
def test_a_save_with_a_bad_figure_writes_no_file_and_says_why(tmp_path, figure, said):
    """The figure is checked before the linkage, its scene or the SVG are written: a save
    refused half-way left three files of four, and the user's linkage rewritten."""
    copy = tmp_path / "four_bar.toml"
    shutil.copy(FOUR_BAR, copy)
    before = copy.read_bytes()
    spec, source, _, _ = read_design_file(copy)
    session = Session(spec, source)
    session.drag("B", 0.0712345, 0.0934567)
    answer = Saving(copy, leading_comments(copy)).save(session, {"type": "save", **figure})
    assert not answer["ok"] and answer["error"].startswith("PinmechError") and said in answer["error"], answer
    assert sorted(p.name for p in tmp_path.iterdir()) == ["four_bar.toml"] and copy.read_bytes() == before


@pytest.mark.parametrize("index", [-1, 361, 10**30])  # a turn of 1-degree poses, both ends: 0 to 360
def test_a_drag_at_a_pose_the_turn_has_not_is_refused_not_taken_at_the_drawn_pose(index):
    spec, source, _, _ = read_design_file(FOUR_BAR)
    session = Session(spec, source)
    before = session.spec
    answer = session.drag("B", 0.0712345, 0.0934567, index=index)
    assert not answer["ok"] and f"at pose {index}: the turn's poses are 0 to 360" in answer["error"]
    assert session.spec is before


def test_a_drag_at_a_pose_past_the_fold_is_refused():
    """A non-Grashof drawing's turn stops at its fold: the poses past it are not drawn."""
    spec, source, driver, speed = read_design_file(ROOT / "models" / "linkages" / "stephenson.toml")
    session = Session(spec, source, driver=driver, speed=speed)
    past = session.first["stopped"]["index"] + 1
    answer = session.drag(session.turn.names[-1], 0.01, 0.02, index=past)
    assert not answer["ok"] and "drawn only where it was solved" in answer["error"]


# ---------------------------------------------------------------- the server
@pytest.fixture
def server(tmp_path):
    spec, source, _, _ = read_design_file(FOUR_BAR)
    session = Session(spec, source)
    page = PageServer(session, Saving(tmp_path / "four_bar.toml", "")).start()
    yield page
    page.stop()


def test_server_listens_on_loopback_only(server):
    assert server.socket.getsockname()[0] == "127.0.0.1"
    assert server.url.startswith(f"http://127.0.0.1:{server.port}/?token=")


def _status(url: str) -> int:
    try:
        with urllib.request.urlopen(url, timeout=10) as reply:
            return reply.status
    except urllib.error.HTTPError as exc:
        return exc.code


def test_server_refuses_requests_without_its_token(server):
    base = f"http://127.0.0.1:{server.port}/"
    assert _status(server.url) == 200
    assert _status(base) == 403
    assert _status(base + "?token=not-the-token") == 403
    assert _status(base + "anything/else?token=" + server.token) == 403


def test_websocket_without_the_token_is_closed_with_policy_violation(server):
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    with pytest.raises(InvalidStatus) as refused:  # closed before it opens: the handshake fails
        with connect(f"ws://127.0.0.1:{server.port}/ws?token=wrong", open_timeout=10):
            pass
    assert refused.value.response.status_code == 403
    with connect(f"ws://127.0.0.1:{server.port}/ws?token={server.token}", open_timeout=10) as ws:
        first = json.loads(ws.recv(timeout=30))
        assert first["type"] == "frame" and first["ok"]


# ---------------------------------------------------------------- the command
@pytest.mark.parametrize("file, said", [
    ("models/linkages/rsur.toml", "planar linkages only"),
    ("models/linkages/no_such_linkage.toml", "no_such_linkage.toml"),
])
def test_design_command_refuses_what_it_cannot_draw_in_one_line(file, said, capsys):
    from pinmech.cli import main

    assert main(["design", str(ROOT / file), "--no-browser"]) != 0
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_a_synthesis_file_opens_on_its_best_answer_with_the_others_listed(tmp_path):
    from pinmech.draw.design_page.synthesis import adopt_run, open_synthesis, synthesis_answer

    text = (ROOT / "models" / "synthesis" / "four_bar_path.toml").read_text()
    file = tmp_path / "path.toml"
    file.write_text(text.replace("generations = 400", "generations = 60"))
    run, answer = open_synthesis(file)
    try:
        assert answer["answers"] and len(run.specs) == len(answer["answers"])
        session = Session(run.specs[0], str(tmp_path / "path_design.toml"))
        adopt_run(session, run)
        listed = synthesis_answer(session, {"type": "synthesis"})
        assert [a["summary"] for a in listed["answers"]] == [a["summary"] for a in answer["answers"]]
        # the answer the page opens passes the file's first target (pinmech synth met it within 1e-4 m)
        first = np.array([0.102112, 0.032029])
        curve = session.turn.path("P")
        assert np.nanmin(np.linalg.norm(curve - first, axis=1)) < 1e-4
    finally:
        run.close()


def test_a_compass_length_written_as_a_parameter_moves_the_parameter():
    spec, source = read_linkage_spec(ROOT / "models" / "linkages" / "watt_params.toml")
    points = linkage_from_spec(spec, source).points
    to = points["D"][:2] + [0.002, 0.001]
    moved = move_joint(spec, "D", to, points, source)
    assert moved.joints["D"].lengths == ("link5", "link6")  # the construction still names them
    c, o6 = points["C"][:2], points["O6"][:2]
    assert abs(float(moved.params["link5"].split()[0]) * 1e-3 - np.linalg.norm(to - c)) < 1e-6
    assert abs(float(moved.params["link6"].split()[0]) * 1e-3 - np.linalg.norm(to - o6)) < 1e-6


def test_a_parameter_shared_by_two_lengths_is_not_moved_by_one_drag(tmp_path):
    text = FOUR_BAR.read_text().replace('crank = "40 mm"', 'crank = "40 mm"\nside = "100 mm"').replace(
        'lengths = ["120 mm", "80 mm"]', 'lengths = ["side", "side"]')
    (tmp_path / "rhombus.toml").write_text(text)
    spec, source = read_linkage_spec(tmp_path / "rhombus.toml")
    points = linkage_from_spec(spec, source).points
    to = points["B"][:2] + [0.003, 0.0]
    moved = move_joint(spec, "B", to, points, source)
    assert moved.params["side"] == "100 mm" and "side" not in moved.joints["B"].lengths
    assert np.linalg.norm(linkage_from_spec(moved, source).points["B"][:2] - to) < DRAG_TOL
