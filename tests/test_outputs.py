"""Output files are whole or unmistakably partial; an existing file is never destroyed;
a signal stops the run with one line and its exit code (128 + the signal's number)."""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pinmech.cli import main
from pinmech.io.sweep import DriverValues
from tests.tolerance import rounding

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def singular_at_zero(tmp_path, models_dir) -> Path:
    """The R-RTR with AB = AC: singular at A = 0 deg (the block sits on C: a change point,
    the crossing of two branches). Swept from warm starts, where no pose is taken for a
    change point passed on the way, that pose stops the sweep (exit 7)."""
    text = (models_dir / "r_rtr.urdf").read_text().replace('<parent_origin xyz="0.05 0 0"',
                                                            '<parent_origin xyz="0.10 0 0"')
    (tmp_path / "ab_ac.urdf").write_text(text)
    scene = tmp_path / "s.toml"
    scene.write_text('urdf = "ab_ac.urdf"\n[drivers.A]\nangle = "-20 deg"\nspeed = "1 rad/s"\n'
                     '[guess]\nB = "-80 deg"\nB_slider = "-30 mm"\n')
    return scene


def _files(folder: Path) -> set[str]:
    return {p.name for p in folder.iterdir()}


def test_a_sweep_failing_at_its_first_pose_leaves_an_existing_csv_as_it_was(singular_at_zero, tmp_path, capsys):
    out = tmp_path / "a.csv"
    out.write_text("an earlier, complete result\n")
    before = _files(tmp_path)
    assert main(["sweep", str(singular_at_zero), "--from", "0 deg", "--to", "10 deg", "--steps", "3", "--start", "warm",
                 "--csv", str(out)]) == 7
    assert out.read_text() == "an earlier, complete result\n"
    assert _files(tmp_path) == before  # nothing written: no partial file, no temporary left behind


def test_a_sweep_failing_midway_keeps_its_rows_as_partial_files_that_agree(singular_at_zero, tmp_path, capsys):
    out, lines = tmp_path / "a.csv", tmp_path / "a.jsonl"
    out.write_text("old\n")
    code = main(["sweep", str(singular_at_zero), "--from", "-20 deg", "--to", "0 deg", "--steps", "5", "--start", "warm",
                 "--csv", str(out), "--json", str(lines)])
    assert code == 10  # a warm start landing on the singular pose: no assembly to keep there
    err = capsys.readouterr().err
    assert out.read_text() == "old\n" and not lines.exists()
    rows = list(csv.reader((tmp_path / "a.csv.partial").open()))
    assert [float(r[0]) for r in rows[1:]] == pytest.approx([-20, -15, -10, -5])  # the poses before 0 deg
    assert len((tmp_path / "a.jsonl.partial").read_text().splitlines()) == 4
    [line] = err.strip().splitlines()  # the error and the partial files, in one line
    assert "sweep stopped at A = 0 deg" in line and "a.csv.partial (" in line and "left as it was" in line
    assert not [n for n in _files(tmp_path) if n.startswith(".")]  # no temporary left behind


def test_a_complete_sweep_replaces_the_file_and_leaves_no_temporary(r_rtr_scene, tmp_path, capsys):
    out = tmp_path / "a.csv"
    out.write_text("old\n")
    os.chmod(out, 0o640)
    assert main(["sweep", str(r_rtr_scene), "--steps", "5", "--csv", str(out)]) == 0
    assert len(out.read_text().splitlines()) == 6 and out.stat().st_mode & 0o777 == 0o640
    assert _files(tmp_path) == {"a.csv"}


@pytest.mark.parametrize("first, second, spelled", [("--csv", "--json", "X.png"), ("--json", "--plot", "X.png"),
                                                   ("--csv", "--plot", "sub/../X.png"), ("--csv", "--plot", "X")])
def test_one_path_for_two_outputs_is_refused_before_computing(r_rtr_scene, tmp_path, capsys, first, second, spelled):
    (tmp_path / "sub").mkdir()
    target = tmp_path / "X.png"  # --plot X writes X.png
    assert main(["sweep", str(r_rtr_scene), "--steps", "3", first, str(target), second, str(tmp_path / spelled)]) == 2
    assert "give each output its own file" in capsys.readouterr().err
    assert not target.exists()


