"""What `pinmech solve` imports and builds (issue 13 item 4: start-up time), guarded without
timing anything: the modules a plain solve does not need stay unimported, and the CLI
parses a subcommand with that subcommand's parser alone, saying the same on an error."""

from __future__ import annotations

import ast
import contextlib
import io
import json
import subprocess
import sys

import pytest

import pinmech
from pinmech import cli

#: Modules a plain `pinmech solve` of a URDF scene must not import: each is imported where
#: it is used (forces, task scenes, sweeps, drawings, linkage files, MJCF, sidecars, hand
#: checks, output files, JSON), so the command does not pay for it.
NOT_FOR_A_SOLVE = (
    "pinmech.io.analysis_task", "pinmech.solve.rates",  # task scenes ([[task]])
    "pinmech.solve.forces", "pinmech.io.forces_scene", "pinmech.solve.forces_report", "pinmech.draw.forces_sweep",
    "pinmech.solve.flywheel",  # force analyses
    "pinmech.io.sweep", "pinmech.solve.cycle", "pinmech.solve.batch", "pinmech.solve.hermite", "pinmech.solve.manifold",
    "pinmech.io.tables", "pinmech.outputs", "pinmech.solve.path",  # sweeps, paths, their output files
    "pinmech.draw", "pinmech.draw.report_page", "pinmech.draw.polygon", "pinmech.draw.plot", "pinmech.model.link_nodes",
    "pinmech.io.check", "pinmech.model.linkage", "pinmech.model.linkage_urdf", "pinmech.model.mjcf", "pinmech.model.sidecar",
    "json", "pint", "matplotlib", "meshcat",
    "pydantic",  # no longer a dependency: scene tables are msgspec Structs (building pydantic models cost ~0.15 s)
    "numpy.random",  # sample poses are drawn by pinmech.seeded (numpy.random and its hashlib/secrets: ~10 ms)
    "difflib",  # only for a name that is not a URDF one
    # the other subcommands: each module is imported when its subcommand is chosen
    "pinmech.cli.forces", "pinmech.cli.sweep", "pinmech.cli.path", "pinmech.cli.snapshot", "pinmech.cli.animate",
    "pinmech.cli.polygon", "pinmech.cli.report", "pinmech.cli.view", "pinmech.cli.build", "pinmech.cli.check",
    "pinmech.design.study.cli", "pinmech.design.synthesis.cli",
)

_SOLVE_IN_A_FRESH_PROCESS = """
import contextlib, io, sys
import pinmech.cli
with contextlib.redirect_stdout(io.StringIO()) as out:
    code = pinmech.cli.main(sys.argv[1:])
print(repr({"code": code, "report": out.getvalue(), "modules": sorted(sys.modules)}))
"""


def _solve_in_a_fresh_process(*args: str) -> dict:
    """`main(["solve", *args])` in a fresh interpreter: exit code, report, every module
    imported (read back with `ast.literal_eval`: the harness imports nothing of its own)."""
    done = subprocess.run([sys.executable, "-c", _SOLVE_IN_A_FRESH_PROCESS, "solve", *args],
                          capture_output=True, text=True, check=True)
    return ast.literal_eval(done.stdout)


def test_a_plain_solve_imports_none_of_the_modules_it_does_not_use(r_rtr_scene):
    run = _solve_in_a_fresh_process(str(r_rtr_scene))
    assert run["code"] == 0 and "Accuracy" in run["report"]
    imported = set(run["modules"])
    assert "pinmech.io.analysis" in imported and "pinocchio" in imported  # the solve did run
    assert sorted(imported & set(NOT_FOR_A_SOLVE)) == []


def test_the_json_report_still_imports_json(r_rtr_scene):
    run = _solve_in_a_fresh_process(str(r_rtr_scene), "--json")
    assert run["code"] == 0 and "json" in run["modules"]
    assert json.loads(run["report"])["accuracy"]["newton_iterations"] >= 0


