"""The closed forms in scripts/closed_form.py against themselves and against the textbooks.

Self-consistency: every velocity is the central finite difference in time of the matching
position, every acceleration that of the velocity, along a motion with constant driver
acceleration. Textbook: the printed values of Problem Chapter I.9 (R-RTR) and of text
problem 17.110 (3R arm), each at half a unit of its last printed digit.
"""

from __future__ import annotations

import sys
from pathlib import Path
from tests.tolerance import rounding

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))

import closed_form as cf
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

# Central difference step and tolerance, chosen together. The truncation error of
# (x(h) - x(-h)) / 2h is h^2/6 |x'''|. A motion of angular rate w has |x'''| ~ w^2 |x'|, and
# the fastest rates below reach w ~ 20 rad/s (link 3 of the R-RTR near its short dead
# centre), so with h = 1e-5 s the error is ~ 1e-10 / 6 * 400 ~ 7e-9 relative to the scale of
# x'. Round-off adds eps |x| / (2h |x'|) ~ 2e-16 / (2e-5 * 5) ~ 2e-12. Measured worst case:
# 7.4e-9. So rtol = 1e-7 with atol = 1e-7 times the largest |x'| over the cycle (components
# cross zero) holds with a margin of ten, while a wrong sign, factor or missing term (an
# error of 1e-2 relative or more) fails by five orders of magnitude.
H = 1e-5
FD_TOL = 1e-7
ANGLES = {"phi3", "theta3", "theta4", "beta"}
CYCLE = np.linspace(0.0, 2.0 * np.pi, 360, endpoint=False) + 0.013  # avoids exact zeros


def driver(t: float, theta0, omega: float, alpha: float):
    """Driver angle [rad] and velocity [rad/s] at time t [s] under constant alpha."""
    return theta0 + omega * t + 0.5 * alpha * t**2, omega + alpha * t


def check_derivative(x_minus, x_plus, dx, angle: bool = False, label: str = "") -> None:
    """Assert (x_plus - x_minus) / 2H equals dx at FD_TOL (see the comment on H).

    An angle difference is wrapped into [-pi, pi) first (atan2 jumps at +-pi).
    """
    dx = np.asarray(dx)
    step = np.asarray(x_plus) - np.asarray(x_minus)
    if angle:
        step = (step + np.pi) % (2 * np.pi) - np.pi
    np.testing.assert_allclose(step / (2 * H), dx, rtol=FD_TOL,
                               atol=FD_TOL * np.max(np.abs(dx)), err_msg=label)


def check_motion(solve, theta0, omega, alpha, pairs) -> None:
    """Finite-difference each (position, velocity) field-name pair of solve(theta, omega)."""
    mid = solve(*driver(0.0, theta0, omega, alpha))
    lo = solve(*driver(-H, theta0, omega, alpha))
    hi = solve(*driver(H, theta0, omega, alpha))
    for pos, vel in pairs:
        check_derivative(getattr(lo, pos), getattr(hi, pos), getattr(mid, vel),
                         angle=pos in ANGLES, label=f"d({pos})/dt vs {vel}")


def assert_printed(actual, printed: str) -> None:
    """Assert actual equals a printed number to half a unit of its last printed digit."""
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    np.testing.assert_allclose(actual, float(printed), rtol=0, atol=0.5 * 10.0**-decimals,
                               err_msg=f"printed {printed}")


# ----------------------------------------------------------------------------- R-RTR

RRTR_PAIRS = [("B", "vB"), ("vB", "aB"), ("D", "vD"), ("vD", "aD"), ("phi3", "omega3"),
              ("omega3", "alpha3"), ("s", "s_dot"), ("s_dot", "s_ddot")]

# Problem Chapter I.9, Mathematica output at phi = 30 deg, omega1 = -50 rpm, alpha1 = 0.
RRTR_PRINTED = {
    "B": ("0.0866025", "0.05"), "phi3": "0.938882", "D": ("0.138604", "0.121035"),
    "vB": ("0.261799", "-0.45345"), "aB": ("-2.37426", "-1.37078"), "omega3": "-7.7316",
    "v_rel": ("0.124781", "0.170454"), "vB3": ("0.38658", "-0.282996"),
    "vD": ("0.935792", "-0.685048"), "coriolis": ("2.63576", "-1.92951"),
    "alpha3": "-34.8653", "a_rel": ("-0.706249", "-0.964755"),
    "aB3": ("-0.444749", "-4.26504"), "aD": ("-1.0766", "-10.3244"),
}


@pytest.fixture(scope="module")
def textbook_r_rtr() -> cf.RRTR:
    return cf.r_rtr(np.radians(30.0), -50.0 * np.pi / 30.0, 0.0)


@pytest.mark.parametrize("name", sorted(RRTR_PRINTED))
def test_r_rtr_printed_values(textbook_r_rtr, name):
    printed = RRTR_PRINTED[name]
    actual = np.atleast_1d(getattr(textbook_r_rtr, name))
    texts = (printed,) if isinstance(printed, str) else printed
    for value, text in zip(actual, texts, strict=True):
        assert_printed(value, text)


