"""Drawings of the bundled models, opened in a real headless browser: the page is offline, the
mechanism is drawn seen along z (its crank at the crank's angle, not mirrored), it spans most
of the view, and a blank page or an empty scene fails the same checks. Grid and axes are
hidden for the measurements (seen from above they cover the page).

The poses are closed by hand: R-RTR with crank angle theta, B = AB (cos theta, sin theta),
link 3 runs from C towards B, so its angle is phi3 = atan2(B - C) and the slider sits at
-|CB| from B; the planar arm at (50, -65, -75) deg.
"""

from __future__ import annotations

import builtins
import importlib.util
import math
import re

import numpy as np
import pinocchio as pin
import pytest

from pinmech.draw import (
    Arrow,
    DrawError,
    animation_html,
    arrow_scales,
    live_viewer,
    load_visuals,
    snapshot_html,
)
from tests.browser import colour_mask, colour_share, read_png, screenshot, span_share
from tests.conftest import MODELS
from tests.tolerance import rounding

needs_meshcat = pytest.mark.skipif(
    importlib.util.find_spec("meshcat") is None,
    reason='drawing needs meshcat: pip install "pinmech[viz]"',
)
CRANK_RED = (0.85, 0.15, 0.15)  # crank AB of the R-RTR, link AB of the planar arm
Z = np.array([0.0, 0.0, 1.0])
AC = 0.05  # ground pivots A and C of the R-RTR [m]
AB = 0.10  # its crank [m]


def r_rtr_pose(theta: float) -> np.ndarray:
    """The R-RTR's closed configuration at crank angle theta [rad] (continuous joints: cos, sin)."""
    B = AB * np.array([math.cos(theta), math.sin(theta)])
    CB = B - np.array([AC, 0.0])
    phi3 = math.atan2(CB[1], CB[0])
    return np.array(
        [
            math.cos(theta),
            math.sin(theta),
            math.cos(phi3 - theta),
            math.sin(phi3 - theta),
            -np.linalg.norm(CB),
        ]
    )


