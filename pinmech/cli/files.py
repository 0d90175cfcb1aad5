"""What a run reads and writes: inputs no output may overwrite, outputs written whole."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from pinmech.exceptions import PinmechError


def check_outputs(args: argparse.Namespace, scene) -> Path | None:
    """Before computing: the figure's format, one file per output, no output over an input.
    Returns the figure's path (".png" added to a name without suffix)."""
    from pinmech.outputs import check_distinct, plot_path

    figure = plot_path(args.plot_path) if args.plot_path else None
    if getattr(args, "paths_path", None):
        args.paths_path = plot_path(args.paths_path, "--paths")
    torque = getattr(args, "torque_plot", None)
    check_distinct({"--csv": args.csv_path, "--json": args.json_path, "--plot": figure,
                    "--paths": getattr(args, "paths_path", None),
                    "--torque-plot": plot_path(torque, "--torque-plot") if torque else None,
                    "--summary-json": getattr(args, "summary_json", None)},
                   inputs_of(scene))
    return figure




#: What each kind of model file is called in messages.
_MODEL_FILES = {"urdf": "the URDF", "robot": "the URDF", "linkage": "the linkage file", "mjcf": "the MJCF file"}


def inputs_of(scene, hand: str | None = None) -> dict[str, Path]:
    """What a run reads, which no output may overwrite: the scene, its model file, a
    sidecar (robot.yaml) and a hand file."""
    out = {"the scene file": scene.path, _MODEL_FILES.get(getattr(scene, "model_kind", ""), "the model file"):
           _urdf_path(scene)}
    if scene.file.sidecar is not None:
        out["the sidecar (robot.yaml)"] = scene.model_file("sidecar")
    if hand:
        out["the hand file"] = Path(hand)
    return out


def _urdf_path(scene) -> Path:
    """The model file the scene names (a URDF, a drawn linkage, an MJCF file): an input
    that no output may overwrite."""
    try:
        kind = scene.model_kind
        return scene.urdf if kind in ("urdf", "robot") else scene.model_file(kind)
    except (PinmechError, StopIteration):
        return scene.path


def write_text(path: str, text: str, what: str) -> None:
    """Write a whole file at once (a failed write leaves no half file behind) and say so."""
    from pinmech.outputs import write_whole

    write_whole(path, text)
    print(f"wrote {path} ({what}, {max(1, len(text) // 1024)} KB)", file=sys.stderr)


def check_page(args: argparse.Namespace, scene, hand: str | None = None) -> None:
    """Before computing: the output file can be made and is not an input."""
    from pinmech.outputs import check_distinct

    check_distinct({"-o": args.output}, inputs_of(scene, hand))


def write_page(path: str, html: str) -> None:
    from pinmech.outputs import write_whole

    write_whole(path, html)
    print(f"wrote {path} ({len(html) // 1024} KB, offline: open it in any browser)", file=sys.stderr)
