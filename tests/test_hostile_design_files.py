"""Study, workspace and synthesis files under attack: NaN, infinities, 1e308 and 1e-300,
inverted or equal bounds, sigma <= 0, counts whose arrays would exhaust memory, coincident
and collinear targets. Each is one line naming the file and the key, exit 4, read from the
file before anything is built or allocated (the whole command within 5 s: the memory
attacks ran past a minute, or to tens of GiB, before).
"""

from __future__ import annotations

import math
import re
import time
from pathlib import Path

import pytest

from pinmech.cli import main
from pinmech.counts import MAX_BYTES

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "models" / "studies"
SYNTHESES = ROOT / "models" / "synthesis"
GIB = f"{MAX_BYTES / 2**30:g} GiB"

#: (bundled file, text in it, its replacement, the key named, a word of the message)
STUDY_ATTACKS = [
    ("four_bar_sensitivity", "steps = 73", "steps = nan", "steps", "whole number"),
    ("four_bar_sensitivity", "steps = 73", "steps = 1e308", "steps", "whole number"),
    ("four_bar_tolerance", 'sigma = "0.05 mm"', 'sigma = "nan mm"', "params.ground.sigma", "finite"),
    ("four_bar_tolerance", 'sigma = "0.05 mm"', 'sigma = "inf mm"', "params.ground.sigma", "finite"),
    ("four_bar_tolerance", 'sigma = "0.05 mm"', 'sigma = "1e308 mm"', "params.ground.sigma", "overflow"),
    ("four_bar_tolerance", 'sigma = "0.05 mm"', 'sigma = "1e-300 mm"', "params.ground.sigma", "underflow"),
    ("four_bar_tolerance", 'sigma = "0.05 mm"', 'sigma = "0 mm"', "params.ground.sigma", "positive"),
    ("four_bar_tolerance", 'sigma = "0.05 mm"', 'sigma = "-0.05 mm"', "params.ground.sigma", "positive"),
    ("four_bar_tolerance", 'tolerance = "0.1 mm"\n\n[params.ground]', 'tolerance = "0.1 mm"\nk = nan\n\n[params.ground]',
     "params.crank.k", "sigmas"),
    ("four_bar_tolerance", 'sigma = "0.05 mm"', 'sigma = "0.05 mm"\nbounds = ["100 mm", "100 mm"]',
     "params.ground.bounds", "not below"),
    ("four_bar_tolerance", 'sigma = "0.05 mm"', 'sigma = "0.05 mm"\nbounds = ["101 mm", "99 mm"]',
     "params.ground.bounds", "not below"),
    ("four_bar_tolerance", 'sigma = "0.05 mm"', 'sigma = "0.05 mm"\nbounds = ["-inf mm", "inf mm"]',
     "params.ground.bounds", "finite"),
    ("four_bar_tolerance", 'sigma = "0.05 mm"', 'sigma = "0.05 mm"\nnominal = "nan mm"', "params.ground.nominal",
     "finite"),
    ("four_bar_tolerance", "samples = 2000", "samples = 10000000", "samples", GIB),
    ("four_bar_tolerance", "steps = 73", "steps = 100000", "samples", GIB),
    ("four_bar_grid", 'from = "20 mm"', 'from = "nan mm"', "grid.crank.from", "finite"),
    ("four_bar_grid", 'from = "20 mm"', 'from = "80 mm"', "grid.crank", "not below"),
    ("four_bar_grid", 'from = "20 mm"', 'from = "90 mm"', "grid.crank", "not below"),
    ("four_bar_grid", "count = 13", "count = 1000000", "grid", "more than"),
    ("four_bar_grid", "steps = 73", "steps = 100000", "grid", GIB),
    ("five_bar_workspace", "count = 45", "count = 0", "workspace.x.count", "whole number"),
    ("five_bar_workspace", 'from = "-60 mm"', 'from = "nan mm"', "workspace.x.from", "finite"),
    ("five_bar_workspace", 'from = "-60 mm"', 'from = "160 mm"', "workspace.x", "not below"),
    ("five_bar_workspace", 'length = "60 mm"', 'length = "0 mm"', "workspace.length", "positive"),
    ("five_bar_workspace", "area_tolerance = 0.05", "area_tolerance = nan", "workspace.area_tolerance", "share"),
    ("five_bar_actuators", 'from = "-180 deg", to = "180 deg", count = 61 }\nmot2',
     'from = "-1e308 deg", to = "1e308 deg", count = 61 }\nmot2', "workspace.actuators.mot1.from", "overflow"),
    ("five_bar_actuators", 'from = "-180 deg", to = "180 deg", count = 61 }\nmot2',
     'from = "nan deg", to = "180 deg", count = 61 }\nmot2', "workspace.actuators.mot1.from", "finite"),
    ("five_bar_actuators", 'from = "-180 deg", to = "180 deg", count = 61 }\nmot2',
     'from = "0 deg", to = "0 deg", count = 61 }\nmot2', "workspace.actuators.mot1", "not below"),
]

