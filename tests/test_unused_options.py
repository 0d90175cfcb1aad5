"""Every draw (and force, range) option of `pinmech sweep` either does its work or is
refused out loud: an `OptionRefused` on one line, exit 2, no file written (pinmech/io/unused_options.py).
Before, `sweep planar_arm --paths X` wrote nothing and said nothing."""

from __future__ import annotations

from pathlib import Path

import pytest

from pinmech.cli import main

SCENES = Path(__file__).resolve().parents[1] / "models" / "scenes"

#: Options of a driver sweep, each with a value, given to task scenes ([[task]]).
DRIVER_SWEEP_OPTIONS = [
    ["--paths", "{out}"], ["--torque-plot", "{out}"], ["--forces"], ["--static"], ["--minimum-norm"],
    ["--flywheel", "0.01 kg*m^2"], ["--links", "AB"], ["--points", "D"], ["--path-plane", "3d"],
    ["--angles", "wrapped"], ["--driver", "A"], ["--from", "0 deg"], ["--to", "90 deg"], ["--steps", "5"],
    ["--through-folds"], ["--interpolate", "2"], ["--tol", "1e-9"], ["--max-iterations", "5"],
    ["--skip-failures"], ["--start", "cold"], ["--cold-start"], ["--no-predictor"], ["--no-batch"],
]


@pytest.mark.parametrize("scene", ["planar_arm.toml", "r_rtr_task.toml"])
@pytest.mark.parametrize("option", DRIVER_SWEEP_OPTIONS, ids=lambda o: o[0])
def test_a_task_scene_refuses_every_driver_sweep_option(scene, option, tmp_path, capsys):
    out = tmp_path / "figure.png"
    argv = ["sweep", str(SCENES / scene), "--duration", "5 ms", "--plot", str(tmp_path / "time.png")]
    assert main(argv + [a.format(out=out) for a in option]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pinmech: error: ") and err.count("\n") == 1
    assert f"{option[0]}: for a driver sweep" in err and "[[task]]" in err and scene in err
    assert list(tmp_path.iterdir()) == []  # refused before anything ran: no figure, no partial file


@pytest.mark.parametrize("option", [["--duration", "1 s"], ["--step", "1 ms"], ["--scheme", "rk4"], ["--gain", "2"]],
                         ids=lambda o: o[0])
def test_a_driven_scene_refuses_the_options_of_a_task(option, tmp_path, capsys):
    assert main(["sweep", str(SCENES / "r_rtr.toml"), "--csv", str(tmp_path / "s.csv"), *option]) == 2
    assert f"{option[0]}: for a task ([[task]])" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("option", "needs"), [
    (["--links", "B"], "--plot FILE"), (["--angles", "wrapped"], "--plot FILE"),
    (["--points", "D"], "--plot FILE or --paths FILE"), (["--path-plane", "3d"], "--plot FILE or --paths FILE"),
], ids=lambda o: o[0] if isinstance(o, list) else "")
def test_a_figure_setting_without_its_figure_is_refused(option, needs, tmp_path, capsys):
    assert main(["sweep", str(SCENES / "r_rtr.toml"), "--csv", str(tmp_path / "s.csv"), *option]) == 2
    err = capsys.readouterr().err
    assert f"{option[0]}: a setting of a figure" in err and f"add {needs}" in err
    assert list(tmp_path.iterdir()) == []


def test_links_with_only_the_paths_figure_are_refused(tmp_path, capsys):
    """The paths figure draws points, not link angles: --links would change nothing."""
    assert main(["sweep", str(SCENES / "four_bar.toml"), "--paths", str(tmp_path / "p.png"), "--links", "rocker"]) == 2
    assert "--links: a setting of a figure" in capsys.readouterr().err


@pytest.mark.parametrize("how", [["--static"], ["--set", "forces.static=true"]], ids=["flag", "scene"])
def test_a_flywheel_in_statics_is_refused(how, tmp_path, capsys):
    """Statics has no motion, so no energy fluctuation to size a flywheel from."""
    argv = ["sweep", str(SCENES / "slider_crank_dynamic.toml"), "--steps", "5", "--csv", str(tmp_path / "s.csv"),
            "--flywheel", "1 kg*m^2", *how]
    assert main(argv) == 2
    assert "--flywheel: a flywheel is sized from the energy a moving cycle stores" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_the_options_a_scene_can_honour_still_draw(tmp_path):
    """The same options where they apply: each figure is written."""
    pytest.importorskip("matplotlib", reason='needs pip install "pinmech[plot]"')
    assert main(["sweep", str(SCENES / "planar_arm.toml"), "--duration", "5 ms", "--plot", str(tmp_path / "t.png"),
                 "--csv", str(tmp_path / "t.csv")]) == 0
    assert main(["sweep", str(SCENES / "four_bar.toml"), "--steps", "13", "--paths", str(tmp_path / "p.png"),
                 "--points", "P", "--path-plane", "xy", "--plot", str(tmp_path / "s.png"), "--links", "rocker",
                 "--angles", "wrapped"]) == 0
    assert {p.name for p in tmp_path.iterdir()} == {"t.png", "t.csv", "p.png", "s.png"}
