"""`pinmech animate`: the GIF's frames against the closed form (a named point's pixel where
the closed form puts it), the page's controls in a real browser (the slider moves the
mechanism and the readout follows), task scenes animated from their path, and the named
errors (no ffmpeg for --mp4, a robot.yaml scene without drivers)."""

from __future__ import annotations

import base64
import json
import math
import re

import numpy as np
import pytest
from closed_form import planar_arm_forward

from pinmech import Scene
from pinmech.cli import main
from tests.conftest import SCENES
from tests.test_plot_design import _coupler_point

pytest.importorskip("matplotlib", reason='plots need pip install "pinmech[plot]"')
Image = pytest.importorskip("PIL.Image", reason='--gif needs pip install "pinmech[plot]"')

#: A point's dot (6 px across) found within this many pixels of where the closed form
#: puts it: the transform is exact; 1.5 px is rounding to the pixel grid and anti-aliasing.
PIXEL_TOL = 1.5
R_ARM = (0.3, 0.3, 0.17)  # AB, BC, CD of models/planar_arm.urdf [m] (tests/test_closed_form.py)


def _gif_frames(path) -> list[np.ndarray]:
    with Image.open(path) as gif:
        out = []
        for k in range(gif.n_frames):
            gif.seek(k)
            out.append(np.asarray(gif.convert("RGB"), dtype=float) / 255)
    return out


def _dot_near(pixels: np.ndarray, at: np.ndarray) -> float:
    """Distance [px] from `at` (column, row) to the centre of the black dot nearest it."""
    dark = np.all(pixels < 0.15, axis=2)
    rows, cols = np.nonzero(dark)
    near = np.hypot(cols - at[0], rows - at[1]) < 8
    if not near.any():
        return math.inf
    return float(np.hypot(cols[near].mean() - at[0], rows[near].mean() - at[1]))


def test_gif_has_a_frame_a_pose_and_p_follows_the_closed_form(tmp_path):
    """13 poses of the drawn four-bar from the scene's 60 deg, one every 30 deg: 13 frames;
    in frames 0, 4 and 9 the dot of P sits where the closed-form coupler point is."""
    from pinmech.draw.animation import driver_frames
    from pinmech.draw.animation_export import FrameRenderer

    gif = tmp_path / "fb.gif"
    assert main(["animate", str(SCENES / "four_bar_drawn.toml"), "--steps", "13", "--gif", str(gif)]) == 0
    frames = _gif_frames(gif)
    assert len(frames) == 13
    renderer = FrameRenderer(driver_frames(Scene.load(SCENES / "four_bar_drawn.toml"), None, None, 13))
    try:
        for k in (0, 4, 9):
            P = np.append(_coupler_point(np.array([60.0 + 30 * k]))[0] / 1000, 0.0)
            at = renderer.to_pixels(P)
            assert _dot_near(frames[k], at) < PIXEL_TOL, (k, at)
            # and not where P is 4 frames on: the dot moves
            later = renderer.to_pixels(np.append(_coupler_point(np.array([60.0 + 30 * (k + 4)]))[0] / 1000, 0.0))
            assert _dot_near(frames[k], later) > PIXEL_TOL
    finally:
        renderer.close()


def test_a_task_scene_animates_its_path(tmp_path):
    """The planar arm's task: D moves at 1 m/s along x from its place at the scene's pose,
    D(t) = D0 + (t, 0); 9 frames over the scene's 0.08 s, one every 10 ms."""
    from pinmech.draw.animation import task_frames
    from pinmech.draw.animation_export import FrameRenderer

    gif, page = tmp_path / "arm.gif", tmp_path / "arm.html"
    assert main(["animate", str(SCENES / "planar_arm.toml"), "--steps", "9", "--gif", str(gif), "-o", str(page)]) == 0
    frames = _gif_frames(gif)
    assert len(frames) == 9
    D0 = planar_arm_forward(np.radians([50, -65, -75]), np.zeros(3), np.zeros(3), *R_ARM).D
    renderer = FrameRenderer(task_frames(Scene.load(SCENES / "planar_arm.toml"), None, 9))
    try:
        for k in (0, 4, 8):
            at = renderer.to_pixels(np.array([D0[0] + 0.01 * k, D0[1], 0.0]))
            assert _dot_near(frames[k], at) < PIXEL_TOL, (k, at)
    finally:
        renderer.close()
    assert '"t = 0.040 s"' in page.read_text(encoding="utf-8")  # the readout of frame 4


