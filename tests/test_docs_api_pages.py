"""The API reference is one page a task (docs/reference/api/*.md): every public name of
`pinmech` documented on exactly one of them, every page reachable from reference/api.md;
and a class's fields, listed in its docstring's "Attributes:" section, are not listed a
second time as members (docs/conf.py's hooks; the built pages are checked in
tests/test_docs_build.py)."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pinmech

ROOT = Path(__file__).resolve().parents[1]
API = ROOT / "docs" / "reference" / "api"


def _documented() -> dict[str, list[str]]:
    """Public name -> the task pages whose autodoc directives name it."""
    found: dict[str, list[str]] = {}
    for page in sorted(API.glob("*.md")):
        for name in re.findall(r"^\.\. auto(?:class|function|exception):: pinmech\.(\w+)\s*$",
                               page.read_text(encoding="utf-8"), re.M):
            found.setdefault(name, []).append(page.stem)
    return found


def test_every_public_name_is_on_exactly_one_task_page() -> None:
    documented = _documented()
    public = set(pinmech.__all__) - {"__version__"}
    assert sorted(public - documented.keys()) == [], "public names on no API page"
    assert sorted(documented.keys() - public) == [], "API pages name what pinmech does not export"
    assert {n: pages for n, pages in documented.items() if len(pages) > 1} == {}


def test_every_task_page_is_in_the_reference_toctree() -> None:
    index = (ROOT / "docs" / "reference" / "api.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"^api/(\w+)$", index, re.M))
    assert listed == {p.stem for p in API.glob("*.md")}


def test_an_attributes_entry_naming_several_fields_becomes_one_entry_a_field() -> None:
    """napoleon reads "by, on: ..." as one field named "on" of type "by,": the hook splits
    it, and the names it finds are the ones not listed again as members."""
    sys.path.insert(0, str(ROOT / "docs"))
    import conf

    doc = ["The wrench at a joint.", "", "Attributes:", "    joint: its name.",
           "    by, on: the link that exerts the wrench,", "        the link it acts on.",
           "    residual, iterations,", "        condition: per pose.", "", "Returns:", "    a, b: not fields."]
    split = conf._one_name_each(doc)
    assert split[3:10] == ["    joint: its name.", "    by: the link that exerts the wrench,",
                           "        the link it acts on.", "    on: see ``by``.", "    residual: per pose.",
                           "    iterations: see ``residual``.", "    condition: see ``residual``."]
    assert split[-1] == "    a, b: not fields."
    assert conf._attribute_names(split) == ["joint", "by", "on", "residual", "iterations", "condition"]