def test_r_rtr_printed_scalars(textbook_r_rtr):
    r = textbook_r_rtr
    assert_printed(np.degrees(r.phi3), "53.794")
    assert_printed(-r.s_dot, "0.211245")  # v32
    assert_printed(-r.s_ddot, "-1.19563")  # a32


@pytest.mark.parametrize("branch", [1, -1])
@pytest.mark.parametrize("alpha1", [0.0, 7.0])
def test_r_rtr_finite_differences(branch, alpha1):
    solve = lambda phi, w: cf.r_rtr(phi, w, alpha1, branch=branch)
    check_motion(solve, CYCLE, -50.0 * np.pi / 30.0, alpha1, RRTR_PAIRS)


@pytest.mark.parametrize("branch", [1, -1])
def test_r_rtr_relative_motion_identities(branch):
    r = cf.r_rtr(CYCLE, 4.0, -3.0, branch=branch)
    scale = np.max(np.abs(r.aB3))
    np.testing.assert_allclose(r.aB3, r.aB + r.a_rel + r.coriolis, rtol=0, atol=rounding(scale))
    np.testing.assert_allclose(r.v_rel, r.vB3 - r.vB, rtol=0, atol=rounding(np.abs(r.vB3).max()))
    np.testing.assert_allclose(r.B - [0.05, 0.0], r.s[:, None] * r.u, rtol=0, atol=rounding(np.abs(r.B).max()))
    np.testing.assert_allclose(np.linalg.norm(r.D - [0.05, 0.0], axis=-1), 0.15, rtol=rounding(1.0))
    assert np.all(branch * r.s > 0)


def test_r_rtr_full_cycle_is_one_call():
    phi = np.linspace(0.0, 2.0 * np.pi, 3600, endpoint=False) + 1e-3
    r = cf.r_rtr(phi, -50.0 * np.pi / 30.0, 0.0)
    assert r.D.shape == (3600, 2) and r.alpha3.shape == (3600,)
    assert np.all(np.isfinite(r.aD))


def test_r_rtr_singular_when_b_on_c():
    assert not cf.r_rtr_closes(0.05, 0.05, 0.0)
    with pytest.raises(ValueError, match="B lies on C"):
        cf.r_rtr([0.3, 0.0], 1.0, 0.0, AB=0.05, AC=0.05)


# -------------------------------------------------------------------------- four-bar

FOUR_BAR_PAIRS = [("A", "vA"), ("vA", "aA"), ("B", "vB"), ("vB", "aB"),
                  ("theta3", "omega3"), ("omega3", "alpha3"),
                  ("theta4", "omega4"), ("omega4", "alpha4")]
GRASHOF = {"a": 0.04, "b": 0.12, "c": 0.08, "d": 0.10}  # crank-rocker, Grashof


@pytest.mark.parametrize("branch", [1, -1])
def test_four_bar_closes_on_its_branch(branch):
    fb = cf.four_bar(CYCLE, 5.0, 2.0, **GRASHOF, branch=branch)
    np.testing.assert_allclose(np.linalg.norm(fb.B - fb.A, axis=-1), GRASHOF["b"], rtol=rounding(1.0))
    np.testing.assert_allclose(np.linalg.norm(fb.B - [GRASHOF["d"], 0.0], axis=-1),
                               GRASHOF["c"], rtol=rounding(1.0))
    w, v = [GRASHOF["d"], 0.0] - fb.A, fb.B - fb.A
    assert np.all(branch * (w[:, 0] * v[:, 1] - w[:, 1] * v[:, 0]) > 0)


@pytest.mark.parametrize("branch", [1, -1])
def test_four_bar_finite_differences(branch):
    solve = lambda th, w: cf.four_bar(th, w, 3.0, **GRASHOF, branch=branch)
    check_motion(solve, CYCLE, 5.0, 3.0, FOUR_BAR_PAIRS)


@settings(max_examples=40, deadline=None)
@given(theta2=st.floats(0.0, 2 * np.pi), lengths=st.tuples(*[st.floats(0.5, 2.0)] * 3),
       branch=st.sampled_from([1, -1]))
def test_four_bar_velocity_of_b_agrees_both_ways(theta2, lengths, branch):
    """vB through the coupler (vA + omega3 k x AB) equals vB through the rocker."""
    b, c, d = lengths
    a = 0.2 * min(lengths)  # a short crank keeps every pose assembled and off toggle
    assume(abs(b - c) + a + 0.1 < d < b + c - a - 0.1)  # keeps off toggle by a margin
    fb = cf.four_bar(theta2, 1.3, -0.7, a, b, c, d, branch)
    np.testing.assert_allclose(fb.vA + fb.omega3 * cf.perp(fb.B - fb.A), fb.vB, atol=rounding(np.abs(fb.vB).max()))
    via_coupler = fb.aA + fb.alpha3 * cf.perp(fb.B - fb.A) - fb.omega3**2 * (fb.B - fb.A)
    np.testing.assert_allclose(via_coupler, fb.aB, atol=1e-11)