def points(model: pin.Model, q: np.ndarray) -> dict[str, np.ndarray]:
    """The named points A, B, C, D (leaf links) in the world frame [m]."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    return {n: data.oMf[model.getFrameId(n, pin.FrameType.BODY)].translation.copy() for n in "ABCD"}


@pytest.fixture(scope="module")
def r_rtr():
    model = pin.buildModelFromUrdf(str(MODELS / "r_rtr.urdf"))
    return model, load_visuals(MODELS / "r_rtr.urdf", model)


@pytest.fixture(scope="module")
def planar_arm():
    model = pin.buildModelFromUrdf(str(MODELS / "planar_arm.urdf"))
    return model, load_visuals(MODELS / "planar_arm.urdf", model)


def test_the_hand_closed_r_rtr_pose_pins_link3_at_c(r_rtr):
    """The residual of the loop the drawings rely on: link 3's origin is on C at every angle;
    at 30 deg, link 3 is at atan2(0.05, 0.0866 - 0.05) = 53.794 deg and |CB| = 0.0620 m."""
    model, _ = r_rtr
    q = r_rtr_pose(math.radians(30))
    assert 30 + math.degrees(math.atan2(q[3], q[2])) == pytest.approx(53.794, abs=5e-4)
    assert q[4] == pytest.approx(-0.0620, abs=5e-5)
    data = model.createData()
    for theta in np.radians([0, 30, 90, 150, 275]):
        pin.forwardKinematics(model, data, r_rtr_pose(theta))
        np.testing.assert_allclose(
            data.oMi[model.getJointId("B_slider")].translation, [AC, 0, 0], atol=rounding(AC)
        )


def crank_angle_deg(pixels: np.ndarray) -> float:
    """Direction of the red crank on screen [deg, modulo 180], x right, y up: its principal axis.

    nan where fewer than 50 pixels are red.
    """
    rows, cols = np.nonzero(colour_mask(pixels, CRANK_RED))
    if len(rows) < 50:
        return math.nan
    xy = np.column_stack([cols, -rows]).astype(float)
    _, _, vt = np.linalg.svd(xy - xy.mean(axis=0), full_matrices=False)
    return math.degrees(math.atan2(vt[0, 1], vt[0, 0])) % 180


def _angle_gap(a: float, b: float) -> float:
    return abs((a - b + 90) % 180 - 90)


def _shot(tmp_path, page: str, name: str, fragment: str = "") -> np.ndarray:
    path = tmp_path / f"{name}.html"
    path.write_text(page, encoding="utf-8")
    return screenshot(path, tmp_path / f"{name}.png", fragment=fragment)


# ----------------------------------------------------------------------------- in a browser
@needs_meshcat
@pytest.mark.browser
def test_r_rtr_snapshot_fills_the_view_with_the_crank_at_30_deg(r_rtr, tmp_path):
    model, visuals = r_rtr
    q = r_rtr_pose(math.radians(30))
    named = points(model, q)
    arrows = [
        Arrow(named["D"], [0.3, -0.2, 0], (0.1, 0.2, 0.9), "v_D", "m/s"),
        Arrow(named["D"], [-1.0, -3.0, 0], (0.9, 0.5, 0.0), "a_D", "m/s^2"),
    ]
    page = snapshot_html(
        model, visuals, q, points=named, arrows=arrows, plane_normal=Z, show_grid=False
    )
    pixels = _shot(tmp_path, page, "r_rtr")
    assert span_share(pixels) > 0.7
    assert colour_share(pixels, CRANK_RED) > 0.005
    assert _angle_gap(crank_angle_deg(pixels), 30.0) < 3.0  # seen from +z, y up: not mirrored


@needs_meshcat
@pytest.mark.browser
def test_planar_arm_snapshot_fills_the_view_with_ab_at_50_deg(planar_arm, tmp_path):
    model, visuals = planar_arm
    q = np.radians([50, -65, -75])
    page = snapshot_html(
        model, visuals, q, points=points(model, q), plane_normal=Z, show_grid=False
    )
    pixels = _shot(tmp_path, page, "planar_arm")
    assert span_share(pixels) > 0.7
    assert colour_share(pixels, CRANK_RED) > 0.005
    assert _angle_gap(crank_angle_deg(pixels), 50.0) < 3.0


@needs_meshcat
@pytest.mark.browser
def test_an_animation_frame_chosen_in_the_address_shows_that_pose(r_rtr, tmp_path):
    """`page.html#frame=K` stops the animation at frame K: the crank is at the K-th angle."""
    model, visuals = r_rtr
    thetas = np.radians(np.arange(0, 180, 30))
    qs = [r_rtr_pose(t) for t in thetas]
    page = animation_html(
        model,
        visuals,
        qs,
        fps=10,
        points_per_frame=[points(model, q) for q in qs],
        plane_normal=Z,
        show_grid=False,
    )
    for k in (1, 3):
        pixels = _shot(tmp_path, page, f"frame{k}", fragment=f"frame={k}")
        assert span_share(pixels) > 0.4  # framed for all poses, so less than a snapshot
        assert colour_share(pixels, CRANK_RED) > 0.002
        assert _angle_gap(crank_angle_deg(pixels), math.degrees(thetas[k])) < 3.0


@pytest.mark.browser
def test_a_blank_page_fails_the_checks(tmp_path):
    pixels = _shot(
        tmp_path, "<!DOCTYPE html><html><body style='background:white'></body></html>", "blank"
    )
    assert span_share(pixels) == 0.0 and colour_share(pixels, CRANK_RED) == 0.0


@needs_meshcat
@pytest.mark.browser
def test_an_empty_scene_fails_the_checks(r_rtr, tmp_path):
    model, _ = r_rtr
    page = snapshot_html(model, pin.GeometryModel(), r_rtr_pose(0.0), show_grid=False)
    pixels = _shot(tmp_path, page, "empty")
    assert span_share(pixels) == 0.0 and colour_share(pixels, CRANK_RED) == 0.0


def test_the_measures_on_a_made_up_picture():
    """A red bar at 30 deg on white: its span and direction, read back."""
    pixels = np.ones((600, 800, 3))
    for s in np.linspace(0, 400, 2000):
        x, y = 200 + s * math.cos(math.radians(30)), 450 - s * math.sin(math.radians(30))
        pixels[int(y) - 5 : int(y) + 5, int(x) - 5 : int(x) + 5] = CRANK_RED
    assert span_share(pixels) == pytest.approx(
        (400 * math.cos(math.radians(30)) + 10) / 800, abs=0.01
    )
    assert colour_share(pixels, CRANK_RED) > 0.008  # the bar: about 4000 of 480 000 pixels
    assert colour_share(pixels * 0.6, CRANK_RED) == colour_share(
        pixels, CRANK_RED
    )  # shaded: same hue
    assert _angle_gap(crank_angle_deg(pixels), 30.0) < 0.5


def test_read_png_gives_rgb_floats(tmp_path):
    import matplotlib.image

    matplotlib.image.imsave(tmp_path / "x.png", np.zeros((4, 6, 3)))
    pixels = read_png(tmp_path / "x.png")
    assert pixels.shape == (4, 6, 3) and pixels.max() == 0.0


# ------------------------------------------------------------------------------ the page
@needs_meshcat
def test_pages_are_self_contained(r_rtr):
    """meshcat's script is inlined and nothing is fetched from a network."""
    model, visuals = r_rtr
    for page in (
        snapshot_html(model, visuals, r_rtr_pose(0.5)),
        animation_html(model, visuals, [r_rtr_pose(0.5), r_rtr_pose(0.7)]),
    ):
        assert len(page) > 500_000  # meshcat's JavaScript, embedded
        assert not re.search(
            r"""<script[^>]*\ssrc=|<link[^>]*href=|(src|href)=["']?(https?:)?//""", page
        )


