"""Synthesis files: every mistake is one line on stderr naming the file and the key, with
the scene-file exit code (4); a synthesis that finds nothing says why (SynthesisError, exit 15)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from pinmech.cli import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "models" / "synthesis" / "four_bar_path.toml"


def _edited(tmp_path: Path, old: str, new: str, example: Path = EXAMPLE) -> Path:
    """The example with its first `old` replaced by `new`, written as tmp_path / bad.toml."""
    text = example.read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


def _refused_naming_file_and_key(path: Path, key: str, capsys) -> None:
    """`pinmech synth path` exits 4 with one line on stderr naming the file and the key."""
    assert main(["synth", str(path)]) == 4
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert str(path) in err and re.search(rf"[ ,]{re.escape(key)}[:,. ]", err), err


@pytest.mark.parametrize("old, new, key", [
    ('task = "path"', 'task = "paths"', "task"),
    ('topology = "four-bar"', 'topology = "five-bar"', "topology"),
    ('["102.112 mm", "32.029 mm"]', '["102.112", "32.029 mm"]', "targets[0]"),
    ('["102.112 mm", "32.029 mm"]', '["102.112 mm"]', "targets[0]"),
    ('["91.920 mm", "41.431 mm"]', '["102.112 mm", "32.029 mm"]', "targets[1]"),
    ('crank = ["10 mm", "80 mm"]', 'crank = ["80 mm", "10 mm"]', "bounds.crank"),
    ('crank = ["10 mm", "80 mm"]', 'crank = ["0 mm", "80 mm"]', "bounds.crank"),
    ('crank = ["10 mm", "80 mm"]', 'crank = ["10 deg", "80 mm"]', "bounds.crank"),
    ('crank = ["10 mm", "80 mm"]', 'krank = ["10 mm", "80 mm"]', "bounds.krank"),
    ('rocker = ["20 mm", "160 mm"]', '', "bounds"),
    ('y = ["-60 mm", "60 mm"] }     # the crank', 'z = ["-60 mm", "60 mm"] }     # the crank', "bounds.O2.z"),
    ('transmission = "25 deg"', 'transmission = "95 deg"', "constraints.transmission"),
    ('transmission = "25 deg"', 'transmission = "25 mm"', "constraints.transmission"),
    ('direction = "either"', 'direction = "up"', "constraints.direction"),
    ('direction = "either"', 'ratio = 1', "constraints.ratio"),
    ('seed = 2', 'seed = -1', "seed"),
    ('seed = 2', 'seed = 2\ntiming = ["0 deg", "10 deg"]', "timing"),
    ('seed = 2', 'seeds = 2', "seeds"),
])
def test_a_bad_synthesis_file_is_one_line_naming_file_and_key(tmp_path, capsys, old, new, key):
    _refused_naming_file_and_key(_edited(tmp_path, old, new), key, capsys)


def test_a_missing_synthesis_file_is_named(tmp_path, capsys):
    assert main(["synth", str(tmp_path / "none.toml")]) == 4
    assert "no such synthesis file" in capsys.readouterr().err


def test_no_linkage_found_is_an_error_with_the_rejected_counts(tmp_path, capsys):
    # A least transmission angle of 89 deg over a 270 deg motion: no four-bar has one
    # (the angle swings through a range as the crank turns), so every candidate is
    # rejected and the error says how many and why.
    path = _edited(tmp_path, 'transmission = "25 deg"', 'transmission = "89 deg"')
    text = path.read_text().replace("generations = 400", "generations = 3").replace("population = 15", "population = 5")
    path.write_text(text)
    assert main(["synth", str(path), "--out", str(tmp_path / "none")]) == 15
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(path) in err and "transmission angle" in err


def test_the_example_writes_linkages_the_engine_reproduces(tmp_path, capsys):
    # The bundled example (targets rounded to 1 um on the bundled four-bar's coupler curve):
    # its best linkage meets them within 1e-3 mm, and the engine sweeping the written scene
    # meets them as closely (the report's numbers are the engine's within 1e-9 mm).
    prefix = tmp_path / "fbp"
    assert main(["synth", str(EXAMPLE), "--out", str(prefix), "--plot"]) == 0
    summary = json.loads((tmp_path / "fbp.json").read_text())
    best = summary["linkages"][0]
    assert max(best["errors_mm"]) < 1e-3
    assert max(abs(a - b) for a, b in zip(best["errors_mm"], best["engine_errors_mm"])) < 1e-9
    assert (tmp_path / "fbp.png").stat().st_size > 10_000
    assert main(["solve", best["files"][1]]) == 0


FUNCTION = ROOT / "models" / "synthesis" / "four_bar_function.toml"


@pytest.mark.parametrize("old, new, key", [
    ('ground = "100 mm"', 'ground = "-100 mm"', "ground"),
    ('ground = "100 mm"', '', "ground"),
    ('["0.0000 deg", "0.0000 deg"],', '["1 deg", "0 deg"],', "pairs[0]"),
    ('["10.8981 deg", "21.1930 deg"]', '["10.8981 mm", "21.1930 deg"]', "pairs[1]"),
    ('["28.5317 deg", "49.5074 deg"]', '["5 deg", "49.5074 deg"]', "pairs"),
    ('ground = "100 mm"', 'ground = "100 mm"\ntargets = [["0 mm", "0 mm"]]', "targets"),
    ('coupler = ["20 mm", "300 mm"]', 'coupler = ["20 mm", "300 mm"]\npoint = ["0 mm", "1 mm"]', "bounds.point"),
    ('ratio = 6', 'ratio = 6\ndirection = "cw"', "constraints.direction"),
])
def test_a_bad_function_file_is_one_line_naming_file_and_key(tmp_path, capsys, old, new, key):
    _refused_naming_file_and_key(_edited(tmp_path, old, new, FUNCTION), key, capsys)


SLIDER_PATH = ROOT / "models" / "synthesis" / "slider_crank_path.toml"
SLIDER_FUNCTION = ROOT / "models" / "synthesis" / "slider_crank_function.toml"


@pytest.mark.parametrize("example, old, new, key", [
    (SLIDER_PATH, 'angle = ["-30 deg", "30 deg"]', 'angle = ["-30 mm", "30 mm"]', "bounds.slide.angle"),
    (SLIDER_PATH, 'offset = ["-100 mm", "100 mm"]', 'offset = ["100 mm", "-100 mm"]', "bounds.slide.offset"),
    (SLIDER_PATH, 'rod = ["40 mm", "200 mm"]', 'coupler = ["40 mm", "200 mm"]', "bounds.coupler"),
    (SLIDER_PATH, 'task = "path"', 'task = "motion"', "targets"),  # a motion takes poses
    (SLIDER_PATH, 'direction = "either"', 'grashof = "crank-rocker"', "constraints.grashof"),
    (SLIDER_FUNCTION, '["30 deg", "-8.149 mm"]', '["30 deg", "-8.149 deg"]', "pairs[1]"),
    (SLIDER_FUNCTION, 'keep = 2', 'keep = 2\nground = "100 mm"', "ground"),
])
def test_a_bad_slider_crank_file_is_one_line_naming_file_and_key(tmp_path, capsys, example, old, new, key):
    _refused_naming_file_and_key(_edited(tmp_path, old, new, example), key, capsys)


def test_the_slider_crank_example_writes_a_linkage_the_engine_reproduces(tmp_path, capsys):
    # The bundled slider-crank example (targets rounded to 1 um on the bundled slider-crank's
    # rod-point curve): its best linkage meets them within 1e-3 mm, the engine sweeping the
    # written scene as closely (the report's numbers are the engine's within 1e-9 mm).
    prefix = tmp_path / "scp"
    assert main(["synth", str(SLIDER_PATH), "--out", str(prefix)]) == 0
    best = json.loads((tmp_path / "scp.json").read_text())["linkages"][0]
    assert best["topology"] == "slider-crank" and max(best["errors_mm"]) < 1e-3
    assert max(abs(a - b) for a, b in zip(best["errors_mm"], best["engine_errors_mm"])) < 1e-9
    assert main(["solve", best["files"][1]]) == 0


INVERTED_PATH = ROOT / "models" / "synthesis" / "inverted_slider_crank_path.toml"
INVERTED_FUNCTION = ROOT / "models" / "synthesis" / "inverted_slider_crank_function.toml"
SLIDER_MOTION = ROOT / "models" / "synthesis" / "slider_crank_motion.toml"
INVERTED_MOTION = ROOT / "models" / "synthesis" / "inverted_slider_crank_motion.toml"


@pytest.mark.parametrize("example, old, new, key", [
    (INVERTED_PATH, 'topology = "inverted-slider-crank"', 'topology = "inverted slider-crank"', "topology"),
    (INVERTED_PATH, 'offset = ["-60 mm", "60 mm"]', 'offset = ["60 mm", "-60 mm"]', "bounds.offset"),
    (INVERTED_PATH, 'offset = ["-60 mm", "60 mm"]', 'offset = ["-60 deg", "60 deg"]', "bounds.offset"),
    (INVERTED_PATH, 'offset = ["-60 mm", "60 mm"]', 'rod = ["40 mm", "60 mm"]', "bounds.rod"),
    (INVERTED_PATH, 'crank = ["20 mm", "150 mm"]', 'crank = ["-20 mm", "150 mm"]', "bounds.crank"),
    (INVERTED_PATH, 'O4 = { x = ["0 mm", "120 mm"]', 'O4 = { x = ["0 mm"]', "bounds.O4.x"),
    (INVERTED_PATH, 'task = "path"', 'task = "motion"', "targets"),  # a motion takes poses
    (INVERTED_PATH, 'direction = "either"', 'grashof = "crank-rocker"', "constraints.grashof"),
    (INVERTED_PATH, '["-50.810 mm", "111.950 mm"]', '["-50.810 mm", "111.950 deg"]', "targets[0]"),
    (INVERTED_FUNCTION, 'ground = "50 mm"', 'ground = "0 mm"', "ground"),
    (INVERTED_FUNCTION, 'ground = "50 mm"', '', "ground"),
    (INVERTED_FUNCTION, '["32.4718 deg", "23.2180 deg"]', '["32.4718 deg", "23.2180 mm"]', "pairs[1]"),
    (INVERTED_FUNCTION, '["78.3938 deg", "54.1456 deg"]', '["12 deg", "54.1456 deg"]', "pairs"),
    (INVERTED_FUNCTION, 'crank = ["20 mm", "200 mm"]', 'crank = ["20 mm", "200 mm"]\nrocker = ["20 mm", "200 mm"]',
     "bounds.rocker"),
    (SLIDER_MOTION, '["82.064 mm", "59.353 mm", "25.564 deg"]', '["82.064 mm", "59.353 mm"]', "poses[1]"),
    (SLIDER_MOTION, '["82.064 mm", "59.353 mm", "25.564 deg"]', '["82.064 mm", "59.353 mm", "25.564 mm"]',
     "poses[1]"),
    (SLIDER_MOTION, 'keep = 2', 'keep = 2\ntargets = [["0 mm", "0 mm"]]', "targets"),
    (SLIDER_MOTION, 'rod = ["40 mm", "200 mm"]', 'rod = ["40 mm", "20 mm"]', "bounds.rod"),
    (INVERTED_MOTION, '["-112.408 mm", "60.027 mm", "193.082 deg"]', '["-112.408 mm", "60.027 mm"]', "poses[1]"),
    (INVERTED_MOTION, '["-112.408 mm", "60.027 mm", "193.082 deg"]', '["-112.408 mm", "60.027 mm", "193 mm"]',
     "poses[1]"),
    (INVERTED_MOTION, 'keep = 2', 'keep = 2\ntiming = ["0 deg", "1 deg", "2 deg", "3 deg", "4 deg", "5 deg"]',
     "timing"),  # a path's
    (INVERTED_MOTION, 'keep = 2', 'keep = 2\nlink = "block"', "link"),  # a six-bar's
    (INVERTED_MOTION, 'offset = ["-60 mm", "60 mm"]', 'offset = ["60 mm", "-60 mm"]', "bounds.offset"),
    (INVERTED_MOTION, 'point = { along', 'rod = ["1 mm", "2 mm"]\npoint = { along', "bounds.rod"),
])
def test_a_bad_inverted_or_slider_motion_file_is_one_line_naming_file_and_key(tmp_path, capsys, example, old, new,
                                                                                key):
    _refused_naming_file_and_key(_edited(tmp_path, old, new, example), key, capsys)


def test_the_inverted_function_example_writes_a_linkage_the_engine_reproduces(tmp_path, capsys):
    # The bundled inverted slider-crank function example (four Chebyshev pairs, the guide's
    # turns rounded to 1e-4 deg, of the bundled R-RTR): four pairs, four unknowns, met to
    # rounding (1e-9 deg); the engine sweeping the written scene turns the guide as the
    # report says (within 1e-9 deg: its Newton tolerance).
    prefix = tmp_path / "isf"
    assert main(["synth", str(INVERTED_FUNCTION), "--out", str(prefix), "--plot"]) == 0
    best = json.loads((tmp_path / "isf.json").read_text())["linkages"][0]
    assert best["topology"] == "inverted-slider-crank" and max(best["errors_deg"]) < 1e-9
    assert max(abs(a - b) for a, b in zip(best["errors_deg"], best["engine_errors_deg"])) < 1e-9
    assert abs(best["dimensions_mm"]["crank"] - 100.0) < 0.05  # the bundled crank, within the pairs' rounding
    assert main(["solve", best["files"][1]]) == 0
