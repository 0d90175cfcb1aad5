"""An offline meshcat page: `_OfflineWindow` stands in for meshcat's ZMQ server, keeps the
scene tree and writes one self-contained page (meshcat's JavaScript embedded, about 850 KB,
no network)."""

from __future__ import annotations

import base64
import html
import json
from collections.abc import Sequence
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

    def page(self, title: str, legend: str, *, fps: float = 30.0, readouts: Sequence[str] = ()) -> str:
        """The whole page: meshcat's script, then every command in tree order, animations last;
        with `readouts` (one text a frame, the driver's value), a bar of controls: play/pause,
        a slider over the frames and the frame's readout."""
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
            controls=_controls(readouts, fps) if readouts else "",
        )


def _controls(readouts: Sequence[str], fps: float) -> str:
    """The animation's controls, always shown: play/pause, a slider over the frames (dragging
    it stops the motion and shows that frame) and the frame's readout. The address
    `#slider=K` moves the slider to frame K as a hand would (for tests and links)."""
    return _CONTROLS.format(last=len(readouts) - 1, first=html.escape(readouts[0]), fps=float(fps),
                            readouts=json.dumps(list(readouts)).replace("</", "<\\/"))


_CONTROLS = """<div id="controls"><button id="play" type="button">❚❚ pause</button>
<input id="driver" type="range" min="0" max="{last}" step="1" value="0" aria-label="frame">
<span id="readout">{first}</span></div>
<script>
var readouts = {readouts};
var slider = document.getElementById("driver"), readout = document.getElementById("readout");
var button = document.getElementById("play");
function show(k) {{ slider.value = k; readout.textContent = readouts[k]; }}
function label() {{ button.textContent = viewer.animator.playing ? "❚❚ pause" : "▶ play"; }}
function frame(k) {{ viewer.animator.pause(); viewer.animator.seek(k / {fps}); show(k); label(); }}
button.onclick = function () {{ if (viewer.animator.playing) viewer.animator.pause(); else viewer.animator.play(); label(); }};
slider.oninput = function () {{ frame(Number(slider.value)); }};
(function follow() {{
  if (viewer.animator.playing) show(Math.min(readouts.length - 1, Math.round(viewer.animator.time * {fps})) % readouts.length);
  requestAnimationFrame(follow);
}})();
var asked = /slider=(\\d+)/.exec(location.hash);
if (asked) {{ slider.value = asked[1]; slider.dispatchEvent(new Event("input")); }}
var still = /frame=(\\d+)/.exec(location.hash);
if (still) show(Number(still[1]));
label();
</script>"""


_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title>
<style>body {{margin: 0}} #meshcat-pane {{width: 100vw; height: 100vh; overflow: hidden}}
#legend {{position: fixed; left: 8px; bottom: 6px; font: 13px sans-serif; color: #444}}
#controls {{position: fixed; top: 6px; left: 8px; right: 260px; display: flex; gap: 10px; align-items: center;
  font: 14px sans-serif; background: rgba(255, 255, 255, 0.9); padding: 5px 8px; border: 1px solid #bbb;
  border-radius: 4px}}
#controls button {{font: 14px sans-serif; min-width: 6em}} #controls input {{flex: 1}}
#readout {{min-width: 10em; font-family: monospace}}</style></head>
<body><div id="meshcat-pane"></div><div id="legend">{legend}</div>
<script>{script}</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
function command(b64) {{ viewer.handle_command_bytearray(Uint8Array.from(atob(b64), c => c.charCodeAt(0))); }}
{commands}
var still = /frame=(\\d+)/.exec(location.hash);
if (still && viewer.animator.duration > 0) {{ viewer.animator.pause(); viewer.animator.seek(Number(still[1]) / {fps}); }}
function centre() {{  // meshcat widens an orthographic view to the right: keep the drawing centred
  var c = viewer.camera;
  if (c.type !== "OrthographicCamera") return;
  var half = (c.right - c.left) / 2;
  c.left = -half; c.right = half; c.updateProjectionMatrix(); viewer.set_dirty();
}}
window.addEventListener("resize", centre);
centre();
</script>{controls}</body></html>
"""