@needs_meshcat
def test_the_title_states_the_arrow_scale_a_third_of_the_drawing(r_rtr):
    model, visuals = r_rtr
    q = r_rtr_pose(math.radians(30))
    start = points(model, q)["D"]
    arrows = [Arrow(start, [2.0, 0, 0], unit="m/s"), Arrow(start, [0, 1.0, 0], unit="m/s")]
    title = re.search(
        r"<title>(.*)</title>", snapshot_html(model, visuals, q, arrows=arrows)
    ).group(1)
    drawn_mm = float(re.search(r"1 m/s = ([0-9.]+) mm", title).group(1))
    size = _drawing_size(model, visuals, q)  # the longest arrow, 2 m/s, is a third of it
    assert drawn_mm * 2.0 == pytest.approx(size / 3 * 1000, rel=1e-2)
    assert "grid cells 20 mm" in title  # a round length near an eighth of the ~0.2 m drawing


def _drawing_size(model, visuals, q) -> float:
    data, gdata = model.createData(), visuals.createData()
    pin.updateGeometryPlacements(model, data, visuals, gdata, q)
    corners = []
    for obj, M in zip(visuals.geometryObjects, gdata.oMg):
        obj.geometry.computeLocalAABB()
        lo, hi = obj.geometry.aabb_local.min_, obj.geometry.aabb_local.max_
        corners += [
            M.act(np.array([x, y, z]))
            for x in (lo[0], hi[0])
            for y in (lo[1], hi[1])
            for z in (lo[2], hi[2])
        ]
    return float(np.max(np.ptp(np.array(corners), axis=0)))


def test_arrow_scales_make_each_units_longest_a_third():
    arrows = [
        Arrow(np.zeros(3), [3.0, 4.0, 0], unit="m/s"),
        Arrow(np.zeros(3), [1.0, 0, 0], unit="m/s"),
        Arrow(np.zeros(3), [0, 0, 50.0], unit="m/s^2"),
        Arrow(np.zeros(3), np.zeros(3), unit="N"),
    ]
    scales = arrow_scales(arrows, size=0.3)
    assert scales == pytest.approx({"m/s": 0.1 / 5.0, "m/s^2": 0.1 / 50.0, "N": 0.0})