def test_an_output_over_the_scene_file_is_refused(r_rtr_scene, tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(r_rtr_scene.read_text().replace('"../r_rtr.urdf"', f'"{r_rtr_scene.parent.parent}/r_rtr.urdf"'))
    text = scene.read_text()
    assert main(["sweep", str(scene), "--steps", "3", "--csv", str(scene)]) == 2
    assert "would overwrite the scene file" in capsys.readouterr().err and scene.read_text() == text


def test_an_unknown_figure_format_is_refused_before_computing(singular_at_zero, tmp_path, capsys):
    # The scene fails at 0 deg (exit 7): exit 2 shows the format was checked first.
    code = main(["sweep", str(singular_at_zero), "--from", "0 deg", "--to", "1 deg", "--steps", "2", "--start", "warm",
                 "--plot", str(tmp_path / "fig.xyz")])
    assert code == 2 and "cannot draw a .xyz figure" in capsys.readouterr().err


def test_a_figure_without_suffix_is_a_png_and_says_so(r_rtr_scene, tmp_path, capsys):
    pytest.importorskip("matplotlib", reason='plots need pip install "pinmech[plot]"')
    assert main(["sweep", str(r_rtr_scene), "--steps", "5", "--plot", str(tmp_path / "fig")]) == 0
    assert (tmp_path / "fig.png").read_bytes()[:4] == b"\x89PNG"
    assert f"figure written to {tmp_path / 'fig.png'}" in capsys.readouterr().err


def test_driver_values_are_linspace_without_its_array():
    import numpy as np

    for first, last, steps in ((0.1, 7.3, 361), (0.0, 1.0, 2), (-3.0, 5e-3, 1000), (2.0, 2.0, 5)):
        np.testing.assert_array_equal(np.array(list(DriverValues(first, last, steps))),
                                      np.linspace(first, last, steps))
    huge = DriverValues(0.0, 1.0, 10**10)  # 80 GB as an array
    assert len(huge) == 10**10 and huge[-1] == 1.0 and huge[1] == pytest.approx(1 / (10**10 - 1), rel=rounding(1.0))


def _sweep_process(scene: Path, folder: Path, steps: str = "10000000") -> subprocess.Popen:  # counts.MAX_POSES
    return subprocess.Popen(
        [sys.executable, "-m", "pinmech", "sweep", str(scene), "--from", "-20 deg", "--to", "-10 deg",
         "--steps", steps, "--csv", str(folder / "b.csv"), "--json", str(folder / "b.jsonl")],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)


def _wait_for_rows(folder: Path, process: subprocess.Popen) -> None:
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and process.poll() is None:
        if any(p.name.startswith(".b.jsonl") and p.stat().st_size > 20_000 for p in folder.iterdir()):
            return
        time.sleep(0.05)
    raise AssertionError(f"the sweep wrote nothing: {process.communicate()}")


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_signal_stops_a_sweep_of_1e7_poses_with_one_line_and_agreeing_partial_files(singular_at_zero, tmp_path, signum):
    process = _sweep_process(singular_at_zero, tmp_path)
    _wait_for_rows(tmp_path, process)
    process.send_signal(signum)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 128 + signum
    [line] = err.strip().splitlines()  # one line, naming the partial files
    assert line.startswith(f"pinmech: interrupted by {signal.Signals(signum).name}: stopped; incomplete output kept in")
    assert "b.csv.partial (" in line and "b.jsonl.partial (" in line
    assert not (tmp_path / "b.csv").exists() and not (tmp_path / "b.jsonl").exists()
    rows = (tmp_path / "b.csv.partial").read_text().splitlines()
    lines = (tmp_path / "b.jsonl.partial").read_text().splitlines()
    assert len(rows) - 1 == len(lines) > 0  # one header; every pose in both files or in neither


def test_two_sweeps_writing_one_file_leave_one_complete_file(r_rtr_scene, tmp_path):
    out = tmp_path / "a.csv"
    runs = [subprocess.Popen([sys.executable, "-m", "pinmech", "sweep", str(r_rtr_scene), "--steps", steps,
                              "--csv", str(out)], stderr=subprocess.PIPE, cwd=ROOT) for steps in ("3000", "3001")]
    assert [r.wait(timeout=120) for r in runs] == [0, 0]
    assert len(out.read_text().splitlines()) - 1 in (3000, 3001)  # one run's rows, whole
    assert _files(tmp_path) == {"a.csv"}


@pytest.mark.parametrize("command", ["snapshot", "animate"])
def test_a_page_over_its_own_scene_or_urdf_is_refused(tmp_path, models_dir, command, capsys):
    pytest.importorskip("meshcat")
    scene = tmp_path / "s.toml"
    scene.write_text(f'urdf = "{models_dir / "r_rtr.urdf"}"\n[drivers.A]\nangle = "30 deg"\n'
                     '[guess]\nB = "20 deg"\nB_slider = "-60 mm"\n')
    text = scene.read_text()
    for target, what in ((scene, "the scene file"), (models_dir / "r_rtr.urdf", "the URDF")):
        assert main([command, str(scene), "-o", str(target)]) == 2
        assert f"would overwrite {what}" in capsys.readouterr().err
    assert scene.read_text() == text


@pytest.mark.parametrize("target, message", [(".", "is a folder: give a file name"),
                                             ("missing/x.csv", "no such folder")])
def test_an_output_that_cannot_be_a_file_is_refused_before_computing(singular_at_zero, tmp_path, capsys, target,
                                                                     message):
    code = main(["sweep", str(singular_at_zero), "--from", "0 deg", "--to", "1 deg", "--steps", "2", "--start", "warm",
                 "--csv", str(tmp_path / target)])
    assert code == 2 and message in capsys.readouterr().err  # 2, not the pose's 7: checked first


def test_a_pipe_is_written_directly(r_rtr_scene, tmp_path, capsys):
    import threading

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got: list[str] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()))
    reader.start()
    assert main(["sweep", str(r_rtr_scene), "--steps", "4", "--csv", str(fifo)]) == 0
    reader.join(timeout=30)
    assert len(got[0].splitlines()) == 5 and _files(tmp_path) == {"pipe"}


