"""What `pinmech synth` writes and reads back: the drawn linkage at its refined values, the
scene's crank angles in the one convention (the first in [0, 360) deg, the sweep on from it
the way the crank turns), swept by the engine through the targets even where the motion
crosses 0/360 or 180 deg; what "meets the targets" means; and a failed engine check
reported with its linkage, never in place of the listing.

The linkages are triple rockers (crank 40, coupler 35, rocker 50, ground 30 mm: 40 + 50 >
35 + 30, no link turns fully), whose crank rocks through 0 deg (O4 at x = -30 mm) or
through 180 deg (O4 at x = +30 mm): a whole turn of motion would stop at a fold. Their
coupler point at each crank angle is the closed form (fourbar.pose, law-of-cosines tested
in test_synthesis_path.py), the targets the synthesis "found".
"""

from __future__ import annotations

import json
import math
import tomllib
from collections import Counter

import numpy as np
import pytest

from pinmech.cli import main
from pinmech.design.synthesis.fourbar import pose
from pinmech.design.synthesis.linkage import engine_check, write_linkage
from pinmech.design.synthesis.result import MET, Linkage, SynthesisResult

#: The engine's P against the closed form's: Newton closes to 1e-13 of the loop's size
#: (~0.1 m, so 1e-14 m) at each pose, and the written drawing is the float to the last bit;
#: 1e-11 m leaves a factor 1000 for the conditioning of these well-shaped poses.
ENGINE_TOL = 1e-11


def _rocker(O4x: float, theta_deg: list[float], way: int) -> Linkage:
    z = np.array([0.0, 0.0, O4x, 0.0, 0.040, 0.035, 0.050, 0.020, 0.010])
    theta = np.radians(theta_deg)
    return Linkage(z, 1.0, theta, way, np.zeros(len(theta)), (1.0, 2.0), "triple rocker")


def _P(lk: Linkage, theta: np.ndarray) -> np.ndarray:
    return pose(lk.z[None], np.array([lk.s]), np.asarray(theta)[None]).P[0]


CASES = {  # crank angles at the targets [deg] as the search may hold them (atan2's or wrapped), and the way
    "ccw through 0, held in (-180, 180]": (-0.030, [-10.69, -5.0, 0.0, 5.0, 17.12], 1),
    "ccw through 0, held in [0, 360)": (-0.030, [349.31, 355.0, 0.0, 5.0, 17.12], 1),
    "cw through 0": (-0.030, [17.12, 5.0, 0.0, 355.0, 349.31], -1),
    "cw through 180, held in (-180, 180]": (0.030, [-170.0, -175.0, 180.0, 175.0, 160.0], -1),
    "ccw through 180, held in [0, 360)": (0.030, [160.0, 175.0, 180.0, 185.0, 190.0], 1),
}


@pytest.mark.parametrize("case", CASES)
def test_the_written_scene_sweeps_the_engine_through_the_targets_across_the_wrap(tmp_path, case):
    O4x, theta, way = CASES[case]
    lk = _rocker(O4x, theta, way)
    targets = _P(lk, lk.theta)
    linkage, scene = write_linkage(lk, tmp_path / "found", "found", "test.toml")
    written = tomllib.loads(scene.read_text())
    start, stop = (float(written["sweep"][k].split()[0]) for k in ("from", "to"))
    assert 0.0 <= start < 360.0
    assert float(written["drivers"]["O2"]["angle"].split()[0]) == start
    assert math.copysign(1, stop - start) == way  # the direction of travel, from the sign of to - from
    travel = way * np.mod(way * (theta[-1] - theta[0]), 360.0)
    assert stop - start == pytest.approx(travel, abs=1e-9)
    check = engine_check(scene, lk, targets)
    assert check.errors.max() <= ENGINE_TOL and check.drift <= ENGINE_TOL


