"""Sweeps: a full crank turn against the closed form, branch continuity, failures named by
their angle, streamed CSV with units, JSON lines and a figure."""

from __future__ import annotations

import csv
import io
import itertools
import json

import closed_form
import numpy as np
import pytest

from pinmech import Scene, SweepError
from pinmech.cli import main
from pinmech.io.sweep import Sweep
from pinmech.io.tables import write_csv
from tests.tolerance import REGULAR, closure

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
    np.testing.assert_allclose(last.points["D"].position, first.points["D"].position, atol=closure(0.2, REGULAR))
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


def test_a_singular_pose_the_sweep_goes_past_is_a_failed_row_naming_its_angle(tmp_path, models_dir):
    """AB = AC: at phi = 0 the block sits on C and the guide's direction is undefined (a
    change point of the inverted slider-crank, r = d). The pose is a failed row saying so
    and the sweep goes on past it; as the last pose it is a row saying so, the sweep ending
    on it (it stopped the sweep, exit 7)."""
    sweep = Sweep.from_scene(_singular_scene(tmp_path, models_dir))
    with pytest.raises(SweepError, match=r"sweep stopped at A = 0 deg"):  # any failure stops a sweep by default
        list(sweep.poses(np.radians([-20.0, -10.0, 0.0, 10.0])))
    poses = list(sweep.poses(np.radians([-20.0, -10.0, 0.0, 10.0]), past_change_points=True))
    assert [p.motion is None for p in poses] == [False, False, True, False]
    assert "A = 0 deg" in poses[2].error and "change point" in poses[2].note
    with pytest.raises(SweepError, match=r"sweep stopped at A = 0 deg") as info:
        list(sweep.poses(np.radians([-20.0, -10.0, 0.0])))
    assert info.value.value == 0.0 and info.value.exit_code == 7
    *_, last = sweep.poses(np.radians([-20.0, -10.0, 0.0]), past_change_points=True)
    assert last.motion is None and "A = 0 deg" in last.error and "last pose is a change point" in last.note


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
                   "closure_residual [1]", "condition_number [1]", "newton_iterations [1]", "pose", "error"):
        assert column in header
    rows = list(csv.DictReader(io.StringIO(out.getvalue())))
    assert {r["pose"] for r in rows} == {"solved"} and not any(r["error"] for r in rows)


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


def test_cli_sweep_ending_on_a_change_point_names_the_angle_and_succeeds(tmp_path, models_dir, capsys):
    """The inverted slider-crank's change point as the last pose: a failed row naming the
    angle, exit 0 (it was exit 7: a sweep's end on a change point is not a failure)."""
    scene = _singular_scene(tmp_path, models_dir)
    assert main(["sweep", str(scene.path), "--from", "-20 deg", "--to", "0 deg", "--steps", "5"]) == 0
    captured = capsys.readouterr()
    assert "at pose 4: the sweep's last pose is a change point" in captured.err
    assert "A = 0 deg" in captured.out.splitlines()[-1]


def test_start_options_agree_on_the_exact_solution(sweep):
    """Predictor, plain warm start and cold start all converge to the same closed poses."""
    values = sweep.default_values(73)
    runs = [list(sweep.poses(values, predictor=p, warm_start=w)) for p, w in ((True, True), (False, True), (False, False))]
    ref = np.array([p.motion.points["D"].acceleration for p in runs[0]])
    for other in runs[1:]:
        got = np.array([p.motion.points["D"].acceleration for p in other])
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-11 * np.abs(ref).max())


def test_cli_marks_interpolated_rows_and_writes_json_lines(r_rtr_scene, tmp_path, capsys):
    json_path = tmp_path / "s.jsonl"
    assert main(["sweep", str(r_rtr_scene), "--steps", "41", "--interpolate", "4", "--json", str(json_path),
                 "--csv", str(tmp_path / "s.csv")]) == 0
    rows = list(csv.DictReader((tmp_path / "s.csv").open()))
    kinds = [r["pose"] for r in rows]
    assert kinds[0] == kinds[-1] == "solved" and kinds.count("interpolated") == 30
    entries = [json.loads(line) for line in json_path.read_text().splitlines()]
    assert [e["pose"] for e in entries] == kinds
    assert entries[1]["accuracy"]["closure_residual"] > 0  # measured, not assumed