def test_mp4_without_ffmpeg_is_a_named_error_before_anything_is_solved(tmp_path, monkeypatch, capsys):
    import pinmech.draw.animation_export
    import pinmech.io.sweep

    monkeypatch.setattr(pinmech.draw.animation_export.shutil, "which", lambda name: None)
    monkeypatch.setattr(pinmech.io.sweep.Sweep, "poses", lambda *a, **k: pytest.fail("solved before refusing"))
    assert main(["animate", str(SCENES / "four_bar.toml"), "--mp4", str(tmp_path / "a.mp4")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "ffmpeg" in err and "--mp4" in err and "Traceback" not in err
    assert not (tmp_path / "a.mp4").exists()


def test_missing_tool_is_a_pinmech_error():
    from pinmech.draw.animation_export import check_mp4
    from pinmech.exceptions import MissingTool, PinmechError

    assert issubclass(MissingTool, PinmechError) and MissingTool.exit_code == 2
    import shutil

    if shutil.which("ffmpeg") is None:
        with pytest.raises(MissingTool, match="needs ffmpeg") as caught:
            check_mp4("a.mp4")
        assert (caught.value.tool, caught.value.option) == ("ffmpeg", "--mp4")


def test_animate_needs_an_output(capsys):
    assert main(["animate", str(SCENES / "four_bar.toml")]) == 2
    assert "-o PAGE.html, --gif FILE.gif or --mp4 FILE.mp4" in capsys.readouterr().err


def test_robot_yaml_scene_without_drivers_says_what_to_add(tmp_path, capsys):
    """The Delta's scene names no drivers: add one table a motor (robot.yaml's name_mot),
    not a [[task]]."""
    assert main(["animate", str(SCENES / "delta.toml"), "-o", str(tmp_path / "d.html")]) == 4
    err = capsys.readouterr().err
    assert all(f"[drivers.mot{k}]" in err for k in (1, 2, 3)) and "[[task]]" not in err, err
    assert not (tmp_path / "d.html").exists()


def test_range_options_that_do_not_fit_the_scene_are_refused(tmp_path, capsys):
    assert main(["animate", str(SCENES / "planar_arm.toml"), "--from", "0 deg", "-o", str(tmp_path / "a.html")]) == 2
    assert "--from" in capsys.readouterr().err
    assert main(["animate", str(SCENES / "four_bar.toml"), "--duration", "1 s", "-o", str(tmp_path / "a.html")]) == 2
    assert "--duration" in capsys.readouterr().err


def _commands(page: str) -> list[dict]:
    import umsgpack

    return [umsgpack.unpackb(base64.b64decode(b)) for b in re.findall(r'command\("([^"]+)"\);', page)]


def test_a_planar_snapshot_is_an_orthographic_view_along_the_normal(tmp_path):
    """The camera of a planar mechanism's page is orthographic (no perspective) and sits on
    the plane's normal (+z: meshcat's camera frame is x +90 deg, so its position is (0, z, 0)
    up to the hair of tilt that keeps y up)."""
    page = tmp_path / "s.html"
    assert main(["snapshot", str(SCENES / "four_bar.toml"), "-o", str(page)]) == 0
    commands = _commands(page.read_text(encoding="utf-8"))
    (camera,) = [c["object"]["object"] for c in commands
                 if c["type"] == "set_object" and c["path"].endswith("/Cameras/default/rotated/<object>")]
    assert camera["type"] == "OrthographicCamera"
    (position,) = [c["value"] for c in commands if c["type"] == "set_property" and c["property"] == "position"
                   and c["path"].endswith("/Cameras/default/rotated/<object>")]
    np.testing.assert_allclose(np.array(position) / np.linalg.norm(position), [0, 1, 0], atol=2e-3)


def test_the_page_names_every_frame_and_traces_the_named_points(tmp_path):
    page = tmp_path / "a.html"
    assert main(["animate", str(SCENES / "four_bar.toml"), "--steps", "13", "-o", str(page)]) == 0
    text = page.read_text(encoding="utf-8")
    readouts = json.loads(re.search(r"var readouts = (\[.*?\]);", text).group(1))
    assert len(readouts) == 13 and readouts[:3] == ["O2 = 60.0°", "O2 = 90.0°", "O2 = 120.0°"]
    traces = [c for c in _commands(text) if c["type"] == "set_object" and "/traces/" in c["path"]]
    assert {c["path"].rsplit("/", 1)[1] for c in traces} == {"A", "B", "P"}
    labels = [c for c in _commands(text) if c["type"] == "set_object" and c["path"].endswith("/label")]
    assert len(labels) >= 5  # O2, A, B, O4, P


# ----------------------------------------------------------------------------- in a browser
@pytest.mark.browser
def test_the_slider_moves_the_mechanism_and_the_readout_follows(tmp_path):
    """The R-RTR's page, 13 frames from 30 deg: moving the slider to frame 3 (as a hand does:
    an input event) stops the motion, shows A = 120 deg in the readout, and the crank is
    drawn at 120 deg (mod 180, measured on the red pixels, 3 deg: a bar of 40 px)."""
    from tests.browser import page_dom, screenshot
    from tests.test_draw import _angle_gap, crank_angle_deg

    page = tmp_path / "r.html"
    assert main(["animate", str(SCENES / "r_rtr.toml"), "--steps", "13", "--no-grid", "-o", str(page)]) == 0
    dom = page_dom(page)  # playing: the readout follows the frames, the button offers to pause
    assert re.search(r'id="readout"[^>]*>A = \d+\.0°<', dom) and "\u275a\u275a pause" in dom
    for k in (3, 5):
        dom = page_dom(page, fragment=f"slider={k}")
        assert re.search(fr'id="readout"[^>]*>A = {30 + 30 * k:.1f}°<', dom), k
        assert "\u25b6 play" in dom  # the slider stopped it
        pixels = screenshot(page, tmp_path / f"r{k}.png", fragment=f"slider={k}")
        assert _angle_gap(crank_angle_deg(pixels), (30.0 + 30 * k) % 180) < 3.0


def test_animation_html_refuses_frames_it_cannot_draw_by_name():
    """Frames naming different points (a KeyError before), readouts or traces that do not
    fit the frames: each a DrawError naming the argument."""
    pytest.importorskip("meshcat", reason='needs pip install "pinmech[viz]"')
    import pinocchio as pin

    from pinmech.draw import DrawError, animation_html, load_visuals
    from tests.conftest import MODELS
    from tests.test_draw import r_rtr_pose

    urdf = MODELS / "r_rtr.urdf"
    model = pin.buildModelFromUrdf(str(urdf))
    visuals = load_visuals(urdf, model)
    qs = [r_rtr_pose(0.1), r_rtr_pose(0.2)]
    here = {"A": np.zeros(3), "B": np.ones(3)}
    with pytest.raises(DrawError, match=r"points_per_frame\[1\] names A, the first frame A, B") as caught:
        animation_html(model, visuals, qs, points_per_frame=[here, {"A": np.zeros(3)}])
    assert caught.value.argument == "points_per_frame"
    with pytest.raises(DrawError, match="3 readouts for 2 poses"):
        animation_html(model, visuals, qs, readouts=["a", "b", "c"])
    with pytest.raises(DrawError, match="traces of points not in points_per_frame: D"):
        animation_html(model, visuals, qs, points_per_frame=[here, here], traces={"D": (1.0, 0.0, 0.0)})
