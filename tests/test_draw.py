"""Offline meshcat pages, opened in a real headless browser: the mechanism is drawn, framed
(it spans most of the view) and its crank's colour is there; a blank page fails the same
checks. Grid and axes are hidden for the measurement (seen edge-on they form a band)."""

from __future__ import annotations

import numpy as np
import pytest

from pinmech.cli import main
from tests.browser import colour_share, screenshot, span_share

pytest.importorskip("meshcat", reason='drawing needs pip install "pinmech[viz]"')
pytestmark = pytest.mark.browser
CRANK_RED = (0.85, 0.15, 0.15)


def _shot(tmp_path, argv):
    html = tmp_path / "page.html"
    assert main([*argv, "-o", str(html), "--no-grid"]) == 0
    text = html.read_text()
    for reference in ('src="http', "src='http", 'href="http', "href='http"):  # nothing fetched from a network
        assert reference not in text
    return screenshot(html, tmp_path / "page.png")


def test_r_rtr_snapshot_fills_the_view(scenes_dir, tmp_path):
    pixels = _shot(tmp_path, ["snapshot", str(scenes_dir / "r_rtr.toml"), "--arrows", "D.velocity", "D.acceleration"])
    assert span_share(pixels) > 0.5
    assert colour_share(pixels, CRANK_RED) > 0.002


def test_planar_arm_snapshot_fills_the_view(scenes_dir, tmp_path):
    pixels = _shot(tmp_path, ["snapshot", str(scenes_dir / "planar_arm.toml")])
    assert span_share(pixels) > 0.5
    assert colour_share(pixels, CRANK_RED) > 0.002  # link AB is drawn red too


def test_r_rtr_animation_first_frame(scenes_dir, tmp_path):
    pixels = _shot(tmp_path, ["animate", str(scenes_dir / "r_rtr.toml"), "--steps", "12"])
    assert span_share(pixels) > 0.25  # framed for the whole cycle, so smaller than one pose
    assert colour_share(pixels, CRANK_RED) > 0.001


def test_a_blank_page_fails_the_checks(tmp_path):
    page = tmp_path / "blank.html"
    page.write_text("<!DOCTYPE html><html><body style='background:white'></body></html>")
    pixels = screenshot(page, tmp_path / "blank.png")
    assert span_share(pixels) == 0.0 and colour_share(pixels, CRANK_RED) == 0.0


def test_an_empty_scene_fails_the_checks(tmp_path, models_dir):
    from pinmech import Mechanism
    from pinmech.draw import Drawing

    drawing = Drawing(Mechanism.from_urdf(models_dir / "r_rtr.urdf"), show_grid=False)
    drawing.vis["pinmech"].set_property("visible", False)
    page = tmp_path / "empty.html"
    page.write_text(drawing.html())
    assert span_share(screenshot(page, tmp_path / "empty.png")) == 0.0


def test_missing_meshcat_names_the_extra(monkeypatch, scenes_dir, tmp_path, capsys):
    import builtins

    real_import = builtins.__import__

    def no_meshcat(name, *args, **kwargs):
        if name.startswith("meshcat"):
            raise ImportError("No module named 'meshcat'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_meshcat)
    assert main(["snapshot", str(scenes_dir / "r_rtr.toml"), "-o", str(tmp_path / "x.html")]) == 2
    assert 'pip install "pinmech[viz]"' in capsys.readouterr().err


def test_arrows_must_name_a_point_quantity(scenes_dir, tmp_path, capsys):
    assert main(["snapshot", str(scenes_dir / "r_rtr.toml"), "-o", str(tmp_path / "x.html"), "--arrows", "Q.speed"]) == 2
    assert "expected POINT.velocity" in capsys.readouterr().err


def test_arrows_are_scaled_per_kind():
    from pinmech.draw import Arrow

    arrows = [Arrow(np.zeros(3), np.array([1.0, 0, 0]), (0, 0, 1)), Arrow(np.zeros(3), np.array([10.0, 0, 0]), (1, 0, 0))]
    assert len({a.color for a in arrows}) == 2


def test_live_viewer_serves_on_loopback(scenes_dir, monkeypatch, capsys):
    """`pinmech view` starts meshcat's server on this machine and prints its URL."""
    monkeypatch.setattr("builtins.input", lambda prompt="": "")
    assert main(["view", str(scenes_dir / "r_rtr.toml")]) == 0
    assert "http://127.0.0.1:" in capsys.readouterr().out
