"""docs/explanation/layout.md lists the package as it is: every module once under its own
package, none that is gone. The reference is the file tree of pinmech/ itself, walked here
(not the script's own listing), and the generated list must be what
scripts/layout_modules.py writes now."""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "explanation" / "layout.md"
GENERATED = ROOT / "docs" / "_generated" / "layout_modules.md"


def _listed() -> set[str]:
    """The modules the generated list names, as paths under pinmech/."""
    found, package = set(), None
    for line in GENERATED.read_text(encoding="utf-8").splitlines():
        heading = re.match(r"## `pinmech((?:\.\w+)*)`", line)
        if heading:
            package = heading.group(1).replace(".", "/").lstrip("/")
        row = re.match(r"\| `(\w+\.py)` \|", line)
        if row:
            found.add(str(Path(package or ".", row.group(1))))
    return found


def test_every_module_of_the_package_is_listed_once_and_nothing_else() -> None:
    on_disk = {str(p.relative_to(ROOT / "pinmech")) for p in (ROOT / "pinmech").rglob("*.py")
               if p.name not in ("__init__.py", "__main__.py")}
    listed = _listed()
    assert on_disk - listed == set(), f"modules missing from the layout: {sorted(on_disk - listed)}"
    assert listed - on_disk == set(), f"the layout lists modules that are gone: {sorted(listed - on_disk)}"


def test_the_generated_list_is_what_the_script_writes_now() -> None:
    sys.path.insert(0, str(ROOT / "scripts"))
    import layout_modules

    assert GENERATED.read_text(encoding="utf-8") == layout_modules.text(), (
        "docs/_generated/layout_modules.md is out of date: run python scripts/layout_modules.py")


def test_the_page_includes_the_list_and_names_no_module_that_is_gone() -> None:
    text = PAGE.read_text(encoding="utf-8")
    assert "{include} ../_generated/layout_modules.md" in text
    modules = {p.name for p in (ROOT / "pinmech").rglob("*.py")}
    named = set(re.findall(r"(?<![/\w])(\w+\.py)\b", text))  # scripts/x.py: not a module
    assert named <= modules, f"layout.md names modules that do not exist: {sorted(named - modules)}"
