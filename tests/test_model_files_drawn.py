"""`pinmech snapshot` draws a drawn linkage, an MJCF leg and a URDF + robot.yaml five-bar.

Each page is photographed by headless chromium (tests/browser.py) without the grid: the
drawing must span most of the view (the camera frames the pose) and show its blue links
(Jansen's upper bar, the leg's shin, the five-bar's distal links), so a model loaded
without its visuals (a blank page, or points only) fails.
"""

from __future__ import annotations

import pytest

from pinmech.cli import main
from tests.browser import colour_share, screenshot, span_share

BLUE = (0.15, 0.35, 0.85)


@pytest.mark.browser
@pytest.mark.parametrize("scene", ["jansen", "leg_mjcf", "five_bar"])
def test_snapshot_shows_the_links(scenes_dir, tmp_path, scene):
    page = tmp_path / f"{scene}.html"
    assert main(["snapshot", str(scenes_dir / f"{scene}.toml"), "-o", str(page), "--no-grid"]) == 0
    pixels = screenshot(page, tmp_path / f"{scene}.png")
    assert span_share(pixels) > 0.5
    assert colour_share(pixels, BLUE) > 0.002
