"""Process capability (design/study/capability.py) against its definitions and published
values: Cp = (USL - LSL) / 6s and Cpk = min(USL - mean, mean - LSL) / 3s on a seeded
normal sample, computed here by hand; the normal's parts per million outside +-3 sigma
(2699.796 ppm, 2 (1 - Phi(3))) and outside +-6 sigma with the mean shifted 1.5 sigma (the
"six sigma" 3.4 ppm); a `[spec]` naming what the study lacks is refused by name."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pinmech.design.study.capability import capability, limits, ppm_normal
from pinmech.exceptions import SceneError, UnitError


def test_cp_and_cpk_are_their_definitions_on_a_normal_sample():
    rng = np.random.default_rng(11)
    x = 0.02 + 0.1 * rng.standard_normal((5000, 1))
    lo, hi = -0.3, 0.25
    mean = sum(float(v) for v in x[:, 0]) / len(x)
    s = math.sqrt(sum((float(v) - mean) ** 2 for v in x[:, 0]) / (len(x) - 1))
    c = capability(x, lo, hi)
    np.testing.assert_allclose(c.cp[0], (hi - lo) / (6 * s), rtol=1e-12)  # sums of 5000 terms: 1e-12 relative
    np.testing.assert_allclose(c.cpk[0], min(hi - mean, mean - lo) / (3 * s), rtol=1e-12)
    counted = np.mean((x[:, 0] < lo) | (x[:, 0] > hi)) * 1e6
    assert c.ppm_observed == counted
    np.testing.assert_allclose(c.ppm[0], ppm_normal(mean, s, lo, hi), rtol=1e-12)


def test_parts_per_million_are_the_published_normal_tails():
    """2 (1 - Phi(3)) = 0.0026997960632601866 (to 4e-6 ppm in 1e6 x); 3.4 ppm at 6 sigma
    limits with a 1.5 sigma shift (3.397673 ppm: Phi(-4.5) and Phi(-7.5))."""
    np.testing.assert_allclose(ppm_normal(0.0, 1.0, -3.0, 3.0), 2699.7960632601866, rtol=1e-12)
    np.testing.assert_allclose(ppm_normal(1.5, 1.0, -6.0, 6.0), 3.397673, rtol=2e-7)  # to its 7 figures


def test_a_spec_is_read_in_its_output_s_quantity_and_checked():
    names, kinds = ["P.x", "rocker.angle"], ["length", "angle"]
    got = limits((("P.x", "0.3 mm"), ("rocker.angle", (("lower", "-0.5 deg"), ("upper", "1 deg")))), names, kinds,
                 "s.toml")
    assert got["P.x"] == (-0.0003, 0.0003)
    np.testing.assert_allclose(got["rocker.angle"], (math.radians(-0.5), math.radians(1.0)), rtol=1e-15)
    with pytest.raises(SceneError, match=r"'Q.x' is not an output of this study \(outputs: P.x, rocker.angle\)"):
        limits((("Q.x", "1 mm"),), names, kinds, "s.toml")
    with pytest.raises(SceneError, match="lower below upper"):
        limits((("P.x", (("lower", "1 mm"), ("upper", "0 mm"))),), names, kinds, "s.toml")
    with pytest.raises(UnitError):
        limits((("P.x", "1 deg"),), names, kinds, "s.toml")
