"""Chains of four-bar loops in series (scripts/benchmark_loops.py, issue 13 item 3): the
generated URDF, its block-triangular structure, and a sweep against the closed form of
the four-bar applied loop after loop, by the compiled core.

No timing here (the script measures it). Tolerances:
- angles 1e-12 rad (issue 13's bar; the closure tolerance is 1e-13 of each loop's size,
  1e-14 rad is typical);
- rates and accelerations 1e-11 of the chain's largest: the closure error times the
  condition number of the dependent Jacobian (up to 14 for four loops), with margin;
- the script's closed form against scripts/closed_form.py (another derivation of the
  same four-bar): 1e-13.
"""

from __future__ import annotations

import importlib
import re

import numpy as np
import pytest

import closed_form
import pinmech
import pinmech.solve.core as core
from pinmech.solve import cycle as solve_cycle
from tests.tolerance import STATED_SWEEP, rounding

# The law of cosines' angles down the chain: rounding times the loops' condition numbers
# (below 40, checked in test_chain_condition_numbers_one_degree_apart_are_numpys).
CHAIN_COND = 40.0

chain = importlib.import_module("benchmark_loops")

K = 4
THETAS = np.radians(np.arange(360.0))


def _solve(k: int, thetas: np.ndarray):
    mech, solver = chain.chain_solver(k)
    q, v, a = chain.sweep(solver, thetas)
    return mech, solver, q, v, a


def test_the_closed_form_is_the_four_bar_of_closed_form_py():
    """One loop: the script's law-of-cosines form and scripts/closed_form.py agree on
    angles, rates and accelerations (a crank speeding up), for the branch it uses."""
    a, b, c, d = chain.LENGTHS
    ours = chain.chain_closed_form(THETAS, 1, omega=2.0, alpha=3.0)
    ref = closed_form.four_bar(THETAS, 2.0, 3.0, a, b, c, d, branch=-chain.BRANCH)
    pairs = [(ours.theta3[:, 0], ref.theta3), (ours.phi[:, 1], ref.theta4)]
    for got, want in pairs:
        assert np.abs(chain.wrap(got - want)).max() < rounding(1.0, CHAIN_COND)
    for got, want in [(ours.omega3[:, 0], ref.omega3), (ours.omega[:, 1], ref.omega4),
                      (ours.alpha3[:, 0], ref.alpha3), (ours.alpha[:, 1], ref.alpha4)]:
        np.testing.assert_allclose(got, want, rtol=0, atol=rounding(np.abs(want).max(), CHAIN_COND))


def test_chain_urdf_is_k_loops_in_series(tmp_path):
    """Mobility one, one cut per loop, and J_dep block lower-triangular: k 2x2 blocks."""
    mech, solver = chain.chain_solver(K, folder=tmp_path)
    assert mech.mobility == 1 and len(mech.closures) == K
    assert mech.model.nv == 2 * K + 1
    blocks = solver.structure.blocks
    assert len(blocks) == K and all(len(b.rows) == 2 and len(b.cols) == 2 for b in blocks)
    with pytest.raises(ValueError):
        chain.chain_urdf(0)


def test_chain_sweep_meets_the_closed_form():
    """A turn of the crank, 1 degree apart, every loop's coupler and output angle within
    1e-12 rad of the closed form, rates within 1e-11 of the largest. The core solves for
    the dependent joints by forward substitution over the K diagonal blocks."""
    mech, solver, q, v, a = _solve(K, THETAS)
    assert core.core_for(solver).solve_blocks == K
    angle, rate, acceleration = chain.chain_errors(mech, q, v, a, chain.chain_closed_form(THETAS, K))
    assert angle <= STATED_SWEEP, angle
    assert rate <= 1e-11 and acceleration <= 1e-11, (rate, acceleration)


class _FollowSpy:
    """A compiled core whose `follow` records why each run stopped (0: every pose done)."""

    def __init__(self, compiled, stops: list):
        self.compiled, self.stops = compiled, stops

    def follow(self, *args):
        out = self.compiled.follow(*args)
        self.stops.append(out[1])
        return out


def test_a_chain_listed_last_loop_first_is_solved_in_dependency_order(tmp_path, monkeypatch):
    """The cuts listed last loop first: J_dep's blocks then come last loop first, the
    reverse of what forward substitution needs (each loop's rows touch the previous
    loop's output column). The core orders the blocks itself, and the sweep meets the
    closed form to the same bars as above (a block solved before the one it leans on
    would read unsolved columns: the corrector would fail and hand every pose to the
    pose-by-pose follow, and the rates would be wrong)."""
    text = chain.chain_urdf(K)
    cuts = re.findall(r"<constraint .*?</constraint>", text, flags=re.S)
    for cut in cuts:
        text = text.replace(cut, "")
    text = text.replace("</robot>", "  " + "\n  ".join(reversed(cuts)) + "\n</robot>")
    path = tmp_path / "chain_backwards.urdf"
    path.write_text(text, encoding="utf-8")
    mech = pinmech.Mechanism.from_urdf(path)
    solver = pinmech.LoopSolver(mech, ["O0"])
    solver.set_reference([0.0], chain.chain_guess(mech, chain.chain_closed_form(0.0, K), 0))
    assert [b.name for b in solver.structure.blocks] == [f"B{i}" for i in reversed(range(K))]
    assert core.core_for(solver).solve_blocks == K
    stops: list[int] = []
    compiled_path = solve_cycle._Cycle._compiled
    monkeypatch.setattr(solve_cycle._Cycle, "_compiled",
                        lambda cycle, compiled, xs: compiled_path(cycle, _FollowSpy(compiled, stops), xs))
    q, v, a = chain.sweep(solver, THETAS)
    assert stops and set(stops) == {0}  # the core's sweep took every pose: none handed to its pose-by-pose follow
    angle, rate, acceleration = chain.chain_errors(mech, q, v, a, chain.chain_closed_form(THETAS, K))
    assert angle <= STATED_SWEEP, angle
    assert rate <= 1e-11 and acceleration <= 1e-11, (rate, acceleration)


