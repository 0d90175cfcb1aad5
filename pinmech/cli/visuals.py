"""The mechanism's visual geometry for the drawing commands (snapshot, animate, view)."""

from __future__ import annotations

import sys


def visuals(mechanism):
    """The mechanism's visual geometry, built only when drawing: meshes of the model's own
    package only (the others named on stderr), links without visuals sketched."""
    from pinmech.draw.pages import mechanism_visuals

    visuals, skipped = mechanism_visuals(mechanism)
    for mesh in skipped:
        print(f"pinmech: warning: mesh {mesh} left out of the drawing: it is outside the model's package",
              file=sys.stderr)
    return visuals
