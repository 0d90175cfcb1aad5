"""The design page's diagnostics, read from the poses its turn already swept: checked
against the closed forms of a crank-rocker four-bar (Norton, Design of Machinery, §4.10 and
§4.12) after its rocker pivot O4 is dragged off the crank's axis, so that every extreme
falls between the turn's 1-degree poses.

The bundled four-bar after the drag: O2 at the origin, O4 at (100, 10) mm (ground d =
|O2 O4|, along theta_d = atan2(10, 100)), crank a = 40, coupler b = 120, rocker c = 80 mm,
B to the left of A -> O4.
- least transmission angle: crank along the ground line (theta = theta_d), where
  cos mu = (b^2 + c^2 - (d - a)^2) / (2 b c);
- rocker extremes: crank and coupler in line, |O2 B| = a + b (extended) at
  theta = theta_d + acos(((a + b)^2 + d^2 - c^2) / (2 (a + b) d)), and |O2 B| = b - a
  (folded) at theta = pi + theta_d + acos(((b - a)^2 + d^2 - c^2) / (2 (b - a) d));
- time ratio Q = alpha / beta, the crank's two turns between them.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

pytest.importorskip("starlette")

from pinmech.draw.design_page.session import Session, read_design_file  # noqa: E402

FOUR_BAR = Path(__file__).resolve().parents[1] / "models" / "linkages" / "four_bar.toml"
A, B, C = 0.04, 0.12, 0.08
D, THETA_D = math.hypot(0.1, 0.01), math.atan2(0.01, 0.1)
#: The limits are polished by Newton on the engine's rate: to the solver's rounding, ~1e-12
#: rad; 1e-9 rad leaves room for the acos of the closed form near its ends (condition ~1e2).
LIMIT_TOL = 1e-9
#: The least angle's place: a flat minimum, located to ~sqrt(eps) (1e-8 rad); its value
#: to the second order of that (rounding, 1e-12 deg); 1e-9 deg for the acos.
LEAST_AT_TOL, LEAST_TOL = 1e-6, 1e-9


@pytest.fixture(scope="module")
def panel():
    spec, source, _, _ = read_design_file(FOUR_BAR)
    session = Session(spec, source)
    assert session.drag("O4", 0.1, 0.01)["ok"]
    return session.diagnostics()["diagnostics"], session


def _turn(x: float) -> float:
    return x % (2 * math.pi)


def test_least_transmission_angle_is_at_the_crank_along_the_ground_line(panel):
    found, _ = panel
    (dyad,) = found["dyads"]
    mu = math.degrees(math.acos((B**2 + C**2 - (D - A) ** 2) / (2 * B * C)))
    assert abs(dyad["least"] - mu) < LEAST_TOL
    assert abs(math.remainder(dyad["least_at"] - THETA_D, 2 * math.pi)) < LEAST_AT_TOL


def test_rocker_extremes_and_time_ratio_are_the_closed_forms(panel):
    found, _ = panel
    (rocker,) = found["outputs"]
    extended = THETA_D + math.acos(((A + B) ** 2 + D**2 - C**2) / (2 * (A + B) * D))
    folded = math.pi + THETA_D + math.acos(((B - A) ** 2 + D**2 - C**2) / (2 * (B - A) * D))
    by_toggle = {x["toggle"]: x["driver"] for x in rocker["limits"]}
    assert abs(math.remainder(by_toggle["extended"] - extended, 2 * math.pi)) < LIMIT_TOL
    assert abs(math.remainder(by_toggle["folded"] - folded, 2 * math.pi)) < LIMIT_TOL
    alpha = _turn(folded - extended)
    alpha = max(alpha, 2 * math.pi - alpha)
    assert abs(rocker["ratio"] - alpha / (2 * math.pi - alpha)) < 1e-8


def test_the_diagnostics_do_not_solve_the_turn_again(monkeypatch):
    from pinmech.solve.loops import LoopSolver

    spec, source, _, _ = read_design_file(FOUR_BAR)
    session = Session(spec, source)
    calls = {"rates": 0, "follow": 0}
    for name in calls:
        original = getattr(LoopSolver, name)

        def counted(self, *args, _original=original, _name=name, **kwargs):
            calls[_name] += 1
            return _original(self, *args, **kwargs)

        monkeypatch.setattr(LoopSolver, name, counted)
    assert session.diagnostics()["diagnostics"]["applicable"]
    # a few closing solves per extreme (2 limits, 2 angle extremes), never one per pose (361)
    assert calls["rates"] <= 4 and calls["follow"] <= 40