def _conditions(solver, thetas: np.ndarray) -> np.ndarray:
    """The condition number of J_dep the sweep reports at each pose."""
    chunks = list(solve_cycle.solve_range(solver, "O0", thetas, driver_q=np.zeros(1), driver_v=np.array([chain.OMEGA]),
                                          driver_a=np.array([chain.ALPHA])))
    assert not any(c.errors for c in chunks)
    return np.concatenate([c.solution.condition for c in chunks])


@pytest.mark.parametrize("k", [2, 5, 16])
def test_chain_condition_numbers_are_the_svds(k):
    """The condition numbers a chain's sweep reports, pose by pose: the core's (J_dep
    permuted into block order, a band, bidiagonalized by plane rotations from 5 loops on)
    against numpy's SVD of the dimensionless J_dep at the same poses. A wrong permutation
    or band would be off by order one. The bar is tests/test_core.py's against the SVD,
    1e-12 + 100 n eps kappa with n = 2k (at most 3e-11 here, condition numbers below 40)."""
    thetas = np.radians(np.arange(0.0, 360.0, 7.0))
    _, solver = chain.chain_solver(k)
    got = _conditions(solver, thetas)
    compiled = core.core_for(solver)
    chunks = list(pinmech.solve_range(solver, solver.drivers[0], thetas, driver_q=np.zeros(1),
                                      driver_v=np.ones(1), driver_a=np.zeros(1)))
    want = []
    for q in np.concatenate([c.solution.q for c in chunks]):
        compiled.residual(q)
        J_dep = compiled.jacobian(False)[:, solver._dep_v] * solver._dep_scale
        sigma = np.linalg.svd(J_dep, compute_uv=False)
        want.append(sigma[0] / sigma[-1])
    want = np.array(want)
    assert np.all(want < 40.0)
    bar = rounding(1.0, want, steps=100 * 2 * k)
    assert np.all(np.abs(got / want - 1.0) <= bar)


def test_chain_condition_numbers_one_degree_apart_are_numpys():
    """Sixteen loops swept a full turn 1 degree apart: every pose's condition number
    search starts from the last pose's values (and the band is J_dep's structural one, not
    scanned), so this is the warm-started path at its usual step. Against
    np.linalg.cond(J_dep, 2) of the dimensionless J_dep at the same poses (LAPACK's SVD), to
    1e-12 relative: both are backward stable, within about n eps kappa = 32 x 2.2e-16 x 40 =
    3e-13 of the exact value (condition numbers below 40, checked)."""
    _, solver = chain.chain_solver(16)
    got = _conditions(solver, THETAS)
    compiled = core.core_for(solver)
    chunks = list(pinmech.solve_range(solver, solver.drivers[0], THETAS, driver_q=np.zeros(1),
                                      driver_v=np.ones(1), driver_a=np.zeros(1)))
    want = []
    for q in np.concatenate([c.solution.q for c in chunks]):
        compiled.residual(q)
        want.append(np.linalg.cond(compiled.jacobian(False)[:, solver._dep_v] * solver._dep_scale, 2))
    want = np.array(want)
    assert len(want) == len(got) == 360 and np.all(want < 40.0)
    assert np.all(np.abs(got / want - 1.0) <= rounding(1.0, want, steps=2 * 32)), np.abs(got / want - 1.0).max()


def test_a_sweeps_condition_numbers_do_not_depend_on_what_ran_before():
    """The condition number's search starts from the previous pose's values within a call,
    but every call from Python starts cold: the same sweep gives the same bits after an
    unrelated one (a study's variants run in other orders on other workers and must give
    the same numbers bit for bit). Exact equality: the same operations on the same inputs."""
    _, solver = chain.chain_solver(16)
    first = _conditions(solver, THETAS[:90])
    _conditions(solver, THETAS[200:260])  # leaves other extreme singular values behind
    again = _conditions(solver, THETAS[:90])
    assert np.array_equal(first, again)


def test_the_closed_form_moves_every_loop():
    """The drag-link proportions carry the motion to the last loop (no loop at rest), and
    every loop stays far from a toggle (transmission angle at least 29 degrees)."""
    cf = chain.chain_closed_form(THETAS, 16)
    assert np.ptp(np.unwrap(cf.phi[:, -1])) > 6.0  # the 16th output turns (nearly) fully
    transmission = np.abs(np.sin(cf.theta3 - cf.phi[:, 1:]))
    assert transmission.min() > np.sin(np.radians(29.0))


def test_benchmark_loops_runs(tmp_path, capsys):
    """The script end to end on short sweeps, one round (the timing itself not checked)."""
    out = tmp_path / "loops.md"
    rows = chain.main(["--loops", "2", "--poses", "20", "--rounds", "1", "--sample-time", "0", "--out", str(out)])
    assert out.read_text() == capsys.readouterr().out.rstrip("\n") + "\n"
    assert {(r.k, r.path) for r in rows} == {(1, "core"), (2, "core")}
    assert all(r.errors[0] <= STATED_SWEEP and len(r.times) == 1 for r in rows)
    assert "| 2 | core |" in out.read_text()
    assert "target" not in out.read_text().lower()  # the targets are the exit code's (missed_targets)