_FIRST = 'targets = [\n  ["102.112 mm", "32.029 mm"],'
_ON_A_LINE = "targets = [" + ", ".join(f'["20 mm", "{20 + 5 * i} mm"]' for i in range(7)) + "]"
_NEAR_LINE = "targets = [" + ", ".join(f'["{20 + 1e-12 * i * i} mm", "{20 + 5 * i} mm"]' for i in range(8)) + "]"
SYNTH_ATTACKS = [
    ("four_bar_path", 'crank = ["10 mm", "80 mm"]', 'crank = ["nan mm", "80 mm"]', "bounds.crank", "finite"),
    ("four_bar_path", 'crank = ["10 mm", "80 mm"]', 'crank = ["10 mm", "1e308 mm"]', "bounds.crank", "overflow"),
    ("four_bar_path", 'crank = ["10 mm", "80 mm"]', 'crank = ["10 mm", "10 mm"]', "bounds.crank", "not below"),
    ("four_bar_path", 'crank = ["10 mm", "80 mm"]', 'crank = ["1e-300 mm", "1e-299 mm"]', "bounds.crank", "underflow"),
    ("four_bar_path", _FIRST, _FIRST + ' ["102.112 mm", "32.029 mm"],', "targets[1]", "place"),
    ("four_bar_path", _FIRST, _FIRST + ' ["102.112 mm", "32.0290001 mm"],', "targets[1]", "place"),
    ("four_bar_path", _FIRST, 'targets = [\n  ["nan mm", "32.029 mm"],', "targets[0]", "finite"),
    ("four_bar_path", _FIRST, 'targets = [\n  ["1e308 mm", "32.029 mm"],', "targets[0]", "overflow"),
    ("four_bar_path", "population = 15", "population = 1000\n" + "targets = [" + ", ".join(
        f'["{i} mm", "{i * i % 97} mm"]' for i in range(300)) + "]\n#", "population", GIB),
]


def _edited(source: Path, old: str, new: str, tmp_path: Path) -> Path:
    text = source.read_text(encoding="utf-8")
    assert old in text, (source, old)
    text = re.sub(r'scene = "\.\./', f'scene = "{source.parents[1].as_posix()}/', text.replace(old, new, 1))
    path = tmp_path / f"attack_{source.name}"
    path.write_text(text, encoding="utf-8")
    return path


def _refused(argv: list[str], path: Path, key: str, word: str, capsys) -> None:
    began = time.monotonic()
    code = main(argv)
    seconds = time.monotonic() - began
    err = capsys.readouterr().err.strip()
    assert code == 4 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert f"{path}, {key}:" in err and word in err, err
    assert seconds < 5, seconds


@pytest.mark.parametrize("base, old, new, key, word", STUDY_ATTACKS,
                         ids=[f"{b}: {n.splitlines()[-1][:40]}" for b, _, n, _, _ in STUDY_ATTACKS])
def test_a_hostile_study_file_is_one_line_before_any_work(base, old, new, key, word, tmp_path, capsys):
    path = _edited(STUDIES / f"{base}.toml", old, new, tmp_path)
    _refused(["study", str(path), "--workers", "0", "--quiet"], path, key, word, capsys)


@pytest.mark.parametrize("base, old, new, key, word", SYNTH_ATTACKS,
                         ids=[f"{b}: {n.splitlines()[-1][:40]}" for b, _, n, _, _ in SYNTH_ATTACKS])