def test_an_output_at_a_symbolic_link_replaces_the_link_never_its_target(r_rtr_scene, tmp_path, capsys):
    """Written as `mv` would: the link becomes the file; the file it pointed to is untouched
    (tests/test_hostile_outputs.py hunts the class over every writer)."""
    (tmp_path / "real").mkdir()
    target = tmp_path / "real" / "a.csv"
    target.write_text("old\n")
    os.symlink(target, tmp_path / "link.csv")
    assert main(["sweep", str(r_rtr_scene), "--steps", "3", "--csv", str(tmp_path / "link.csv")]) == 0
    assert not (tmp_path / "link.csv").is_symlink() and len((tmp_path / "link.csv").read_text().splitlines()) == 4
    assert target.read_text() == "old\n" and _files(tmp_path / "real") == {"a.csv"}


def test_animate_refuses_more_frames_than_a_page_can_keep(r_rtr_scene, tmp_path, capsys):
    assert main(["animate", str(r_rtr_scene), "-o", str(tmp_path / "a.html"), "--steps", "10000000000"]) == 2
    assert "--steps must be between 2 and 20000 frames" in capsys.readouterr().err


@pytest.mark.parametrize("target, message", [("/", "is a folder"), (".", "is a folder"), ("..", "is a folder"),
                                             ("/dev/null", "is not a regular file")])
def test_a_figure_that_cannot_be_a_file_is_refused_in_one_line(singular_at_zero, target, message, capsys):
    code = main(["sweep", str(singular_at_zero), "--from", "0 deg", "--to", "1 deg", "--steps", "2", "--start", "warm", "--plot", target])
    assert code == 2 and f"--plot {target} {message}" in capsys.readouterr().err


def test_rows_sent_to_standard_output_end_with_a_mark_when_the_run_stops(singular_at_zero, capsys):
    # a warm start landing on the singular pose: no assembly to keep there (exit 10)
    assert main(["sweep", str(singular_at_zero), "--from", "-20 deg", "--to", "0 deg", "--steps", "5",
                 "--start", "warm"]) == 10
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 1 + 4 + 1  # header, the 4 poses before 0 deg, the mark
    assert lines[-1].startswith("INCOMPLETE: pinmech stopped before the last row (sweep stopped at A = 0 deg")


