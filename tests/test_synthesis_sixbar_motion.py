"""Six-bar motion generation on the engine (design/synthesis/sixbar.py, task = "motion"):
a link of the Watt's last dyad carried through poses, the bundled file's poses, and every
bad key of a six-bar motion file.

Reference: the Watt's positions in closed form, written here with numpy apart from
pinmech (tests/test_synthesis_sixbar.py's successive circle intersections by the law of
cosines: B from A and O4, C on the rocker from O4 and B, D from C and O6, P from C and D),
and link5's angle atan2(D - C) (its x axis, from its first joint to the next). The
linkages found are also swept again by the engine from their written files."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pinmech.design.synthesis.file import load_synthesis, parse_synthesis
from pinmech.design.synthesis.search import synthesise
from pinmech.design.synthesis.sixbar_output import engine_check, write_linkage
from pinmech.exceptions import SceneError
from tests.test_synthesis_sixbar import WATT, watt_pose
from tests.tolerance import rounding

ROOT = Path(__file__).resolve().parents[1]
SYNTHESIS = ROOT / "models" / "synthesis"
GAMMA = math.radians(25.0)  # the part's line from link5's C -> D (the bundled file's)


def _turn(a: np.ndarray) -> np.ndarray:
    return np.abs(np.mod(a + math.pi, 2 * math.pi) - math.pi)


def test_recovers_the_bundled_watt_carrying_link5_through_eight_poses(tmp_path):
    # Eight poses of link5 (P's place and the part's angle, 25 deg from C -> D) at crank
    # angles 60..270 deg, from the closed form at full precision, with their timing; the
    # four params of the last dyad and P hidden in a box of +-3 mm about them (the first
    # loop and O6 as drawn), the part's angle and the crank's start searched too. The
    # linkage found meets the closed form's places within 1e-8 of its size (190 mm) and
    # its angles within 1e-8 rad (the objective weighs an angle error e as a place error S
    # e, S the poses' extent ~35 mm: met to 1e-8 of the size, e < 1e-7 at worst; the
    # refinement takes both to rounding, ~1e-15); its params are the hidden ones (1e-6 m),
    # the part's line 25 deg from C -> D (1e-6 rad); its written scene swept by the engine
    # meets the poses within 1e-8 of its size and 1e-8 rad. About 9 s here (DE stops once
    # a refined candidate meets the poses within 1e-10).
    theta = np.radians(60.0 + 30.0 * np.arange(8))
    places, phi = watt_pose(theta, **WATT)
    raw = {"task": "motion", "topology": "watt", "scene": "../scenes/watt_params.toml", "point": "P",
           "link": "link5", "seed": 1, "population": 6, "generations": 30, "keep": 1,
           "poses": [[f"{float(x)!r} m", f"{float(y)!r} m", f"{float(a + GAMMA)!r} rad"]
                     for (x, y), a in zip(places, phi)],
           "timing": [f"{float(t)!r} rad" for t in theta - theta[0]],
           "bounds": {k: [f"{v - 0.003!r} m", f"{v + 0.003!r} m"] for k, v in WATT.items()},
           "constraints": {"transmission": "20 deg", "pins": ["B", "D"]}}
    spec = parse_synthesis(raw, SYNTHESIS / "inline.toml")
    best = synthesise(spec).linkages[0]
    assert best.task == "motion" and best.meets(1e-8)
    np.testing.assert_allclose(best.z, list(WATT.values()), atol=1e-6)
    assert abs(best.phi0 - GAMMA) <= 1e-6
    found, found_phi = watt_pose(best.theta, *best.z)
    assert np.max(np.linalg.norm(found - places, axis=1)) <= 1e-8 * best.size
    assert np.max(_turn(found_phi + best.phi0 - spec.angles)) <= 1e-8
    _, scene = write_linkage(spec, best, tmp_path / "watt_motion")
    errors, angle_errors = engine_check(spec, scene, best)
    assert np.max(errors) <= 1e-8 * best.size and np.max(angle_errors) <= 1e-8


def test_the_bundled_watt_motion_file_holds_poses_of_the_closed_form():
    # models/synthesis/watt_motion.toml: its eight poses are watt.toml's (link5 90, link6
    # 70, CP 50, DP 60 mm) at crank 60..270 deg with the part 25 deg from C -> D, within
    # their rounding (0.5 um and 0.5e-6 deg), and its timing those crank turns.
    spec = load_synthesis(SYNTHESIS / "watt_motion.toml")
    theta = np.radians(60.0) + spec.timing
    places, phi = watt_pose(theta, **WATT)
    assert np.max(np.abs(places - spec.targets)) <= 0.5e-9 + rounding(0.2)
    assert np.max(_turn(phi + GAMMA - spec.angles)) <= math.radians(0.5e-6) + rounding(math.pi)
    assert spec.output == "link5" and spec.point == "P"


_POSES = [["153 mm", "77 mm", "77 deg"], ["156 mm", "89 mm", "63 deg"], ["149 mm", "98 mm", "56 deg"]]


@pytest.mark.parametrize("change, key", [
    ({"link": "link9"}, "link"),  # no such link
    ({"link": "link6"}, "link"),  # a link that does not carry P
    ({"link": None}, "link"),  # missing
    ({"output": "link6"}, "output"),  # a function's key
    ({"ground": "100 mm"}, "ground"),
    ({"targets": [["1 mm", "2 mm"]] * 3}, "targets"),  # a path's key
    ({"poses": [["153 mm", "77 mm"]] * 3}, "poses[0]"),  # no angle
    ({"poses": _POSES[:2]}, "poses"),  # fewer than 3
    ({"timing": ["0 deg", "30 deg"]}, "timing"),  # one a pose
    ({"timing": ["0 deg", "30 deg", "20 deg"]}, "timing"),  # not one way
    ({"point": "Q"}, "point"),
])
def test_every_bad_key_of_a_six_bar_motion_file_is_named(change, key):
    # One line naming the file and the key, whatever is wrong.
    raw = {"task": "motion", "topology": "watt", "scene": "../scenes/watt_params.toml", "link": "link5",
           "poses": _POSES, "bounds": {"link5": ["80 mm", "100 mm"]}, **change}
    raw = {k: v for k, v in raw.items() if v is not None}
    with pytest.raises(SceneError) as err:
        parse_synthesis(raw, SYNTHESIS / "inline.toml")
    assert key in str(err.value) and "inline.toml" in str(err.value) and "\n" not in str(err.value)