def test_importing_pinmech_imports_its_modules_on_first_use():
    code = ("import sys, pinmech; before = {m for m in sys.modules if m.startswith('pinmech.')}; "
            "pinmech.Sweep; print(sorted(before), 'pinmech.io.sweep' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "['pinmech.exceptions'] True"


def test_every_public_name_resolves_to_its_module():
    for name in pinmech.__all__:
        value = getattr(pinmech, name)
        module = getattr(value, "__module__", None)
        assert name == "__version__" or (module or "").startswith("pinmech."), name
    assert set(pinmech.__all__) <= set(dir(pinmech))
    assert pinmech.Sweep is __import__("pinmech.io.sweep", fromlist=["Sweep"]).Sweep
    with pytest.raises(AttributeError, match="no attribute 'Nothing'"):
        pinmech.Nothing  # noqa: B018


def _parsed(parse, argv: list[str]):
    """What a parse gives: the namespace (its function by name), or the exit code, with
    everything printed."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            args = vars(parse(argv)).copy()
            args["func"] = args["func"].__name__
            result = sorted(args.items())
        except SystemExit as exc:
            result = exc.code
    return result, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("argv", [
    ["solve", "s.toml"], ["solve", "s.toml", "--json", "--angle", "45 deg", "--set", "a=1", "--set", "b=2"],
    ["solve", "s.toml", "--limits", "bad"], ["solve", "s.toml", "extra"], ["solve"], ["solve", "-h"],
    ["solve", "s.toml", "--version"], ["sweep", "s.toml", "--steps", "x"], ["sweep", "-h"],
    ["check", "h.toml", "--slack", "3"], ["build", "l.toml"], ["report", "s.toml", "-o", "r.html", "--steps", "0"],
    [], ["-h"], ["--version"], ["nope", "s.toml"],
])
def test_a_subcommand_parsed_alone_reads_and_says_what_the_full_parser_does(argv, monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")  # both help texts wrapped alike
    assert _parsed(cli.parse_args, argv) == _parsed(lambda a: cli.build_parser().parse_args(a), argv)


def test_a_valid_solve_command_line_builds_the_solve_parser_only(monkeypatch, r_rtr_scene):
    built = []
    build = cli.build_parser

    def recording(command=None, **kwargs):
        built.append(command)
        return build(command, **kwargs)

    monkeypatch.setattr(cli, "build_parser", recording)
    cli.parse_args(["solve", str(r_rtr_scene), "--angle", "45 deg"])
    assert built == ["solve"]
    built.clear()
    with pytest.raises(SystemExit), contextlib.redirect_stderr(io.StringIO()):
        cli.parse_args(["solve", str(r_rtr_scene), "--no-such-option"])
    assert built == ["solve", None]  # the error is the full parser's


def test_loops_of_full_rank_on_their_first_closed_pose_are_not_sampled_around(monkeypatch, models_dir):
    """The mobility check closes one pose; only a rank below the row count (loops that may
    repeat each other) sends it to close neighbouring poses (tests/test_mobility.py)."""
    from pinmech.model import mobility
    from pinmech.model.mechanism import Mechanism

    closings = []
    close = mobility.close_least_squares

    def counting(*args, **kwargs):
        closings.append(1)
        return close(*args, **kwargs)

    monkeypatch.setattr(mobility, "close_least_squares", counting)
    report = mobility.constraint_rank(Mechanism.from_urdf(models_dir / "r_rtr.urdf"))
    assert (report.rank, report.rows, report.redundant, len(closings)) == (2, 2, (), 1)


def test_a_source_tree_without_its_compiled_core_says_so_in_one_line(tmp_path, scenes_dir):
    """`python -m pinmech` run inside a checkout that was installed with `pip install .` imports
    the checkout's source, which has no compiled core beside it: the command says so in one
    line (exit 2) and names the way out, instead of a traceback. (Here the source is copied
    without its core, and the editable install's import hook, which would find the real
    package first, is left out.)"""
    import shutil
    from pathlib import Path

    source = Path(pinmech.__file__).parent
    shutil.copytree(source, tmp_path / "pinmech", ignore=shutil.ignore_patterns("*.so", "*.pyd", "__pycache__", "csrc"))
    run = ("import runpy, sys\n"
           "sys.meta_path[:] = [f for f in sys.meta_path if 'editable' not in getattr(f, '__module__', '')]\n"
           "sys.path.insert(0, sys.argv[1])\n"
           "sys.argv = ['pinmech', 'solve', sys.argv[2]]\n"
           "runpy.run_module('pinmech', run_name='__main__')\n")
    done = subprocess.run([sys.executable, "-c", run, str(tmp_path), str(scenes_dir / "r_rtr.toml")],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stdout[-300:] + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pinmech: error: pinmech's compiled core is missing from")
    assert str(tmp_path / "pinmech") in lines[0] and "pip install -e ." in lines[0]
