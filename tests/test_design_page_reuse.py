"""The design page keeps one compiled mechanism across drags that change only dimensions
(its placements written in place, as design studies write variants): every turn it solves
is the turn of a mechanism built afresh from the same drawing, to rounding, and a drag that
fails leaves the kept turn's mechanism as it was."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("starlette")

from pinmech.draw.design_page.frame import TurnSolver  # noqa: E402
from pinmech.draw.design_page.session import Session, read_design_file  # noqa: E402
from pinmech.solve.sweep_frames import frame_paths  # noqa: E402

LINKAGES = Path(__file__).resolve().parents[1] / "models" / "linkages"
#: The same poses solved from the same placements: positions ~0.1 m agree to rounding
#: (a few 1e-16 m); 1e-12 m leaves room for a Newton step's last iterate.
SAME = 1e-12


def _fresh(session: Session) -> np.ndarray:
    return TurnSolver(session.solver.driver, session.solver.speed).solve(session.spec, session.source).position


@pytest.mark.parametrize("file, joint", [("four_bar.toml", "B"), ("watt.toml", "D"), ("slider_crank.toml", "A")])
def test_drags_reuse_the_mechanism_and_solve_what_a_fresh_build_solves(file, joint):
    spec, source, driver, speed = read_design_file(LINKAGES / file)
    session = Session(spec, source, driver=driver, speed=speed)
    built = session.turn.sweep.mechanism
    at = session.turn.linkage.points[joint][:2]
    for step in ([0.003, 0.001], [-0.002, 0.004], [0.001, -0.003]):
        assert session.drag(joint, *(at + step))["ok"]
        assert session.turn.sweep.mechanism is built  # written in place, not built again
        assert np.nanmax(np.abs(session.turn.position - _fresh(session))) < SAME


def test_a_turn_refused_after_its_write_leaves_the_kept_turns_mechanism_as_it_was():
    from pinmech.draw.design_page.edits import move_joint
    from pinmech.exceptions import PinmechError

    spec, source, _, _ = read_design_file(LINKAGES / "four_bar.toml")
    session = Session(spec, source)
    kept, built = session.turn, session.turn.sweep.mechanism
    at = kept.linkage.points["B"][:2]
    moved = move_joint(session.spec, "B", at + [0.004, 0.002], kept.linkage.points, source)

    def refuse(turn) -> None:  # as a drag at another crank angle that misses the mouse is refused
        assert turn.sweep.mechanism is built  # solved on the written mechanism
        raise PinmechError("refused")

    assert not session.solve(moved, refuse)["ok"]
    assert session.turn is kept
    solved = ~np.isnan(kept.q).any(axis=1)
    again = frame_paths(built, kept.names, kept.q[solved], kept.v[solved], kept.a[solved])
    assert np.abs(again.position[..., :2] - kept.position[solved]).max() < SAME
    assert session.drag("B", *(at + [0.001, 0.001]))["ok"]
    assert np.nanmax(np.abs(session.turn.position - _fresh(session))) < SAME
