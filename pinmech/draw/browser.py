"""Headless chromium, photographing a saved page: the docs' pictures and the page tests
take the same route.

The command line that works here (Debian's chromium, no GPU, no network, root): software
WebGL through SwiftShader (`--enable-unsafe-swiftshader`; `--use-gl=swiftshader` gives a
blank page), no background networking, and a virtual time budget that lets the page draw
and then exits (a budget of 0 or 100 ms hangs, so a subprocess timeout guards).
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
)
WINDOW = (800, 600)  # width, height of the view [pixels]
BUDGET_MS = 3000  # virtual time for the page to load and draw [ms]
TIMEOUT_S = 90  # wall-clock limit of one screenshot [s]


def find_chromium() -> str | None:
    """The chromium executable on the PATH, or None."""
    return shutil.which("chromium")


def chromium_command(
    chromium: str,
    html_file: Path,
    png: Path,
    profile: Path,
    *,
    fragment: str = "",
    budget_ms: int = BUDGET_MS,
    window: tuple[int, int] = WINDOW,
) -> list[str]:
    """The command line that draws `html_file` (address `#fragment` appended) into `png`."""
    url = Path(html_file).resolve().as_uri() + (f"#{fragment}" if fragment else "")
    return [
        chromium,
        *FLAGS,
        f"--window-size={window[0]},{window[1]}",
        f"--user-data-dir={profile}",
        f"--virtual-time-budget={budget_ms}",
        f"--screenshot={png}",
        url,
    ]


def photograph(
    chromium: str,
    html_file: Path,
    png: Path,
    *,
    fragment: str = "",
    window: tuple[int, int] = WINDOW,
    timeout_s: float = TIMEOUT_S,
) -> Path:
    """Save chromium's screenshot of a page as `png` (a fresh profile each time)."""
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run(
            chromium_command(chromium, html_file, png, Path(profile), fragment=fragment, window=window),
            capture_output=True,
            timeout=timeout_s,
            check=True,
        )
    return Path(png)
