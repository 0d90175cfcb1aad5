"""Headless chromium, photographing a saved page: the docs' pictures and the page tests
take the same route.

The command line that works here (Debian's chromium, no GPU, no network, root): software
WebGL through SwiftShader (`--enable-unsafe-swiftshader`; `--use-gl=swiftshader` gives a
blank page), no background networking, and a virtual time budget that lets the page draw
and then exits (a budget of 0 or 100 ms hangs, so a subprocess timeout guards).
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
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
#: How long a used profile's removal is retried while chromium's helper processes let go [s].
PROFILE_CLEANUP_S = 10.0


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


@contextmanager
def chromium_profile(prefix: str = "pinmech-chromium-") -> Iterator[Path]:
    """A fresh, empty chromium profile folder, removed after use.

    Chromium's helper processes (crashpad, the GPU and utility processes) can still write
    into the profile for a moment after the browser itself has exited, so a plain removal
    races them ("Directory not empty"); it is retried for up to PROFILE_CLEANUP_S."""
    folder = Path(tempfile.mkdtemp(prefix=prefix))
    try:
        yield folder
    finally:
        remove_profile(folder)


def remove_profile(folder: Path, within_s: float = PROFILE_CLEANUP_S) -> None:
    """Remove a used profile folder, retrying while something still writes into it; what is
    left after `within_s` [s] (a stuck helper's files) stays in the temporary folder."""
    deadline = time.monotonic() + within_s
    while True:
        try:
            shutil.rmtree(folder)
            return
        except FileNotFoundError:
            return
        except OSError:
            if time.monotonic() > deadline:
                shutil.rmtree(folder, ignore_errors=True)
                return
            time.sleep(0.05)


def end_process_group(process: subprocess.Popen, timeout_s: float = 10.0) -> None:
    """End a browser started with `start_new_session=True` and every helper it left behind:
    SIGTERM to its process group, SIGKILL to what is still there after `timeout_s` [s]."""
    for sent in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(process.pid, sent)
        except (ProcessLookupError, PermissionError):
            pass  # the group is gone already
        try:
            process.wait(timeout=timeout_s)
            break
        except subprocess.TimeoutExpired:
            continue
    deadline = time.monotonic() + timeout_s  # helpers outliving the browser itself
    while time.monotonic() < deadline:
        try:
            os.killpg(process.pid, 0)
        except (ProcessLookupError, PermissionError):
            return
        time.sleep(0.05)


def run_chromium(command: list[str], timeout_s: float) -> subprocess.CompletedProcess:
    """Run a headless chromium command to its end, with its helpers ended with it.

    Raises:
        subprocess.TimeoutExpired: still running after `timeout_s` [s] (the browser is ended).
        subprocess.CalledProcessError: chromium exited with a failure.
    """
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
    try:
        out, err = process.communicate(timeout=timeout_s)
    finally:
        end_process_group(process)
    if process.returncode:
        raise subprocess.CalledProcessError(process.returncode, command, out, err)
    return subprocess.CompletedProcess(command, process.returncode, out, err)


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
    with chromium_profile() as profile:
        run_chromium(chromium_command(chromium, html_file, png, profile, fragment=fragment, window=window),
                     timeout_s)
    return Path(png)
