"""A real browser for page tests: Debian's chromium, headless (`pinmech.draw.browser`, the
route the README's pictures take too), takes a screenshot of a saved HTML file, and the
pixels say whether something is drawn, how much of the view it spans and whether a colour
is there.
"""

from __future__ import annotations

import colorsys
import os
from pathlib import Path

import numpy as np
import pytest

from pinmech.draw.browser import find_chromium, photograph

CHROMIUM = find_chromium()
BACKGROUND = 0.9  # a pixel with every channel above this is the white page
UI_BOXES = (
    (slice(0, 30), slice(-260, None)),  # meshcat's "Open Controls" bar, top right
    (slice(-24, None), slice(None)),
)  # pinmech's legend line, at the bottom


def require_browser() -> str:
    """The chromium executable; skips the test where none is installed.

    CI sets PINMECH_REQUIRE_BROWSER, and there a missing chromium fails instead.
    """
    if CHROMIUM is None:
        if os.environ.get("PINMECH_REQUIRE_BROWSER"):
            pytest.fail("PINMECH_REQUIRE_BROWSER is set but chromium is not installed")
        pytest.skip("chromium is not installed (apt-get install chromium)")
    return CHROMIUM


def screenshot(html_file: Path, png: Path, *, fragment: str = "", window: tuple[int, int] = (800, 600)) -> np.ndarray:
    """RGB pixels (floats in [0, 1], shape (height, width, 3)) of the page as chromium draws it."""
    photograph(require_browser(), html_file, png, fragment=fragment, window=window)
    return read_png(png)


def read_png(png: Path) -> np.ndarray:
    """RGB pixels of a PNG file, floats in [0, 1]."""
    import matplotlib.image

    return np.asarray(matplotlib.image.imread(png))[:, :, :3]


def drawn_mask(pixels: np.ndarray) -> np.ndarray:
    """Pixels that are not the white page, meshcat's control bar and the legend left out."""
    mask = np.any(pixels < BACKGROUND, axis=2)
    for rows, cols in UI_BOXES:
        mask[rows, cols] = False
    return mask


def span_share(pixels: np.ndarray, min_pixels: int = 50) -> float:
    """The larger of the width and height shares of the view spanned by drawn pixels.

    0 for a page with fewer than `min_pixels` drawn pixels (blank, or a speck).
    """
    ys, xs = np.nonzero(drawn_mask(pixels))
    if len(xs) < min_pixels:
        return 0.0
    height, width = pixels.shape[:2]
    return max((xs.max() - xs.min() + 1) / width, (ys.max() - ys.min() + 1) / height)


def colour_share(pixels: np.ndarray, rgb: tuple[float, float, float]) -> float:
    """Share of the view's pixels of the colour (as `colour_mask` finds it)."""
    return float(colour_mask(pixels, rgb).mean())


def colour_mask(
    pixels: np.ndarray,
    rgb: tuple[float, float, float],
    *,
    hue_tol: float = 0.04,
    min_saturation: float = 0.45,
    min_value: float = 0.25,
) -> np.ndarray:
    """Pixels of the colour's hue (within `hue_tol` turns), saturated and lit.

    Shading changes a surface's brightness, not its hue, hence a hue test.
    """
    hue = colorsys.rgb_to_hsv(*rgb)[0]
    value = pixels.max(axis=2)
    spread = value - pixels.min(axis=2)
    saturation = np.where(value > 0, spread / np.maximum(value, 1e-9), 0.0)
    distance = np.abs((_hues(pixels, value, spread) - hue + 0.5) % 1.0 - 0.5)
    return (distance < hue_tol) & (saturation > min_saturation) & (value > min_value)


def _hues(pixels: np.ndarray, value: np.ndarray, spread: np.ndarray) -> np.ndarray:
    """Hue in turns [0, 1) of every pixel (as colorsys.rgb_to_hsv, vectorised)."""
    r, g, b = (pixels[..., i] for i in range(3))
    safe = np.maximum(spread, 1e-9)
    hue = np.where(
        value == r, (g - b) / safe, np.where(value == g, 2.0 + (b - r) / safe, 4.0 + (r - g) / safe)
    )
    return (hue / 6.0) % 1.0


def print_pdf(html_file: Path, pdf: Path, paper: str | None = None) -> Path:
    """The page printed to PDF by headless chromium (as a reader's "print to PDF"); `paper`
    ("A4", "letter"): the paper chosen in the print dialog (else chromium's default, Letter)."""
    from pinmech.draw.browser import chromium_profile, run_chromium

    if paper is not None:  # as a reader picks a paper size: a copy of the page asks for it
        text = Path(html_file).read_text(encoding="utf-8")
        html_file = Path(pdf).with_suffix(".html")
        html_file.write_text(text.replace("</style>", f"@page {{size: {paper}}}</style>", 1), encoding="utf-8")
    with chromium_profile() as profile:
        run_chromium([require_browser(), "--headless", "--no-sandbox", "--disable-gpu", "--no-pdf-header-footer",
                      f"--user-data-dir={profile}", f"--print-to-pdf={pdf}", Path(html_file).resolve().as_uri()],
                     timeout_s=120)
    return pdf


def page_dom(html_file: Path, *, fragment: str = "") -> str:
    """The page's DOM as chromium holds it once its scripts have run (`--dump-dom`)."""

    from pinmech.draw.browser import chromium_command, chromium_profile, run_chromium

    with chromium_profile() as profile:
        command = [c for c in chromium_command(require_browser(), html_file, profile / "x.png", profile,
                                               fragment=fragment) if not c.startswith("--screenshot")]
        done = run_chromium([*command[:-1], "--dump-dom", command[-1]], timeout_s=90)
    return done.stdout


def pdf_pages(pdf: Path) -> int:
    """The number of pages of a PDF file (`pdfinfo`, poppler-utils)."""
    import re
    import shutil
    import subprocess

    if shutil.which("pdfinfo") is None:
        if os.environ.get("PINMECH_REQUIRE_BROWSER"):
            pytest.fail("PINMECH_REQUIRE_BROWSER is set but pdfinfo is not installed (apt-get install poppler-utils)")
        pytest.skip("pdfinfo is not installed (apt-get install poppler-utils)")
    out = subprocess.run(["pdfinfo", str(pdf)], check=True, capture_output=True, text=True).stdout
    return int(re.search(r"^Pages:\s+(\d+)", out, re.MULTILINE).group(1))