@pytest.mark.parametrize("argv, code, message", [
    (["--interpolate", "0"], 2, "at least 1"),
    (["--steps", "1"], 2, "at least 2"),
    (["--tol", "-1"], 2, "must be between"),
    (["--max-iterations", "0"], 2, "at least 1"),
    (["--set", "sweep.colour=1"], 4, "unknown key colour"),
    (["--set", 'sweep.start="hot"'], 4, "must be one of"),
    (["--start", "cold", "--interpolate", "4"], 2, "predictor start"),
])
def test_cli_bad_sweep_options_exit_with_one_line(r_rtr_scene, capsys, argv, code, message):
    assert main(["sweep", str(r_rtr_scene), "--steps", "5", *argv]) == code
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_scene_sweep_keys_set_the_defaults(tmp_path, models_dir, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(f'urdf = "{models_dir / "r_rtr.urdf"}"\n[drivers.A]\nangle = "30 deg"\nspeed = "-50 rpm"\n'
                     '[guess]\nB = "20 deg"\nB_slider = "-60 mm"\n'
                     '[sweep]\nsteps = 5\nfrom = "0 deg"\nto = "90 deg"\nstart = "warm"\n')
    assert main(["sweep", str(scene)]) == 0
    rows = list(csv.reader(io.StringIO(capsys.readouterr().out)))
    assert [float(r[0]) for r in rows[1:]] == pytest.approx([0, 22.5, 45, 67.5, 90])


def test_a_task_scene_is_followed_in_time(scenes_dir, tmp_path, capsys):
    """`pinmech sweep` on text 17.110's arm: the path mode, for the scene's [sweep]
    duration (0.08 s, 1 ms steps) or --duration; without either it says what is missing."""
    csv_path = tmp_path / "arm.csv"
    assert main(["sweep", str(scenes_dir / "planar_arm.toml"), "--csv", str(csv_path)]) == 0
    lines = csv_path.read_text().splitlines()
    assert lines[0].startswith("t [s],A.q [deg]") and len(lines) == 82
    assert main(["sweep", str(scenes_dir / "planar_arm.toml"), "--duration", "10 ms", "--csv", str(csv_path)]) == 0
    assert len(csv_path.read_text().splitlines()) == 12
    text = (scenes_dir / "planar_arm.toml").read_text().split("[sweep]")[0].replace('"../', f'"{scenes_dir.parent}/')
    (tmp_path / "arm.toml").write_text(text)
    assert main(["sweep", str(tmp_path / "arm.toml")]) == 2
    assert "--duration" in capsys.readouterr().err


def test_the_figure_marks_failures_and_stays_bounded(tmp_path, models_dir):
    """A failing pose leaves a gap (NaN) and a red mark; a long sweep keeps every n-th pose."""
    pytest.importorskip("matplotlib", reason='plots need pip install "pinmech[plot]"')
    from pinmech.draw.plot import SweepPlot

    sweep = Sweep.from_scene(_singular_scene(tmp_path, models_dir))
    recorder = SweepPlot(sweep, total=41, max_points=20)
    for pose in sweep.poses(np.radians(np.linspace(-20.0, 20.0, 41)), skip_failures=True):
        recorder.add(pose)
    assert recorder.every == 3 and len(recorder.failed) == 1
    assert any(np.isnan(v).any() for panel in recorder.series.values() for v in panel.values())
    png = recorder.save(tmp_path / "f.png")
    assert png.stat().st_size > 20_000


def test_the_figure_needs_matplotlib(r_rtr_scene, monkeypatch, capsys):
    """Without the extra: one line naming it, exit 2, and no sweep run first."""
    import builtins

    real_import = builtins.__import__

    def no_matplotlib(name, *args, **kwargs):
        if name.startswith("matplotlib"):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    assert main(["sweep", str(r_rtr_scene), "--steps", "5", "--plot", "x.png"]) == 2
    assert 'pip install "pinmech[plot]"' in capsys.readouterr().err


def test_a_sweep_where_every_pose_fails_plots_nothing_and_says_so(tmp_path, models_dir, capsys):
    pytest.importorskip("matplotlib", reason='plots need pip install "pinmech[plot]"')
    scene = _singular_scene(tmp_path, models_dir)
    code = main(["sweep", str(scene.path), "--from", "0 deg", "--to", "0 deg", "--steps", "2", "--skip-failures",
                 "--plot", str(tmp_path / "none.png"), "--csv", str(tmp_path / "none.csv")])
    assert code == 2 and "nothing to plot" in capsys.readouterr().err
    rows = list(csv.reader((tmp_path / "none.csv").open()))
    assert rows[0] == ["A.q [deg]", "pose", "error"] and [r[1] for r in rows[1:]] == ["failed", "failed"]


def test_the_progress_bar_shows_on_a_terminal_only(monkeypatch):
    """Piped (the tests), poses pass through untouched; on a terminal tqdm wraps them."""
    import sys

    from pinmech.cli.progress import progress as _progress

    items = iter(range(3))
    assert _progress(items, 3) is items
    pytest.importorskip("tqdm", reason='the bar needs pip install "pinmech[progress]"')
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    bar = _progress(range(3), 3)
    assert type(bar).__name__ == "tqdm" and list(bar) == [0, 1, 2]


def test_a_sweep_of_absurdly_many_steps_is_refused_before_any_work(scenes_dir, tmp_path, capsys):
    """Issue 22 item 16's class: `--steps 100000000000` (or `[sweep] steps`) is over
    counts.MAX_POSES (10 million): exit 2 before the first row, naming where it was asked
    and the count (the signal tests of test_outputs.py run the limit itself)."""

    out = tmp_path / "rows.csv"
    assert main(["sweep", str(scenes_dir / "four_bar.toml"), "--steps", "100000000000", "--csv", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--steps" in err and "1e+11 poses" in err and "10,000,000" in err and not out.exists()
    scene = tmp_path / "fb.toml"
    text = (scenes_dir / "four_bar.toml").read_text().replace('urdf = "../', f'urdf = "{scenes_dir.parent}/')
    assert "[sweep]\n" in text
    scene.write_text(text.replace("[sweep]\n", "[sweep]\nsteps = 20000000\n"))
    assert main(["sweep", str(scene)]) == 2
    assert "fb.toml: [sweep] steps" in capsys.readouterr().err
