"""A real browser for page tests: headless Debian chromium takes a screenshot of a saved
HTML file, and the pixels say whether the mechanism is drawn and framed."""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
# Flags for a closed network: no sandbox (root), no GPU (software WebGL via SwiftShader),
# no background networking; a virtual time budget lets the page draw, then exit.
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader", "--disable-quic",
         "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--virtual-time-budget=3000", "--window-size=800,600"]


def require_browser() -> str:
    """The chromium executable; skips the test where there is none (fails in CI, which must have it)."""
    if CHROMIUM is None:
        if os.environ.get("PINMECH_REQUIRE_BROWSER"):
            pytest.fail("PINMECH_REQUIRE_BROWSER is set but no chromium is installed")
        pytest.skip("no chromium installed (apt-get install chromium)")
    return CHROMIUM


def screenshot(html_file: Path, png: Path) -> np.ndarray:
    """RGB pixels (floats in [0, 1]) of the page as headless chromium draws it."""
    exe = require_browser()
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run([exe, *FLAGS, f"--user-data-dir={profile}", f"--screenshot={png}", html_file.resolve().as_uri()],
                       capture_output=True, timeout=120, check=True)
    import matplotlib.image

    return matplotlib.image.imread(png)[:, :, :3]


def drawn_mask(pixels: np.ndarray) -> np.ndarray:
    """Pixels that are not the white background (meshcat's control bar, top right, left out)."""
    mask = np.any(pixels < 0.85, axis=2)
    mask[:30, -260:] = False
    return mask


def span_share(pixels: np.ndarray) -> float:
    """The larger of the width and height shares spanned by drawn pixels (0 for a blank page)."""
    ys, xs = np.nonzero(drawn_mask(pixels))
    if len(xs) < 50:
        return 0.0
    return max((xs.max() - xs.min()) / pixels.shape[1], (ys.max() - ys.min()) / pixels.shape[0])


def colour_share(pixels: np.ndarray, rgb: tuple[float, float, float], tol: float = 0.2) -> float:
    """Share of pixels close to a colour (shading varies, hence the tolerance)."""
    near = np.all(np.abs(pixels - np.asarray(rgb)) < tol, axis=2)
    return float(near.mean())
