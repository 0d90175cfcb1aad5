"""A joint dragged on the design page while the linkage is shown at a crank angle other than
the drawn one: at that angle, the joint is where the mouse is. Checked on the bundled
four-bar (O2 at the origin, O4 at (100, 0) mm, crank 40 mm drawn along x) against its own
geometry at crank angle 90 deg: A at (0, 40) mm.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("starlette")

from pinmech.draw.design_page.session import Session, read_design_file  # noqa: E402
from pinmech.model.linkage import linkage_from_spec  # noqa: E402

LINKAGES = Path(__file__).resolve().parents[1] / "models" / "linkages"
POSE = 90  # 1-degree poses from the drawn one: the crank at 90 deg
A90, O4 = np.array([0.0, 0.04]), np.array([0.1, 0.0])
#: Lengths written to 1e-6 m (edits.DECIMALS): each within 0.5e-6 m of the exact one.
WRITTEN = 1e-6


def _session(file: str = "four_bar.toml") -> Session:
    spec, source, driver, speed = read_design_file(LINKAGES / file)
    return Session(spec, source, driver=driver, speed=speed)


def _metres(text: str) -> float:
    value, unit = text.split()
    return float(value) * {"mm": 1e-3, "m": 1.0}[unit]


def test_a_pin_dragged_at_90_deg_gets_the_coupler_and_rocker_that_put_it_there():
    session = _session()
    assert np.allclose(session.turn.position[POSE, session.turn.names.index("A")], A90, atol=1e-12)
    mouse = np.array([0.052, 0.091])
    frame = session.drag("B", *mouse, index=POSE)
    assert frame["ok"], frame.get("error")
    coupler, rocker = (_metres(x) for x in session.spec.joints["B"].lengths)
    assert abs(coupler - np.linalg.norm(mouse - A90)) < WRITTEN
    assert abs(rocker - np.linalg.norm(mouse - O4)) < WRITTEN
    at = session.turn.position[POSE, session.turn.names.index("B")]
    assert np.linalg.norm(at - mouse) < 4 * WRITTEN  # two lengths each within 0.5e-6 m


def test_the_crank_pin_dragged_at_90_deg_turns_the_drawn_crank_back_by_90_deg():
    session = _session()
    mouse = np.array([-0.005, 0.045])
    assert session.drag("A", *mouse, index=POSE)["ok"]
    drawn = linkage_from_spec(session.spec, session.source).points["A"][:2]
    assert abs(np.linalg.norm(drawn) - np.linalg.norm(mouse)) < WRITTEN  # the crank's length
    turned = math.atan2(mouse[1], mouse[0]) - math.atan2(drawn[1], drawn[0])
    assert abs(turned - math.radians(POSE)) < WRITTEN / 0.045  # the drawn crank 90 deg back
    at = session.turn.position[POSE, session.turn.names.index("A")]
    assert np.linalg.norm(at - mouse) < 2 * WRITTEN


def test_a_coupler_point_dragged_at_90_deg_keeps_its_triangle_with_a_and_b():
    session = _session()
    before = {n: session.turn.position[POSE, k] for k, n in enumerate(session.turn.names)}
    mouse = np.array([0.02, 0.11])
    assert session.drag("P", *mouse, index=POSE)["ok"]
    drawn = linkage_from_spec(session.spec, session.source).points
    for base in ("A", "B"):  # P rides on the coupler: its distances to A and B are the mouse's at 90 deg
        assert abs(np.linalg.norm(drawn["P"][:2] - drawn[base][:2]) - np.linalg.norm(mouse - before[base])) < 2 * WRITTEN
    assert np.linalg.norm(session.turn.position[POSE, session.turn.names.index("P")] - mouse) < 2 * WRITTEN


def test_a_joint_that_cannot_be_carried_back_is_refused_saying_return_to_the_drawn_pose():
    session = _session("slider_crank.toml")
    before = session.spec
    at = session.turn.position[POSE, session.turn.names.index("B")]
    frame = session.drag("B", at[0] + 0.01, at[1], index=POSE)  # the block's pin: rod and piston move with it
    assert not frame["ok"] and "return the crank to the drawn pose" in frame["error"]
    assert session.spec is before