# ------------------------------------------------------------------------------ errors
@needs_meshcat
@pytest.mark.parametrize(
    "q, shown", [(np.zeros(4), "got 4"), ([1, 0, 1, 0, np.nan], "nan"), ("abc", "abc")]
)
def test_a_wrong_configuration_is_named(r_rtr, q, shown):
    model, visuals = r_rtr
    with pytest.raises(DrawError, match=r"q must be 5 finite numbers \(model.nq\)") as info:
        snapshot_html(model, visuals, q)
    assert info.value.argument == "q" and shown in str(info.value)


@pytest.mark.parametrize("start, vector", [([0, 0], [1, 0, 0]), ([0, 0, 0], [1, np.inf, 0])])
def test_an_arrow_needs_two_finite_3_vectors(start, vector):
    with pytest.raises(DrawError, match="3 finite numbers"):
        Arrow(start, vector)


@needs_meshcat
def test_errors_name_the_argument(r_rtr, tmp_path):
    model, visuals = r_rtr
    q = r_rtr_pose(0.3)
    cases = [
        (lambda: snapshot_html(model, visuals, q, plane_normal=[0, 0, 0]), "plane_normal"),
        (lambda: snapshot_html(model, visuals, q, points={"P": [1, 2]}), "points['P']"),
        (
            lambda: snapshot_html(pin.Model(), visuals, np.zeros(0)),
            "visual_model",
        ),  # another model's
        (lambda: animation_html(model, visuals, []), "qs"),
        (lambda: animation_html(model, visuals, [q], fps=0), "fps"),
        (lambda: animation_html(model, visuals, [q, q], points_per_frame=[{}]), "points_per_frame"),
        (lambda: load_visuals(tmp_path / "missing.urdf", model), "urdf_path"),
    ]
    for call, argument in cases:
        with pytest.raises(DrawError) as info:
            call()
        assert info.value.argument == argument


def test_a_broken_mesh_is_a_draw_error(tmp_path, r_rtr):
    urdf = tmp_path / "broken.urdf"
    urdf.write_text(
        (MODELS / "r_rtr.urdf")
        .read_text()
        .replace('<box size="0.10 0.008 0.004"/>', '<mesh filename="package://nowhere/crank.stl"/>')
    )
    with pytest.raises(DrawError, match="broken.urdf") as info:
        load_visuals(urdf, r_rtr[0])
    assert info.value.argument == "urdf_path"


def test_missing_meshcat_names_the_extra(monkeypatch, r_rtr):
    model, visuals = r_rtr
    real_import = builtins.__import__

    def no_meshcat(name, *args, **kwargs):
        if name.split(".")[0] == "meshcat":
            raise ImportError("No module named 'meshcat'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_meshcat)
    with pytest.raises(ImportError, match=re.escape('pip install "pinmech[viz]"')):
        snapshot_html(model, visuals, r_rtr_pose(0.0))


# ------------------------------------------------------------------------------ live server
@needs_meshcat
def test_the_live_viewer_serves_on_loopback_and_stops(r_rtr):
    model, visuals = r_rtr
    with live_viewer(model, visuals, r_rtr_pose(0.3), plane_normal=Z) as view:
        assert view.url.startswith("http://127.0.0.1:")
        server = view.visualizer.window.server_proc
        assert server.poll() is None
    assert server.poll() is not None


def test_without_chromium_browser_tests_skip_and_ci_fails(monkeypatch):
    from tests import browser

    monkeypatch.setattr(browser, "CHROMIUM", None)
    monkeypatch.delenv("PINMECH_REQUIRE_BROWSER", raising=False)
    with pytest.raises(pytest.skip.Exception, match="chromium is not installed"):
        browser.require_browser()
    monkeypatch.setenv("PINMECH_REQUIRE_BROWSER", "1")
    with pytest.raises(pytest.fail.Exception, match="PINMECH_REQUIRE_BROWSER"):
        browser.require_browser()
