"""An offline meshcat page: `_OfflineWindow` stands in for meshcat's ZMQ server, keeps the
scene tree and writes one self-contained page (meshcat's JavaScript embedded, about 850 KB,
no network)."""

from __future__ import annotations

import base64
import html
from pathlib import Path
from typing import Any

from pinmech.draw.scene import _meshcat


class _OfflineWindow:
    """Stands in for meshcat's ZMQ server: keeps the scene tree, writes one offline page."""

    web_url = "(offline page: no server)"

    def __init__(self) -> None:
        _meshcat()
        from meshcat.servers.tree import SceneTree

        self.tree = SceneTree()
        self.animations: list[bytes] = []

    def send(self, command: Any) -> None:
        import umsgpack
        from meshcat.servers.tree import find_node

        data = command.lower()
        blob = umsgpack.packb(data)
        path = [p for p in data["path"].split("/") if p]
        kind = data["type"]
        if kind == "set_animation":
            self.animations = [blob]
        elif kind == "delete":
            parent = find_node(self.tree, path[:-1]) if path else None
            if parent is not None and path[-1] in parent:
                del parent[path[-1]]
        else:
            node = find_node(self.tree, path)
            if kind == "set_transform":
                node.transform = blob
            elif kind == "set_object":
                node.object, node.properties = blob, []
            elif kind == "set_property":
                node.properties.append(blob)

    def get_scene(self) -> str:
        """meshcat's `Visualizer.static_html()` asks for this."""
        return self.page("MeshCat", "")

    def page(self, title: str, legend: str, *, fps: float = 30.0) -> str:
        """The whole page: meshcat's script, then every command in tree order, animations last."""
        from meshcat.servers.tree import walk

        blobs = []
        for node in walk(self.tree):
            blobs += ([node.object] if node.object is not None else []) + list(node.properties)
            blobs += [node.transform] if node.transform is not None else []
        commands = "\n".join(
            f'command("{base64.b64encode(b).decode()}");' for b in blobs + self.animations
        )
        script = (Path(_meshcat().__file__).parent / "viewer" / "dist" / "main.min.js").read_text(
            encoding="utf-8"
        )
        heading = f"{title} ({legend})" if legend else title
        return _PAGE.format(
            title=html.escape(heading),
            legend=html.escape(legend),
            script=script,
            commands=commands,
            fps=float(fps),
        )


_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title>
<style>body {{margin: 0}} #meshcat-pane {{width: 100vw; height: 100vh; overflow: hidden}}
#legend {{position: fixed; left: 8px; bottom: 6px; font: 13px sans-serif; color: #444}}</style></head>
<body><div id="meshcat-pane"></div><div id="legend">{legend}</div>
<script>{script}</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
function command(b64) {{ viewer.handle_command_bytearray(Uint8Array.from(atob(b64), c => c.charCodeAt(0))); }}
{commands}
var still = /frame=(\\d+)/.exec(location.hash);
if (still && viewer.animator.duration > 0) {{ viewer.animator.pause(); viewer.animator.seek(Number(still[1]) / {fps}); }}
</script></body></html>
"""

