"""The documentation site builds offline with warnings as errors, and its links hold.

`sphinx-build -W --keep-going -n` (nitpicky: every cross-reference must resolve; no
intersphinx, so nothing is fetched), then every link between the built pages is followed:
the page it names exists and so does the anchor. The reference is the built HTML itself.
"""

from __future__ import annotations

import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

ROOT = Path(__file__).resolve().parents[1]
pytest.importorskip("sphinx", reason='the docs need pip install "pinmech[docs]"')


class _Links(HTMLParser):
    """The ids and the links (href, src) of one HTML page."""

    def __init__(self) -> None:
        super().__init__()
        self.ids: set[str] = set()
        self.links: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for name, value in attrs:
            if name == "id" and value:
                self.ids.add(value)
            elif name in ("href", "src") and value:
                self.links.append(value)


def _parse(page: Path) -> _Links:
    links = _Links()
    links.feed(page.read_text(encoding="utf-8"))
    return links


# Under xdist the module's tests share one worker, so the site is built once, not once a worker.
pytestmark = pytest.mark.xdist_group("docs_build")


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("html")
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-n", "-q", "-b", "html",
                          str(ROOT / "docs"), str(out)], capture_output=True, text=True, timeout=600, check=False)
    assert run.returncode == 0, run.stderr
    return out


@pytest.mark.slow
def test_the_site_builds_with_warnings_as_errors(site: Path) -> None:
    for page in ("index", "install", "tutorials/r_rtr", "reference/cli", "reference/api", "gallery", "changelog"):
        assert (site / f"{page}.html").is_file(), page


@pytest.mark.slow
def test_every_link_within_the_site_reaches_a_page_and_its_anchor(site: Path) -> None:
    pages = {page: _parse(page) for page in site.rglob("*.html")}
    broken = []
    for page, parsed in pages.items():
        for link in parsed.links:
            parts = urlsplit(link)
            if parts.scheme or parts.netloc or link.startswith(("mailto:", "javascript:")):
                continue  # outside the site: not followed offline
            target = (page.parent / unquote(parts.path)).resolve() if parts.path else page
            if target.is_dir():
                target = target / "index.html"
            if not target.exists():
                broken.append(f"{page.relative_to(site)}: {link}")
            elif parts.fragment and target.suffix == ".html":
                ids = pages[target].ids if target in pages else _parse(target).ids
                if unquote(parts.fragment) not in ids:
                    broken.append(f"{page.relative_to(site)}: {link} (no such anchor)")
    assert not broken, "\n".join(broken)


@pytest.mark.slow
def test_the_home_page_lists_the_sections_and_shows_the_picture(site: Path) -> None:
    home = (site / "index.html").read_text(encoding="utf-8")
    for caption in ("Tutorials", "How-to guides", "Reference", "Explanation"):
        assert re.search(rf">\s*{caption}\s*<", home), caption
    assert "r_rtr.png" in home


@pytest.mark.slow
def test_no_field_of_a_result_is_documented_twice(site: Path) -> None:
    """Each class of the API pages lists its fields once: in its "Variables" (the
    docstring's "Attributes:"), not again as a member entry below it."""
    twice = []
    for page in sorted((site / "reference" / "api").glob("*.html")):
        html = page.read_text(encoding="utf-8")
        for part in re.split(r'<dl class="py (?:class|exception)">', html)[1:]:
            name = re.search(r'id="([^"]+)"', part).group(1)
            fields = re.search(r'<dt class="field-\w+">Variables.*?</dd>', part, re.S)
            listed = set(re.findall(r"<strong>(\w+)</strong>", fields.group(0))) if fields else set()
            members = [i.rsplit(".", 1)[1] for i in re.findall(r'<dt class="sig sig-object py" id="([^"]+)"', part)
                       if i.startswith(name + ".")]
            twice += [f"{page.name}: {name}.{m}" for m in sorted(listed & set(members))]
            twice += [f"{page.name}: {name}.{m} (two member entries)" for m in set(members) if members.count(m) > 1]
    assert twice == []
