"""The fixed and moving centrodes of a chosen link over a sweep, on the paths figure.

The fixed centrode is the path of the link's instant centre relative to the ground, drawn
in the plane; the moving centrode is the same centre seen from the link, drawn on the
link at the scene's pose, where it touches the fixed one (the link's motion is the moving
centrode rolling on the fixed one without slipping: Uicker, Theory of Machines and
Mechanisms, sec. 3.21). Centres come from `instant_centres` (Kennedy's theorem)."""

from __future__ import annotations

from array import array

import numpy as np

from pinmech.model.display import colour_of, hex_colour
from pinmech.exceptions import DiagnosticError, FrameNotFound
from pinmech.solve.instant_centres import centrode_points


class CentrodeTrace:
    """Records a link's instant centre pose by pose, then draws both centrodes.

    Args:
        design: the sweep's design diagnostics (`design_sweep.DesignSweep`): its planar linkage.
        link: the link's name.
    """

    def __init__(self, design, link: str) -> None:
        mech = design.sweep.mechanism
        if link not in mech.links:
            raise FrameNotFound("link", link, list(mech.links), path=mech.source)
        if not design.applicable:
            raise DiagnosticError(f"--centrodes {link}: centrodes are drawn for planar mechanisms only "
                                  f"({design.reason})", path=mech.source)
        self.linkage, self.name = design.linkage, link
        self.index = next((k for k, n in self.linkage.names.items() if n == link), None)
        if self.index is None or self.index == 0:
            raise DiagnosticError(f"--centrodes {link}: the ground has no centrode; name a moving link "
                                  f"({', '.join(n for k, n in self.linkage.names.items() if k)})", path=mech.source)
        self.fixed = (array("d"), array("d"), array("d"))  # world frame [m]
        self.moving = (array("d"), array("d"), array("d"))  # the link's frame [m]

    def add(self, q: np.ndarray | None) -> None:
        """One pose (q None: a failed pose, a gap in both curves)."""
        if q is None:
            fixed, moving = np.full(3, np.nan), np.full(3, np.nan)
        else:
            self.linkage.place(q)
            xy, moving = centrode_points(self.linkage, self.index)
            fixed = self.linkage.to_world(xy) if np.all(np.isfinite(xy)) else np.full(3, np.nan)
        for values, x in zip(self.fixed, fixed.tolist()):
            values.append(x)
        for values, x in zip(self.moving, np.asarray(moving).tolist()):
            values.append(x)

    def world(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Both centrodes in the world frame [m], (N, 3) each, the moving one carried by the
        link at configuration q."""
        self.linkage.place(q)
        M = self.linkage.data.oMi[self.index]
        moving = np.array(self.moving).T
        return np.array(self.fixed).T, moving @ M.rotation.T + M.translation

    def draw(self, ax, axes: np.ndarray, scale: float, q: np.ndarray | None) -> None:
        """On the paths axes: `axes` (2, 3) the drawing plane's axes, `scale` from m; the
        moving centrode at q (the scene's pose), or not drawn without one. Parts farther from
        the paths than their own extent are left out (a centrode reaches infinity wherever
        the link only translates)."""
        if q is None:
            return
        fixed, moving = self.world(q)
        colour = hex_colour(colour_of(self.linkage.mechanism, self.name))
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()  # the paths' and the mechanism's extent
        grow = max(x1 - x0, y1 - y0)  # a centrode runs to infinity where the link translates:
        box = (x0 - grow, x1 + grow, y0 - grow, y1 + grow)  # drawn within a window around them
        for curve, style, what in ((fixed, "-", "fixed"), (moving, (0, (4, 2)), "moving")):
            u, v = axes @ curve.T * scale
            outside = (u < box[0]) | (u > box[1]) | (v < box[2]) | (v > box[3])
            u, v = np.where(outside, np.nan, u), np.where(outside, np.nan, v)
            ax.plot(u, v, color=colour, linewidth=1.2, linestyle=style, alpha=0.6 if what == "fixed" else 1.0,
                    gid=f"{what} centrode", label=f"{what} centrode of {self.name}"
                    + (" (at the scene's pose)" if what == "moving" else ""))
        ax.set_xlim(box[0], box[1])
        ax.set_ylim(box[2], box[3])
