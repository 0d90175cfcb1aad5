"""A tolerance study's stack-up (design/study/stackup.py) against the textbook: the worst
case sum |S_i| t_i and the RSS sqrt(sum (S_i t_i)^2) of the rocker angle of the bundled
four-bar, with S_i = d(theta4)/dp_i from central differences of Norton's closed form (the
law of cosines, scripts/closed_form.py); the shares (S_i sigma_i)^2 / sigma^2 add to 1."""

from __future__ import annotations

from pathlib import Path

import closed_form
import numpy as np

from pinmech.design.study.file import load_study
from pinmech.design.study.run import study
from pinmech.design.study.stackup import covariances, ellipse, point_pairs, stackup
from pinmech.design.study.tolerance_report import tolerance_lines

STUDIES = Path(__file__).resolve().parents[1] / "models" / "studies"


def _small(tmp_path: Path) -> Path:
    text = (STUDIES / "four_bar_tolerance.toml").read_text().replace("samples = 2000", "samples = 60")
    text = text.replace("steps = 73", "steps = 25").replace('"../scenes/', f'"{STUDIES.parent}/scenes/')
    (tmp_path / "small.toml").write_text(text)
    return tmp_path / "small.toml"


def test_worst_case_and_rss_of_the_rocker_are_the_closed_form_stackups(tmp_path):
    """Tolerances t = (0.1, 0.15, 0.1, 0.1) mm for (crank, ground, coupler, rocker): the
    crank's, rocker's at 3 sigma, the ground's 3 x 0.05 mm, the coupler's uniform half
    width. S_i from the closed form at h = 1e-7 m (error ~1e-9 rad/m, as
    tests/test_sensitivity.py); times t ~ 1e-4 m: tolerance 1e-11 rad."""
    result = study(_small(tmp_path))
    st = stackup(result)
    np.testing.assert_allclose(st.tolerance, [1e-4, 1.5e-4, 1e-4, 1e-4], rtol=1e-15)
    theta2, h = result.values, 1e-7
    nominal = np.array([0.04, 0.10, 0.12, 0.08])  # a, d, b, c in the study's order

    def theta4(a, d, b, c):
        return np.unwrap(closed_form.four_bar(theta2, 0.0, 0.0, a, b, c, d, +1).theta4)

    S = np.column_stack([(theta4(*(nominal + h * e)) - theta4(*(nominal - h * e))) / (2 * h) for e in np.eye(4)])
    j = result.outputs.index("rocker.angle")
    np.testing.assert_allclose(st.worst[:, j], np.abs(S) @ st.tolerance, rtol=0, atol=1e-11)
    np.testing.assert_allclose(st.rss[:, j], np.sqrt(((S * st.tolerance) ** 2).sum(axis=1)), rtol=0, atol=1e-11)
    sigma = np.array([1e-4 / 3, 5e-5, 1e-4 / np.sqrt(3), 1e-4 / 3])
    np.testing.assert_allclose(st.sigma_linear[:, j], np.sqrt(((S * sigma) ** 2).sum(axis=1)), rtol=0, atol=1e-11)
    np.testing.assert_allclose(st.contribution.sum(axis=-1), 1.0, rtol=0, atol=1e-12)
    assert st.solved == st.samples == 60


def test_a_point_s_linear_covariance_is_s_sigma_s_transposed(tmp_path):
    """P's covariance at each pose: S diag(sigma^2) S^T, its diagonal sigma_linear^2 of P.x
    and P.y; the 3-sigma ellipse of a diagonal covariance has half axes 3 sigma."""
    result = study(_small(tmp_path))
    (name, ix, iy), = point_pairs(result.outputs)
    linear, mc = covariances(result, ix, iy)
    st = stackup(result)
    np.testing.assert_allclose(linear[:, 0, 0], st.sigma_linear[:, ix] ** 2, rtol=1e-12)
    np.testing.assert_allclose(linear[:, 1, 1], st.sigma_linear[:, iy] ** 2, rtol=1e-12)
    np.testing.assert_allclose(mc[:, 0, 0], st.sigma[:, ix] ** 2, rtol=1e-12)
    e = ellipse(np.diag([4.0, 1.0]))
    np.testing.assert_allclose(np.abs(e).max(axis=0), [6.0, 3.0], rtol=1e-3)  # 73 points on the ellipse


def test_sigma_is_said_over_the_survivors_and_how_many():
    s = {"sigma_over": {"solved": 7, "samples": 10, "failed": 3}, "stackup": {}, "capability": {}}
    assert "over the 7 of 10 variants that solved, 3 failed" in tolerance_lines(s, "O2")[0]


def test_the_bundled_drawn_tolerance_study_reads_its_spec():
    spec = load_study(STUDIES / "four_bar_drawn_tolerance.toml")
    assert dict(spec.limits)["P.x"] == "0.25 mm"
