"""Result objects shown in a notebook: outside text (a scene's title) is escaped HTML."""

from __future__ import annotations

import html.parser
from pathlib import Path

from pinmech import Scene, analyse

ROOT = Path(__file__).resolve().parents[1]


class _Tags(html.parser.HTMLParser):
    """The start tags of an HTML fragment and its text, as a browser's tokenizer sees them."""

    def __init__(self):
        super().__init__()
        self.tags, self.text = [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)

    def handle_data(self, data):
        self.text.append(data)


def test_a_scene_title_with_markup_is_text_in_the_notebook_table(tmp_path):
    """A title '<script>...</script><b>' was written into _repr_html_ as markup."""
    title = '<script>alert("x")</script><b>&'
    scene = tmp_path / "s.toml"
    scene.write_text(f"title = {title!r}\n" + (ROOT / "models/scenes/four_bar_drawn.toml").read_text()
                     .replace('title = "Four-bar linkage, drawn"\n', "")
                     .replace('"../linkages/four_bar.toml"', repr(str(ROOT / "models/linkages/four_bar.toml"))))
    parser = _Tags()
    parser.feed(analyse(Scene.load(scene))._repr_html_())
    assert "script" not in parser.tags and "b" not in parser.tags
    assert title in "".join(parser.text)
