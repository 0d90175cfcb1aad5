"""The motion of a solved scene as plain HTML tables (a notebook's view, the report page's)."""

from __future__ import annotations

import html
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from pinmech.solve.motion import Motion


def html_table(rows: list[list[str]]) -> str:
    """A plain HTML table, the first row its header."""
    head, *rest = rows
    cells = "".join(f"<th>{html.escape(c)}</th>" for c in head)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rest)
    return f"<table><tr>{cells}</tr>{body}</table>"


def motion_table_html(m: Motion, normal: np.ndarray | None) -> str:
    """The points' and links' motion as HTML tables (SI units; angles in degrees; a planar
    mechanism's rates about its plane's `normal`)."""
    points = [["point", "link", "position [m]", "velocity [m/s]", "|v| [m/s]", "acceleration [m/s²]", "|a| [m/s²]"]]
    for name, p in m.points.items():
        points.append([name, p.link, _vec(p.position), _vec(p.velocity), f"{np.linalg.norm(p.velocity):.6g}",
                       _vec(p.acceleration), f"{np.linalg.norm(p.acceleration):.6g}"])
    links = [["link", "φ [deg]", "ω [rad/s]", "α [rad/s²]"]]
    for name, link in m.links.items():
        w = link.angular_velocity if normal is None else [float(normal @ link.angular_velocity)]
        a = link.angular_acceleration if normal is None else [float(normal @ link.angular_acceleration)]
        angle = "" if link.angle is None else f"{np.degrees(link.angle):.6g}"
        links.append([name, angle, _vec(np.asarray(w)), _vec(np.asarray(a))])
    return html_table(points) + html_table(links)


def _vec(v: np.ndarray) -> str:
    return ", ".join(f"{x:.6g}" for x in np.ravel(v)) if np.size(v) != 1 else f"{float(np.ravel(v)[0]):.6g}"
