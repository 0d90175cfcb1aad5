"""Every example of README.md and docs/ runs: each code block is executed (or, for a file's
text, read by the reader it is written for), and every printed output shown is what the
command prints now (scripts/docs_outputs.py wrote it; nothing is pasted by hand).

Blocks by language: `bash` lines are run (`pinmech ...` in-process from a scratch folder
beside models/, with small sizes for long sweeps); `python` blocks are executed; `toml`
blocks are parsed, and a whole scene is solved, a hand file checked, a linkage or study
file read; `xml` and `yaml` are parsed; `text` is printed output and must be a generated
file (README: after an `<!-- output: NAME -->` marker); `none` is a drawing, not code.
The reference for each is the run itself: no exception and the exit code the page implies.
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import pytest
from markdown_it import MarkdownIt

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md"] + sorted(p for p in (ROOT / "docs").rglob("*.md") if "_generated" not in p.parts)
LANGUAGES = {"bash", "python", "toml", "xml", "yaml", "text", "none"}

#: Commands shown but not run here, and why.
NOT_RUN = {
    "pip": "installs: .ci/run installs the package with the README's test command",
    "python3 -m venv": "installs: .ci/run runs the README's test command itself",
    ".venv/bin/pip": "installs: .ci/run runs the README's test command itself",
    "source": "a shell's environment",
    "python -m pytest": "the test suite itself",
    ".venv/bin/python -m pytest": "the test suite itself",
    "python -m sphinx": "tests/test_docs_build.py builds the site",
    "python -m http.server": "a server that runs until stopped",
    "pinmech view": "a live meshcat server that runs until stopped (tests/test_view_server.py)",
    "pinmech design": "a page's server that runs until stopped (tests/test_design_page*.py)",
    "python scripts/": "benchmarks and picture scripts: minutes each (tests/test_scripts.py runs the quick ones)",
    ".venv/bin/python scripts/": "benchmarks: minutes each (tests/test_scripts.py runs the quick ones)",
    "dask": "a cluster's processes",
}

#: Long commands run with small sizes: the option added unless the command gives it.
SMALL = {"sweep": ("--steps", "13"), "animate": ("--steps", "5"), "study": ("--workers", "0")}
#: A grid study (a workspace or actuator map) runs on a grid of at most this many points an
#: axis, its area or volume refined to this relative bound: the same file, commands and code
#: paths as the page's (the boundary's cells still halved), on a coarser grid (the maps'
#: numbers are checked in tests/test_workspace_*.py).
SMALL_GRID, SMALL_BOUND = 9, "0.5"


def _small_studies(text: str) -> str:
    """`text` with each bundled grid study it names (models/studies/NAME.toml with a grid
    `count`) replaced by a copy in the scratch folder whose counts are at most SMALL_GRID."""
    for name in sorted(set(re.findall(r"models/studies/(\w+)\.toml", text))):
        source = (ROOT / "models" / "studies" / f"{name}.toml").read_text(encoding="utf-8")
        small = re.sub(r"\bcount = (\d+)", lambda m: f"count = {min(int(m.group(1)), SMALL_GRID)}", source)
        small = re.sub(r"\b(area|volume)_tolerance = [0-9.e-]+", rf"\1_tolerance = {SMALL_BOUND}", small)
        if small == source or "[workspace]" not in source and "[actuators]" not in source:
            continue
        Path("small_studies").mkdir(exist_ok=True)
        Path("small_studies", f"{name}.toml").write_text(small, encoding="utf-8")
        text = text.replace(f"models/studies/{name}.toml", f"small_studies/{name}.toml")
    return text


@dataclass(frozen=True)
class Block:
    page: Path
    line: int
    language: str
    text: str
    before: str  # the page's text before the block (for README's output markers)

    def __str__(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}:{self.language}"


def _blocks() -> list[Block]:
    found = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        lines = text.splitlines(keepends=True)
        for token in MarkdownIt("commonmark").parse(text):
            if token.type != "fence" or token.info.startswith("{"):
                continue
            start = token.map[0]
            found.append(Block(page, start + 1, token.info.split()[0] if token.info else "",
                               token.content, "".join(lines[:start])))
    return found


BLOCKS = _blocks()


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    """A folder beside the bundled models: models/ linked, and the files of models/ linked
    one by one too (scenes/ a real folder holding links to the bundled scenes), so a scene
    written into scenes/ finds "../r_rtr.urdf" and a hand file finds "r_rtr.toml"."""
    (tmp_path / "models").symlink_to(ROOT / "models")
    for entry in (ROOT / "models").iterdir():
        if entry.name != "scenes":
            (tmp_path / entry.name).symlink_to(entry)
    (tmp_path / "scenes").mkdir()
    for entry in (ROOT / "models" / "scenes").iterdir():
        (tmp_path / "scenes" / entry.name).symlink_to(entry)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    return tmp_path


def _commands(script: str) -> list[list[str]]:
    """The commands of a bash block, as argument lists: continuation lines joined, comments
    dropped, `a && b` two commands."""
    commands: list[list[str]] = []
    for line in script.replace("\\\n", " ").splitlines():
        words = shlex.split(line, comments=True)
        while words:
            cut = words.index("&&") if "&&" in words else len(words)
            commands.append(words[:cut])
            words = words[cut + 1:]
    return commands


def _pinmech(argv: list[str]) -> tuple[int, str]:
    from pinmech.cli import main

    command = argv[0] if argv else ""
    task = command in ("sweep", "animate") and "[[task]]" in Path(argv[1]).read_text(encoding="utf-8")
    if command in SMALL and SMALL[command][0] not in argv and not task:  # a task scene: followed in time
        argv = [*argv, *SMALL[command]]
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
        code = main(argv)
    return code, out.getvalue()


def _run_bash(block: Block) -> None:
    for argv in _commands(_small_studies(block.text)):
        command = shlex.join(argv)
        if any(command.startswith(prefix) for prefix in NOT_RUN):
            continue
        assert argv[0] in ("pinmech", ".venv/bin/pinmech"), f"{block}: no rule to run {command!r}"
        code, out = _pinmech(argv[1:])
        allowed = (0, 1) if argv[1] == "check" else (0,)  # check: 1 = a printed value is wrong
        assert code in allowed, f"{block}: {command!r} exited {code}:\n{out}"


def _run_toml(block: Block, scratch: Path) -> None:
    data = tomllib.loads(block.text)
    if {"urdf", "linkage", "mjcf", "robot"} & data.keys():
        scene = scratch / "scenes" / "from_docs.toml"
        scene.write_text(block.text, encoding="utf-8")
        code, out = _pinmech(["solve", str(scene)])
        assert code == 0, f"{block}: the scene does not solve (exit {code}):\n{out}"
    elif "value" in data and "scene" in data:
        hand = scratch / "scenes" / "from_docs.hand.toml"
        hand.write_text(block.text, encoding="utf-8")
        code, out = _pinmech(["check", str(hand)])
        assert code in (0, 1), f"{block}: the hand file is refused (exit {code}):\n{out}"
    elif "joints" in data:
        from pinmech.model.linkage import parse_linkage

        path = scratch / "from_docs_linkage.toml"
        path.write_text(block.text, encoding="utf-8")
        assert parse_linkage(path).links


def _run_xml(block: Block) -> None:
    try:
        ET.fromstring(block.text)
    except ET.ParseError:  # a fragment: several elements, or a comment before one
        ET.fromstring(f"<robot>{block.text}</robot>")


_MARKER = re.compile(r"<!-- output: (\w+) -->\n$")


def _check_text(block: Block) -> None:
    marker = _MARKER.search(block.before)
    assert block.page.name == "README.md" and marker, (
        f"{block}: printed output must come from scripts/docs_outputs.py (a literalinclude of "
        "docs/_generated in the docs; an <!-- output: NAME --> marker in the README)")
    generated = (ROOT / "docs" / "_generated" / f"{marker.group(1)}.txt").read_text(encoding="utf-8")
    assert block.text == generated, f"{block}: run python scripts/docs_outputs.py"


#: Blocks whose commands take more than a few seconds even at small sizes (a 2000-variant
#: tolerance study, a 169-point grid): marked slow (`pytest -m "not slow"` leaves them out).
LONG = ("pinmech study models/studies/four_bar_tolerance.toml", "pinmech study models/studies/four_bar_grid.toml",
        "models/studies/five_bar_workspace.toml", "models/studies/delta_workspace.toml",  # ~4 min each
        "models/studies/five_bar_actuators.toml")


def _cases() -> list:
    return [pytest.param(b, id=str(b), marks=[pytest.mark.slow] if any(c in b.text for c in LONG) else [])
            for b in BLOCKS]


@pytest.mark.parametrize("block", _cases())
def test_the_example_runs(block: Block, scratch: Path) -> None:
    assert block.language in LANGUAGES, f"{block}: a code block needs a language, one of {sorted(LANGUAGES)}"
    if block.language == "bash":
        _run_bash(block)
    elif block.language == "python":
        scope: dict = {"__name__": "__docs__"}
        exec(compile(_small_studies(block.text), str(block), "exec"), scope)  # noqa: S102
    elif block.language == "toml":
        _run_toml(block, scratch)
    elif block.language == "xml":
        _run_xml(block)
    elif block.language == "yaml":
        import yaml

        assert yaml.safe_load(block.text) is not None
    elif block.language == "text":
        _check_text(block)


def _normalised(text: str) -> str:
    """Rounding-level residuals (1e-13 and below) and the last digits of full-precision
    floats (JSON's 17 digits) differ from machine to machine: compared to 10 digits."""
    text = re.sub(r"\b\d(\.\d+)?e-(1[3-9]|[2-9]\d|\d{3})\b", "<rounding>", text)
    return re.sub(r"-?\d+\.\d{11,}(e[-+]?\d+)?", lambda m: f"{float(m.group()):.10g}", text)


@pytest.mark.slow
def test_the_generated_outputs_are_what_the_commands_print_now() -> None:
    """docs/_generated holds what each command prints today (residuals at rounding aside)."""
    sys.path.insert(0, str(ROOT / "scripts"))
    import docs_outputs

    for path, text in docs_outputs.expected().items():
        assert path.exists(), f"{path.relative_to(ROOT)} is missing: run python scripts/docs_outputs.py"
        assert _normalised(path.read_text(encoding="utf-8")) == _normalised(text), (
            f"{path.relative_to(ROOT)} is out of date: run python scripts/docs_outputs.py")


def test_every_page_is_reached_and_every_include_exists() -> None:
    """Each docs page's includes name files that exist (the build checks the rest)."""
    for page in PAGES[1:]:
        text = page.read_text(encoding="utf-8")
        for target in re.findall(r"```\{(?:literalinclude|include)\} (\S+)", text):
            assert (page.parent / target).resolve().exists(), f"{page.relative_to(ROOT)}: {target}"


def test_the_scene_reference_lists_every_key_a_scene_may_have() -> None:
    """docs/reference/scene.md's key table holds the keys the scene reader knows, no more."""
    from pinmech.io.scene import KNOWN_KEYS

    text = (ROOT / "docs" / "reference" / "scene.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"^\| `\[{0,2}(\w+)(?:\.\w+)?\]{0,2}` \|", text, re.M))
    assert listed == KNOWN_KEYS


def test_the_readme_links_reach_files_and_anchors() -> None:
    """Every relative link of README.md names a file of the repository (a page of docs/, an
    image), and an in-page link a heading of the README (GitHub's anchor of it)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    anchors = {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-")
               for h in re.findall(r"^#+ (.*)$", text, re.M)}
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"\w+://", target):
            continue
        if target.startswith("#"):
            assert target[1:] in anchors, target
        else:
            assert (ROOT / target.split("#")[0]).exists(), target
