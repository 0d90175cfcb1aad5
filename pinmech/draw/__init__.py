"""meshcat drawings of a Pinocchio model: one pose or an animation, as an offline HTML page.

The inputs are plain Pinocchio objects and numpy arrays (a `pin.Model`, its visual
`pin.GeometryModel`, configuration vectors, points and vectors in the world frame), so this
module knows nothing of scenes or solvers. meshcat (the extra `viz`) is imported inside the
functions only.

A static page needs no server: `_OfflineWindow` stands in for meshcat's ZMQ server, keeps
the scene tree and writes one self-contained page (meshcat's JavaScript embedded, about
850 KB, no network). meshcat's camera orbits the world origin, so the drawing is shifted to
put the centre of its bounding box there, and the camera looks along a planar mechanism's
normal from the distance at which the drawing spans most of the view.

Modules: `pages` (the public functions), `scene` (one meshcat scene), `offline` (the offline
page), `inputs` (checks, `DrawError`), `geometry` (boxes, axes, transforms).
"""

from pinmech.draw.inputs import DrawError
from pinmech.draw.pages import (
    LiveView,
    animation_html,
    live_viewer,
    load_visuals,
    package_visuals,
    snapshot_html,
)
from pinmech.draw.scene import INSTALL_HINT, ROOT, Arrow, arrow_scales

__all__ = [
    "INSTALL_HINT",
    "ROOT",
    "Arrow",
    "DrawError",
    "LiveView",
    "animation_html",
    "arrow_scales",
    "live_viewer",
    "load_visuals",
    "package_visuals",
    "snapshot_html",
]