def test_the_drawing_carries_the_refined_values_to_the_last_bit(tmp_path):
    """The written [params] are the search's numbers to the last bit (mm and back: one
    rounding each way, an ulp of the size), and the drawing they make puts P where the
    closed form does (the compass constructions' rounding: a few eps x size / sin of the
    circles' angle, well within 1e-15 m here)."""
    from pinmech.model.linkage import parse_linkage

    lk = _rocker(-0.030, [349.31, 355.0, 0.0], 1)
    linkage, _ = write_linkage(lk, tmp_path / "found", "found", "test.toml")
    params = tomllib.loads(linkage.read_text())["params"]
    for name, value in zip(("O2x", "O2y", "O4x", "O4y", "crank", "coupler", "rocker"), lk.z):
        assert abs(float(params[name].split()[0]) / 1e3 - value) <= np.spacing(0.05)
    drawn = parse_linkage(linkage).points
    assert np.max(np.abs(drawn["P"][:2] - _P(lk, lk.theta[:1])[0])) <= 1e-15


def test_the_written_four_bar_is_drawn_from_named_dimensions_a_user_can_edit(tmp_path):
    """Every dimension is a [params] entry the joints use: change the crank from 40 to 45 mm
    and A lies 45 mm from O2 at the same angle, B where the circles about the new A (the
    coupler) and O4 (the rocker) meet."""
    from pinmech.model.linkage import parse_linkage

    lk = _rocker(-0.030, [349.31, 355.0, 0.0], 1)
    linkage, _ = write_linkage(lk, tmp_path / "found", "found", "test.toml")
    text = linkage.read_text()
    assert tomllib.loads(text)["joints"]["A"] == {"from": "O2", "length": "crank", "angle": "349.31 deg"}
    linkage.write_text(text.replace('crank = "40.0 mm"', 'crank = "45.0 mm"'))
    A = parse_linkage(linkage).points["A"][:2]
    assert np.allclose(A, 0.045 * np.array([math.cos(math.radians(349.31)), math.sin(math.radians(349.31))]),
                       rtol=0, atol=1e-16)


def _synthesis_file(tmp_path, targets: np.ndarray):
    path = tmp_path / "line.toml"
    listed = ", ".join(f'["{float(x) * 1e3!r} mm", "{float(y) * 1e3!r} mm"]' for x, y in targets)
    path.write_text("""title = "a check that fails"
task = "path"
topology = "four-bar"
targets = [LISTED]
[bounds]
O2 = { x = ["-60 mm", "60 mm"], y = ["-60 mm", "60 mm"] }
O4 = { x = ["-60 mm", "60 mm"], y = ["-60 mm", "60 mm"] }
crank = ["5 mm", "60 mm"]
coupler = ["5 mm", "60 mm"]
rocker = ["5 mm", "60 mm"]
point = { along = ["-60 mm", "60 mm"], across = ["-60 mm", "60 mm"] }
""".replace("LISTED", listed))
    return path


def test_a_failed_engine_check_is_listed_with_its_linkage_and_the_others_are_kept(tmp_path, monkeypatch, capsys):
    """Linkage 2 asks the engine to turn the rocker's crank past its fold (at 18.57 deg:
    |A O4| = 50 - 35 there, by the law of cosines); linkage 1 is sound. Both are listed,
    both written, the JSON says which failed, and the exit code is the fold's (11)."""
    from pinmech.design.synthesis import search
    from pinmech.design.synthesis.file import load_synthesis

    good = _rocker(-0.030, [-10.0, 0.0, 10.0], 1)
    bad = _rocker(0.030, [160.0, 180.0, 350.0], 1)  # 350 deg lies past the fold at 341.43 deg
    path = _synthesis_file(tmp_path, _P(good, good.theta))
    spec = load_synthesis(path)
    monkeypatch.setattr(search, "synthesise", lambda *a, **k: SynthesisResult(spec, [good, bad], Counter(), 1, 1))
    code = main(["synth", str(path), "--out", str(tmp_path / "out")])
    out, err = capsys.readouterr()
    assert code == 11
    assert "linkage 1: " in out and "linkage 2: " in out
    assert "FAILED" in out.split("linkage 2: ")[-1]
    report = json.loads((tmp_path / "out.json").read_text())
    assert [lk["engine_check"].split(":")[0] for lk in report["linkages"]] == ["passed", "failed"]
    assert (tmp_path / "out_2.toml").is_file() and (tmp_path / "out_1_scene.toml").is_file()


