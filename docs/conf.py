"""Sphinx configuration of pinmech's documentation site.

Sphinx with MyST (Markdown) and the furo theme, as the Python side of the field documents
itself (Pinocchio's Python bindings, pink, qpsolvers): autodoc reads pinmech's own docstrings
for the API reference, sphinx-argparse reads the CLI's argparse parser, and the pages stay
Markdown files that the tests run (tests/test_docs_examples.py). Built offline with warnings
as errors (tests/test_docs_build.py): no intersphinx, nitpicky references.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).parent / "_ext"))  # cli_parser: the CLI reference

project = "pinmech"
author = "pinmech's authors"
copyright = "pinmech's authors, BSD-3-Clause"  # noqa: A001

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinxarg.ext",
    "sphinx.ext.mathjax",  # the equations (MyST dollarmath), typeset by the reader's browser
]

source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_generated", "Thumbs.db", ".DS_Store"]

myst_enable_extensions = ["colon_fence", "deflist", "dollarmath", "amsmath"]  # $..$, $$..$$: equations as maths
myst_heading_anchors = 3

nitpicky = True
# Names of other packages in signatures and docstrings (numpy, Pinocchio, the standard
# library): intersphinx is off (the build is offline), so they cannot resolve.
nitpick_ignore_regex = [
    (r"py:.*", r"(np|numpy|pin|pinocchio|pint|pathlib|collections|typing|argparse|dask|"
               r"distributed|matplotlib|pandas|pyarrow|scipy|os|io|concurrent)\b.*"),
    (r"py:.*", r"(Path|Sequence|Mapping|Iterable|Iterator|Callable|Any|ndarray|NDArray|"
               r"ArrayLike|Literal|Self|IO|TextIO|Figure|Axes|Model|Data)"),
    # Annotations of typed (msgspec) objects: msgspec's own types, and pinmech's internal
    # entry types named bare in forward references. Dotted names are still checked.
    (r"py:class", r"(Struct|NODEFAULT|Annotated|Union|[A-Z]\w*)"),
    # Types of pinmech's modules that the public API returns but does not export by name.
    (r"py:.*", r"pinmech\.(model|solve|io|design|draw)\..*"),
    (r"py:class", r"(int|float|str|bool|bytes|dict|list|tuple|set|frozenset|object|None|type|"
                  r"Exception|KeyboardInterrupt|ImportError|ValueError|optional)"),
]

autodoc_typehints = "description"
autodoc_typehints_description_target = "documented"
autodoc_member_order = "bysource"
autodoc_default_options = {"undoc-members": False}
napoleon_google_docstring = True
napoleon_numpy_docstring = False
napoleon_use_ivar = True  # a dataclass's "Attributes:" as fields, not a second description
napoleon_use_rtype = False  # "Returns: The solved poses: ..." is prose, not a type


def _plain_text(app, what, name, obj, options, lines) -> None:
    """Docstrings are written for `help()` in Markdown's habits: `|F|` is a magnitude, not
    an RST substitution; `code` is code, not RST's interpreted text; and a property's
    "The URDF file: ..." is a sentence, not napoleon's "type: description"."""
    if what in ("class", "exception"):
        lines[:] = _one_name_each(lines)
        _LISTED[:] = _attribute_names(lines)
    for i, line in enumerate(lines):
        line = line.replace("|", "\\|")
        lines[i] = _CODE.sub(lambda m: f"``{m.group(1)}``" + ("\\ " if m.group(2) else ""), line)
    _literal_blocks(lines)
    if what == "module":
        _module_examples(lines)
    if what in ("property", "attribute", "data") and lines and ":" in lines[0]:
        # U+A789 (a letter that looks like a colon): napoleon then reads no type here
        lines[0] = lines[0].replace(":", "\ua789", 1)


#: The names the class being documented lists in its "Attributes:" section: documented there
#: (napoleon's fields), so not a second time as members (`_skip_listed`). autodoc filters a
#: class's members right after processing the class's own docstring.
_LISTED: list[str] = []


def _attribute_names(lines: list[str]) -> list[str]:
    """The names an "Attributes:" section of a Google-style docstring lists: each entry
    starts at four spaces, and may name several ("by, on: ..."), over more than one line."""
    entries, inside = [], False
    for line in lines:
        if line.strip() == "Attributes:":
            inside = True
        elif inside and line.strip() and not line.startswith(" "):
            inside = False
        elif inside and re.match(r"^ {4}\S", line):
            entries.append(line.strip())
        elif inside and entries and line.strip():
            entries[-1] += " " + line.strip()
    names = []
    for entry in entries:
        head = re.sub(r"\([^)]*\)", "", entry.split(": ", 1)[0] if ": " in entry else entry.rstrip(":"))
        if re.fullmatch(r"\w+(?:,\s*\w+)*", head.strip()):
            names += re.findall(r"\w+", head)
    return names