def test_a_hostile_synthesis_file_is_one_line_before_any_work(base, old, new, key, word, tmp_path, capsys):
    if new.startswith("population = 1000"):  # drop the bundled targets: the attack gives its own
        text = (SYNTHESES / f"{base}.toml").read_text(encoding="utf-8")
        start = text.index("targets = [")
        old, new = text[start:text.index("]\n\n", start) + 2], new.replace("\n#", "\n")
        base_path = tmp_path / "base.toml"
        base_path.write_text(text.replace("population = 15", ""), encoding="utf-8")
        path = _edited(base_path, old, new, tmp_path)
    elif new.startswith(("targets = [\n", "targets = [" + '["20')):
        path = _edited(SYNTHESES / f"{base}.toml", old, new, tmp_path)
    else:
        path = _edited(SYNTHESES / f"{base}.toml", old, new, tmp_path)
    _refused(["synth", str(path)], path, key, word, capsys)


def _with_targets(tmp_path, points: list[tuple[float, float]]) -> Path:
    """The bundled four-bar path file with its whole target list replaced by `points` [mm]."""
    source = SYNTHESES / "four_bar_path.toml"
    text = source.read_text(encoding="utf-8")
    old = re.search(r"targets = \[.*?\n\]", text, re.S).group(0)
    return _edited(source, old, "targets = [" + ", ".join(f'["{x!r} mm", "{y!r} mm"]' for x, y in points) + "]",
                   tmp_path)


def _on_a_line(n: int, slope: float, off: float = 0.0) -> list[tuple[float, float]]:
    """n targets 5 mm apart along y = 20 + slope (x - 20) [mm], the k-th moved off it by
    off k (k - n + 1) mm (a parabola through the first and last: no three on one line)."""
    return [(20.0 + 5 * k, 20.0 + slope * 5 * k + off * k * (k - n + 1)) for k in range(n)]


@pytest.mark.parametrize("n, slope", [(6, 0.0), (6, 1e6), (5, 0.3)])
def test_up_to_six_collinear_targets_a_four_bar_can_meet_are_not_refused_by_the_reader(tmp_path, n, slope):
    """A four-bar's coupler curve is a sextic, which meets a line in six points: six
    collinear targets or fewer are the search's business."""
    from pinmech.design.synthesis.file import load_synthesis

    assert len(load_synthesis(_with_targets(tmp_path, _on_a_line(n, slope))).targets) == n


@pytest.mark.parametrize("n, slope, off", [(7, 0.0, 0.0), (7, 1e6, 0.0), (10, -0.3, 0.0), (8, 2.0, 1e-13)],
                         ids=["seven on y = 20", "seven near vertical", "ten sloping", "eight 1e-13 mm off"])
def test_more_than_six_collinear_targets_for_a_four_bar_are_one_line_before_any_work(tmp_path, capsys, n, slope, off):
    """Seven or more targets on one line (to 1e-9 of their extent: rounding of the file's
    numbers) are more than a sextic meets: refused before the search, the count said."""
    path = _with_targets(tmp_path, _on_a_line(n, slope, off))
    _refused(["synth", str(path)], path, "targets", f"the {n} targets lie on one line", capsys)


def test_seven_targets_off_a_line_by_more_than_rounding_are_the_searchs_business(tmp_path):
    """Seven targets on a parabola 1e-4 mm off their chord at most (1e-7 of their 30 mm
    extent, above the 1e-9 collinear share): not one line, so not refused."""
    from pinmech.design.synthesis.file import load_synthesis

    assert len(load_synthesis(_with_targets(tmp_path, _on_a_line(7, 0.0, 1e-5))).targets) == 7


def test_collinear_targets_of_a_slider_crank_are_its_slider_s_line(tmp_path):
    from pinmech.design.synthesis.file import load_synthesis

    text = (SYNTHESES / "slider_crank_path.toml").read_text(encoding="utf-8")
    start = text.index("targets = [")
    old = text[start:text.index("]\n", text.index("\n", start) + 1) + 1]
    path = _edited(SYNTHESES / "slider_crank_path.toml", old, _ON_A_LINE, tmp_path)
    assert len(load_synthesis(path).targets) == 7