def test_met_means_within_the_printed_share_of_the_size(tmp_path, monkeypatch, capsys):
    """The listing prints the tolerance behind "meets the targets" and applies it: errors of
    1e-5 mm on a 50 mm linkage (2e-7 of its size) are not met at MET = 1e-10, none are."""
    from pinmech.design.synthesis.report import text

    from pinmech.design.synthesis.file import load_synthesis

    lk = _rocker(-0.030, [-10.0, 0.0, 10.0], 1)
    spec = load_synthesis(_synthesis_file(tmp_path, _P(lk, lk.theta)))
    near = Linkage(lk.z, lk.s, lk.theta, lk.way, np.array([1e-8, 0.0, 0.0]), lk.transmission, lk.grashof)
    listing = text(SynthesisResult(spec, [near, lk], Counter(), 1, 1))
    assert f"within {MET:g} of its size" in listing
    first, second = listing.split("linkage 2:")
    assert "meets the targets" in first and first.split("meets the targets")[1].split("\n")[0].endswith(
        "no: the closest this search found (errors above)")
    assert second.split("meets the targets")[1].split("\n")[0].endswith(": yes")


def test_the_written_scene_carries_the_targets_and_the_paths_figure_draws_them(tmp_path, monkeypatch):
    """A path task's scene writes its targets (`[sweep] targets`, mm to 12 significant
    figures) and `pinmech sweep SCENE --paths` draws them as crosses numbered 1, 2, ... on P's
    path: read back, each cross is the closed form's P at its crank angle, to the 12 figures
    written (1e-9 of the 0.05 m size; the figure draws in mm)."""
    import matplotlib.pyplot as plt

    from pinmech.io.scene import Scene

    O4x, theta, way = CASES["ccw through 0, held in [0, 360)"]
    lk = _rocker(O4x, theta, way)
    assert lk.task == "path"
    targets = _P(lk, lk.theta)
    _, scene = write_linkage(lk, tmp_path / "found", "found", "test.toml", targets)
    read = np.array(Scene.load(scene).file.sweep.targets["P"])
    np.testing.assert_allclose(read, targets, rtol=0, atol=1e-9 * 0.05)
    kept = []
    monkeypatch.setattr(plt, "close", lambda fig=None: kept.append(fig))
    assert main(["sweep", str(scene), "--paths", str(tmp_path / "p.png")]) == 0
    ax = kept[0].axes[0]
    (crosses,) = [x for x in ax.get_lines() if x.get_gid() == "targets P"]
    np.testing.assert_allclose(np.asarray(crosses.get_xydata(), float), 1e3 * targets, rtol=0, atol=1e-9 * 50.0)
    numbers = sorted(int(t.get_text()) for t in ax.texts if t.get_gid() == "targets P")
    assert numbers == list(range(1, len(targets) + 1))


@pytest.mark.parametrize("places, said", [('[["1 mm"]]', "list of [x, y] places"), ('[["1 mm", "nan mm"]]', "finite"),
                                          ('[["1 mm", "2 deg"]]', "length"), ('"P"', "list of [x, y] places")])
def test_bad_targets_in_a_scene_are_named(tmp_path, capsys, places, said):
    """A scene's `[sweep] targets` that are not places: one line naming the file, the key
    and the value, no traceback."""
    from tests.conftest import SCENES

    text = (SCENES / "four_bar_drawn.toml").read_text(encoding="utf-8").replace("../", str(SCENES.parent) + "/")
    scene = tmp_path / "bad.toml"
    scene.write_text(text + f"\n[sweep]\ntargets = {{P = {places}}}\n", encoding="utf-8")
    assert main(["solve", str(scene)]) != 0
    err = capsys.readouterr().err
    assert "sweep.targets" in err and said in err and "Traceback" not in err
