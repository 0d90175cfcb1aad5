"""Sweeps: a full crank turn against the closed form, branch continuity, failures named by
their angle, streamed CSV with units, JSON lines and a figure."""

from __future__ import annotations

import csv
import io
import itertools
import json

import numpy as np
import pytest

import closed_form
from pinmech import Scene, SweepError
from pinmech.cli import main
from pinmech.sweep import Sweep
from pinmech.tables import write_csv

OMEGA1 = -50 * np.pi / 30


@pytest.fixture
def sweep(r_rtr_scene):
    return Sweep.from_scene(Scene.load(r_rtr_scene))


def test_a_full_turn_matches_the_closed_form(sweep):
    """1e-10 of each quantity's largest magnitude over the cycle (see test_r_rtr.py)."""
    values = sweep.default_values(721)
    poses = list(sweep.poses(values))
    cf = closed_form.r_rtr(values, OMEGA1, 0.0)
    vD = np.array([p.motion.points["D"].velocity[:2] for p in poses])
    aD = np.array([p.motion.points["D"].acceleration[:2] for p in poses])
    w3 = np.array([p.motion.links["link3"].angular_velocity[2] for p in poses])
    for ours, theirs in ((vD, cf.vD), (aD, cf.aD), (w3, cf.omega3)):
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-10 * np.abs(theirs).max())


def test_the_sweep_stays_on_its_branch_and_ends_where_it_started(sweep):
    poses = list(sweep.poses(sweep.default_values(361)))
    first, last = poses[0].motion, poses[-1].motion
    np.testing.assert_allclose(last.points["D"].position, first.points["D"].position, atol=1e-13)
    # D stays on the far side of B from C all the way round (branch +1): s = CB.u > 0
    for p in poses:
        m = p.motion
        u = m.points["D"].position - m.points["C"].position
        assert u @ (m.points["B"].position - m.points["C"].position) > 0


def test_rows_are_produced_lazily(sweep):
    """A generator: taking 3 poses of a million-pose sweep solves 3 poses."""
    gen = sweep.poses(np.linspace(0.0, 2e3 * np.pi, 1_000_000))
    taken = list(itertools.islice(gen, 3))
    assert [p.index for p in taken] == [0, 1, 2]


def _singular_scene(tmp_path, models_dir):
    text = (models_dir / "r_rtr.urdf").read_text().replace('<parent_origin xyz="0.05 0 0"', '<parent_origin xyz="0.10 0 0"')
    (tmp_path / "r_rtr_ab_ac.urdf").write_text(text)
    scene = tmp_path / "s.toml"
    scene.write_text('urdf = "r_rtr_ab_ac.urdf"\n[drivers.A]\nangle = "-20 deg"\nspeed = "1 rad/s"\n'
                     '[guess]\nB = "-80 deg"\nB_slider = "-30 mm"\n')
    return Scene.load(scene)


def test_a_singular_pose_stops_the_sweep_naming_its_angle(tmp_path, models_dir):
    """AB = AC: at phi = 0 the block sits on C and the guide's direction is undefined."""
    sweep = Sweep.from_scene(_singular_scene(tmp_path, models_dir))
    with pytest.raises(SweepError, match=r"sweep stopped at A = 0 deg") as info:
        list(sweep.poses(np.radians([-20.0, -10.0, 0.0, 10.0])))
    assert info.value.value == 0.0 and info.value.exit_code == 7


def test_skip_failures_reports_the_pose_with_its_error(tmp_path, models_dir):
    sweep = Sweep.from_scene(_singular_scene(tmp_path, models_dir))
    poses = list(sweep.poses(np.radians([-20.0, 0.0, 20.0]), skip_failures=True))
    assert [p.motion is None for p in poses] == [False, True, False]
    assert poses[1].error.startswith("SingularPoseError")
    out = io.StringIO()
    write_csv(sweep, poses, out)
    rows = list(csv.reader(io.StringIO(out.getvalue())))
    assert float(rows[2][0]) == 0.0 and rows[2][-1].startswith("SingularPoseError")


def test_csv_columns_carry_units(sweep):
    out = io.StringIO()
    assert write_csv(sweep, sweep.poses(sweep.default_values(5)), out) == 5
    header = next(csv.reader(io.StringIO(out.getvalue())))
    for column in ("A.q [deg]", "link3.angle [deg]", "link3.omega [rad/s]", "link3.alpha [rad/s^2]",
                   "B_slider.v_rel [m/s]", "B_slider.a_rel [m/s^2]", "D.|v| [m/s]", "D.|a| [m/s^2]",
                   "closure_residual [1]", "condition_number [1]"):
        assert column in header


def test_cli_writes_csv_json_and_a_figure(r_rtr_scene, tmp_path):
    pytest.importorskip("matplotlib", reason='plots need pip install "pinmech[plot]"')
    csv_path, json_path, png = tmp_path / "s.csv", tmp_path / "s.jsonl", tmp_path / "s.png"
    code = main(["sweep", str(r_rtr_scene), "--steps", "37", "--csv", str(csv_path), "--json", str(json_path),
                 "--plot", str(png)])
    assert code == 0
    assert len(csv_path.read_text().splitlines()) == 38
    lines = json_path.read_text().splitlines()
    assert len(lines) == 37 and json.loads(lines[0])["A"] == pytest.approx(np.radians(30))
    assert png.stat().st_size > 20_000  # a real figure, not an empty canvas


def test_cli_range_in_users_units(r_rtr_scene, capsys):
    assert main(["sweep", str(r_rtr_scene), "--from", "0 deg", "--to", "90 deg", "--steps", "4"]) == 0
    rows = list(csv.reader(io.StringIO(capsys.readouterr().out)))
    assert [float(r[0]) for r in rows[1:]] == pytest.approx([0, 30, 60, 90])


def test_cli_failure_exit_code_names_the_angle(tmp_path, models_dir, capsys):
    scene = _singular_scene(tmp_path, models_dir)
    assert main(["sweep", str(scene.path), "--from", "-20 deg", "--to", "20 deg", "--steps", "5"]) == 7
    assert "sweep stopped at A = 0 deg" in capsys.readouterr().err


def test_start_options_agree_on_the_exact_solution(sweep):
    """Predictor, plain warm start and cold start all converge to the same closed poses."""
    values = sweep.default_values(73)
    runs = [list(sweep.poses(values, predictor=p, warm_start=w)) for p, w in ((True, True), (False, True), (False, False))]
    ref = np.array([p.motion.points["D"].acceleration for p in runs[0]])
    for other in runs[1:]:
        got = np.array([p.motion.points["D"].acceleration for p in other])
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-11 * np.abs(ref).max())