def test_a_linkage_with_a_link_of_no_length_is_refused_naming_the_link(tmp_path, capsys):
    """crank = "0 mm" draws A on O2: the crank has no length and its two joints coincide
    (another linkage). Refused in one line naming the link, both pins and the gap (it swept,
    exit 0, a mechanism without its crank)."""
    text = (ROOT / "models" / "linkages" / "four_bar.toml").read_text(encoding="utf-8")
    assert 'crank = "40 mm"' in text
    (tmp_path / "fb.toml").write_text(text.replace('crank = "40 mm"', 'crank = "0 mm"'), encoding="utf-8")
    scene = tmp_path / "scene.toml"
    scene.write_text('title = "s"\nlinkage = "fb.toml"\n[drivers.O2]\nangle = "0 deg"\nspeed = "60 rpm"\n')
    assert main(["sweep", str(scene), "--steps", "5", "--csv", str(tmp_path / "s.csv")]) == 3
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "[links] crank: its pins O2 and A are drawn 0 mm apart" in err, err


@pytest.mark.parametrize("base", ["four_bar_drawn_tolerance", "four_bar_drawn_sensitivity"])
def test_a_study_param_that_draws_a_link_of_no_length_is_refused_before_the_run(tmp_path, capsys, base):
    """A study's nominal crank = 0 mm over a drawn linkage: refused in one line naming the
    study file, the param, its value and the link (exit 4: the study file's value; it ran,
    and reported σ of a linkage without its crank)."""
    path = _edited(STUDIES / f"{base}.toml", 'param = "crank"', 'param = "crank"\nnominal = "0 mm"', tmp_path)
    began = time.monotonic()
    assert main(["study", str(path), "--workers", "0", "--quiet"]) == 4
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"{path}, params.crank.nominal:" in err, err
    assert "crank = 0 mm" in err and "[links] crank" in err, err
    assert time.monotonic() - began < 5


def test_an_angle_param_in_a_drawing_that_fails_is_named_in_degrees():
    """The message naming the values a drawing failed with shows an angle param (gamma, a
    polar construction's angle) in deg, not its radians times 1000 as 'mm'."""
    from pinmech.design.study.drawn_params import Drawing
    from pinmech.exceptions import ModelError
    from pinmech.io.scene import Scene
    from pinmech.io.scene_model import load_mechanism

    scene = Scene.load(ROOT / "models" / "scenes" / "four_bar_coupler_point.toml")
    drawing = Drawing(scene, load_mechanism(scene), "test")
    with pytest.raises(ModelError, match=r"coupler = 300 mm, gamma = 30 deg"):
        drawing.write({**drawing.values, "coupler": 0.3, "gamma": math.radians(30.0)})


def test_a_study_nominal_whose_compass_circles_do_not_meet_is_refused_before_the_run(tmp_path, capsys):
    """coupler = 300 mm with rocker 80 mm: |A O4| = 60 mm < 300 - 80, the circles about A and
    O4 do not meet, B cannot be drawn. One line naming the study file, the param, the joint
    and the radii (exit 4)."""
    path = _edited(STUDIES / "four_bar_drawn_tolerance.toml", 'param = "coupler"',
                   'param = "coupler"\nnominal = "300 mm"', tmp_path)
    assert main(["study", str(path), "--workers", "0", "--quiet"]) == 4
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"{path}, params.coupler.nominal:" in err, err
    assert "[joints] B" in err and "0.3 m and 0.08 m" in err, err


def test_tolerance_variants_that_cannot_be_drawn_are_counted_not_fatal(tmp_path, capsys):
    """A crank tolerance of 150 mm over a 40 mm crank: many variants draw B from circles
    that do not meet (|A O4| beyond coupler + rocker). Each is a failed variant, "cannot
    assemble", and sigma is over the survivors, counted (the first such variant ended the
    study, exit 3)."""
    path = _edited(STUDIES / "four_bar_drawn_tolerance.toml", 'tolerance = "0.1 mm"', 'tolerance = "150 mm"', tmp_path)
    path.write_text(path.read_text(encoding="utf-8").replace("samples = 2000", "samples = 100"), encoding="utf-8")
    assert main(["study", str(path), "--workers", "0", "--quiet"]) == 0
    out = capsys.readouterr()
    text = out.out + out.err
    assert "failed: cannot assemble:" in text and "variants that solved" in text, text[-2000:]