def _one_name_each(lines: list[str]) -> list[str]:
    """An "Attributes:" entry naming several fields ("by, on: the link that exerts...,
    the link it acts on"; a line may wrap) as one entry a field, as napoleon reads them:
    the first carries the text, the others point to it."""
    out, inside, i = [], False, 0
    while i < len(lines):
        line = lines[i]
        if line.strip() == "Attributes:" or (inside and line.strip() and not line.startswith(" ")):
            inside = line.strip() == "Attributes:"
        head = line
        while inside and re.fullmatch(r" {4}\w+(?:,\s*\w+)*,", head.rstrip()) and i + 1 < len(lines):
            i += 1
            head = head.rstrip() + " " + lines[i].strip()
        names = re.match(r"^ {4}(\w+(?:,\s*\w+)+)\s*:\s(.*)$", head) if inside else None
        if names:
            first, *others = re.findall(r"\w+", names.group(1))
            out.append(f"    {first}: {names.group(2)}")
            while i + 1 < len(lines) and re.match(r"^ {5,}\S", lines[i + 1]):
                i += 1
                out.append(lines[i])
            out += [f"    {other}: see ``{first}``." for other in others]
        else:
            out.append(head if head is not line else line)
        i += 1
    return out


def _skip_listed(app, what, name, obj, skip, options):
    """A member the class's "Attributes:" section already documents is not listed again."""
    return True if what in ("class", "exception") and name in _LISTED else None


def _literal_blocks(lines: list[str]) -> None:
    """A sentence ending in ":" over an indented block (an example, a file's text) shows the
    block as code, as `help()` does: RST's "::" (napoleon's section titles are left alone)."""
    out: list[str] = []
    for i, line in enumerate(lines):
        out.append(line)
        text = line.rstrip()
        if not text.endswith(":") or text.endswith("::") or text.strip()[:-1].lower() in _SECTIONS:
            continue
        following = next((n for n in lines[i + 1:] if n.strip()), "")
        if len(following) - len(following.lstrip()) > len(line) - len(line.lstrip()):
            out[-1] = text + ":"
            if i + 1 < len(lines) and lines[i + 1].strip():
                out.append("")
    lines[:] = out


def _module_examples(lines: list[str]) -> None:
    """A module's docstring shows its file formats as indented blocks after a blank line:
    code, as `help()` shows them (RST's lone "::" paragraph before each)."""
    out: list[str] = []
    for i, line in enumerate(lines):
        starts = (line.startswith(" ") and line.strip() and i > 1 and not lines[i - 1].strip()
                  and not lines[i - 2].startswith(" ") and not lines[i - 2].rstrip().endswith("::"))
        if starts:
            out += ["::", ""]
        out.append(line)
    lines[:] = out


_SECTIONS = {"args", "arguments", "attributes", "example", "examples", "keyword args", "methods",
             "note", "notes", "other parameters", "parameters", "raises", "returns", "return",
             "see also", "todo", "warning", "warnings", "warns", "yields", "yield", "references"}

_CODE = re.compile(r"(?<![`:])`([^`]+)`(?!`)(?=([A-Za-z0-9])?)")


#: Pages other work adds at the top of docs/ (a study kind, synthesis), listed in the home
#: page's "Design studies and synthesis" toctree when they exist: a pattern that matches no
#: page yet lists nothing (a glob toctree would warn, and warnings are errors here). Any
#: other page at the top of docs/ that the home page does not list goes under "More".
OPTIONAL_PAGES = ("studies*.md", "synthesis*.md", "workspace*.md")


def _optional_pages(app, docname: str, source: list[str]) -> None:
    """The home page's toctrees of optional pages, written out from the files present."""
    if docname != "index":
        return
    here = Path(app.srcdir)
    design = sorted({p.stem for pattern in OPTIONAL_PAGES for p in here.glob(pattern)})
    listed = set(re.findall(r"^([\w/]+)$", source[0], re.M))
    others = sorted(p.stem for p in here.glob("*.md") if p.stem not in listed | set(design) | {"index"})
    source[0] = source[0].replace("<!-- optional pages -->", "\n".join(design))
    source[0] = source[0].replace("<!-- other pages -->", "\n".join(others))


def setup(app) -> None:
    app.connect("autodoc-process-docstring", _plain_text, priority=400)  # before napoleon's
    app.connect("autodoc-skip-member", _skip_listed)
    app.connect("source-read", _optional_pages)

# Commands and options in prose stay as typed: no "--set" turned into an en dash.
smartquotes = False
# Literal blocks of docstrings (file formats, examples) are shown as written, not as Python.
highlight_language = "none"

html_theme = "furo"
html_title = "pinmech"
html_static_path: list[str] = []
html_show_sourcelink = False
