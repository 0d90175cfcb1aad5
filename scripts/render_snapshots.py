"""Regenerate the README's pictures: each bundled mechanism's snapshot, as headless
chromium draws the offline meshcat page (the same route as the browser tests).

Run: python scripts/render_snapshots.py      (needs pinmech[viz] and Debian's chromium)
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"
SCENES = {
    "r_rtr": ["--arrows", "D.velocity", "D.acceleration"],
    "planar_arm": ["--arrows", "D.velocity"],
    "four_bar": ["--arrows", "P.velocity"],
    "slider_crank": [],
}
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader", "--disable-quic",
         "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--virtual-time-budget=3000", "--window-size=800,600"]


def main() -> None:
    chromium = shutil.which("chromium")
    if chromium is None:
        print("this script needs Debian's chromium: apt-get install chromium")
        return
    try:
        import meshcat  # noqa: F401
    except ImportError:
        print('this script needs meshcat: pip install "pinmech[viz]"')
        return
    from pinmech.cli import main as pinmech

    IMAGES.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for name, extra in SCENES.items():
            html = Path(tmp) / f"{name}.html"
            pinmech(["snapshot", str(ROOT / "models" / "scenes" / f"{name}.toml"), "-o", str(html), "--no-grid", *extra])
            png = IMAGES / f"{name}.png"
            subprocess.run([chromium, *FLAGS, f"--user-data-dir={tmp}/profile", f"--screenshot={png}", html.as_uri()],
                           capture_output=True, timeout=120, check=True)
            print(f"wrote {png}")


if __name__ == "__main__":
    main()