def test_polygon_report_and_build_never_write_over_what_they_read(tmp_path, models_dir, capsys):
    """`polygon -o`, `report -o` and `build -o` named their own scene, URDF, hand file or
    linkage and replaced it (exit 0): now refused before anything is computed, the file
    untouched. Copies in tmp_path, so a regression destroys nothing bundled."""
    import shutil

    urdf = tmp_path / "r_rtr.urdf"
    shutil.copy(models_dir / "r_rtr.urdf", urdf)
    scene = tmp_path / "s.toml"
    scene.write_text('urdf = "r_rtr.urdf"\n[drivers.A]\nangle = "30 deg"\n[guess]\nB = "20 deg"\nB_slider = "-60 mm"\n')
    hand = tmp_path / "s.hand.toml"
    hand.write_text('scene = "s.toml"\n[[value]]\nlabel = "x"\npath = "joints.A.q"\nvalue = "30 deg"\n')
    linkage = tmp_path / "four_bar.toml"
    shutil.copy(models_dir / "linkages" / "four_bar.toml", linkage)
    before = {p: p.read_bytes() for p in (urdf, scene, hand, linkage)}
    runs = [(["polygon", str(scene), "-o", str(scene)], "the scene file"),
            (["polygon", str(scene), "-o", str(urdf)], "the URDF"),
            (["report", str(scene), "-o", str(scene), "--steps", "0"], "the scene file"),
            (["report", str(scene), "--hand", str(hand), "-o", str(hand), "--steps", "0"], "the hand file"),
            (["build", str(linkage), "-o", str(linkage)], "the linkage file")]
    for argv, what in runs:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert f"would overwrite {what}" in err and len(err.strip().splitlines()) == 1, err
    assert {p: p.read_bytes() for p in before} == before


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_stops_the_compiled_core_inside_a_span_of_a_million_turns(models_dir, tmp_path, signum):
    """Two poses 1e7 rad apart: the compiled core follows 1.6 million turns in one call,
    without the GIL. It looks at Python's signal handlers every 4096 steps (about 10 ms),
    so Ctrl-C and SIGTERM stop it with pinmech's one line; before, it ran on for minutes
    (only SIGKILL stopped a span of 1e10 deg)."""
    process = subprocess.Popen(
        [sys.executable, "-m", "pinmech", "sweep", str(models_dir / "scenes" / "r_rtr.toml"), "--from", "0 rad",
         "--to", "2e7 rad", "--steps", "3", "--csv", str(tmp_path / "b.csv")],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    time.sleep(4)  # imports, the first pose, then well inside the core's span
    assert process.poll() is None, process.communicate()
    sent = time.monotonic()
    process.send_signal(signum)
    _, err = process.communicate(timeout=60)
    assert time.monotonic() - sent < 10
    assert process.returncode == 128 + signum, err
    [line] = err.strip().splitlines()
    assert line.startswith(f"pinmech: interrupted by {signal.Signals(signum).name}: stopped")


def test_build_writes_files_as_every_other_output_does(tmp_path, models_dir):
    """`pinmech build` left its URDF at mkstemp's 0600 (and turned an existing 0640 file to
    0600): now the mode an ordinary write gives under the umask, or the old file's."""
    import os
    import stat

    umask = os.umask(0o022)
    try:
        fresh, kept = tmp_path / "a.urdf", tmp_path / "b.urdf"
        kept.write_text("x")
        kept.chmod(0o640)
        for target in (fresh, kept):
            assert main(["build", str(models_dir / "linkages" / "four_bar.toml"), "-o", str(target)]) == 0
    finally:
        os.umask(umask)
    assert stat.S_IMODE(fresh.stat().st_mode) == 0o644
    assert stat.S_IMODE(kept.stat().st_mode) == 0o640
    assert "<robot" in kept.read_text()


def test_a_figure_refused_at_the_end_names_the_users_file_not_its_temporary(tmp_path, capsys):
    """`--paths` with no point to trace is refused when the figure is drawn: the message
    named the hidden temporary file (.p.png.XXXX.tmp.png), not p.png."""
    pytest.importorskip("matplotlib", reason='needs pip install "pinmech[plot]"')
    from pinmech.cli import main

    scene = tmp_path / "arm.toml"
    scene.write_text(f'linkage = "{Path(__file__).resolve().parents[1] / "models/linkages/four_bar.toml"}"\n'
                     '[drivers.O2]\nangle = "0 deg"\nspeed = "1 rad/s"\n[report]\npoints = []\n')
    target = tmp_path / "p.png"
    code = main(["sweep", str(scene), "--steps", "5", "--paths", str(target)])
    err = capsys.readouterr().err
    assert code != 0 and f"nothing to draw in {target}" in err and ".tmp" not in err, err
    assert not target.exists()