def test_four_bar_cannot_close():
    with pytest.raises(ValueError, match="cannot close"):
        cf.four_bar([0.0, np.pi], 1.0, 0.0, a=1.0, b=1.0, c=1.0, d=5.0)


# ---------------------------------------------------------------------- slider-crank

SLIDER_PAIRS = [("x_B", "v_B"), ("v_B", "a_B"), ("beta", "omega_rod"),
                ("omega_rod", "alpha_rod")]


@pytest.mark.parametrize("branch", [1, -1])
@pytest.mark.parametrize("e", [0.0, 0.02])
def test_slider_crank_finite_differences_and_closure(branch, e):
    solve = lambda th, w: cf.slider_crank(th, w, -4.0, 0.05, 0.15, e, branch)
    check_motion(solve, CYCLE, 6.0, -4.0, SLIDER_PAIRS)
    sc = solve(CYCLE, 6.0)
    np.testing.assert_allclose(np.linalg.norm(sc.B - sc.A, axis=-1), 0.15, rtol=rounding(1.0))
    np.testing.assert_allclose(sc.B[:, 1], e)
    assert np.all(branch * (sc.x_B - sc.A[:, 0]) > 0)


def test_slider_crank_cannot_close():
    with pytest.raises(ValueError, match="cannot close"):
        cf.slider_crank(np.pi / 2, 1.0, 0.0, r=0.1, l=0.05, e=-0.1)


# ---------------------------------------------------------------------------- 3R arm

R_ARM = (0.3, 0.3, 0.17)


@pytest.fixture(scope="module")
def textbook_arm() -> cf.ArmRates:
    return cf.planar_arm_rates(np.radians(50.0), np.radians(-15.0), np.radians(-90.0),
                               *R_ARM, vD=[1.0, 0.0], aD=[0.0, 0.0])


def test_arm_printed_values(textbook_arm):
    """Text 17.110 prints 2 significant figures; all four agree at that precision."""
    assert_printed(textbook_arm.omega_AB, "-3.6")
    assert_printed(textbook_arm.omega_BC, "2.4")
    assert_printed(textbook_arm.alpha_AB, "-12.1")
    assert_printed(textbook_arm.alpha_BC, "16.5")  # the text's theta2_ddot = -16.5


def test_arm_rates_reproduce_the_prescribed_motion(textbook_arm):
    q = np.radians([50.0, -65.0, -75.0])
    state = cf.planar_arm_forward(q, textbook_arm.q_dot, textbook_arm.q_ddot, *R_ARM)
    np.testing.assert_allclose(state.vD, [1.0, 0.0], rtol=0, atol=rounding(1.0))
    np.testing.assert_allclose(state.aD, [0.0, 0.0], rtol=0, atol=rounding(1.0))
    np.testing.assert_allclose(state.D, textbook_arm.D, rtol=0, atol=rounding(np.abs(textbook_arm.D).max()))
    assert textbook_arm.omega_CD == 0.0 and textbook_arm.alpha_CD == 0.0


def test_arm_rates_with_rotating_hand():
    th = np.radians([[30.0, 100.0, 200.0], [-20.0, 45.0, 10.0]])
    rates = cf.planar_arm_rates(*th.T, *R_ARM, vD=[[0.3, -0.2]], aD=[[1.0, 2.0]],
                                omega_CD=1.5, alpha_CD=-2.5)
    q = np.diff(th, axis=-1, prepend=0.0)
    state = cf.planar_arm_forward(q, rates.q_dot, rates.q_ddot, *R_ARM)
    np.testing.assert_allclose(state.vD, [[0.3, -0.2]] * 2, rtol=0, atol=rounding(1.0))
    np.testing.assert_allclose(state.aD, [[1.0, 2.0]] * 2, rtol=0, atol=rounding(10.0))


def test_arm_forward_finite_differences():
    rng = np.random.default_rng(17110)
    q0, qd, qdd = rng.uniform(-np.pi, np.pi, (64, 3)), rng.uniform(-4, 4, (64, 3)), \
        rng.uniform(-10, 10, (64, 3))
    states = [cf.planar_arm_forward(q0 + qd * t + 0.5 * qdd * t**2, qd + qdd * t, qdd, *R_ARM)
              for t in (-H, 0.0, H)]
    for pos, vel in [("B", "vB"), ("C", "vC"), ("D", "vD"), ("vB", "aB"), ("vC", "aC"),
                     ("vD", "aD")]:
        check_derivative(getattr(states[0], pos), getattr(states[2], pos),
                         getattr(states[1], vel), label=f"d({pos})/dt vs {vel}")


def test_arm_singular_when_stretched():
    with pytest.raises(ValueError, match="det"):
        cf.planar_arm_rates(0.4, 0.4, -1.0, *R_ARM, vD=[1.0, 0.0], aD=[0.0, 0.0])
