"""Three-pose motion generation of a slider-crank in closed form (Sandor & Erdman, Advanced
Mechanism Design, vol. 2, ch. 2; Norton, Design of Machinery, ch. 5: three-position
synthesis): the rod's starting points for the motion search and the tests' reference.

Poses j = 1, 2, 3: the rod's point P_j [m] and the rod's angle alpha_j [rad] (the part's).
A point of the rod with coordinates b in the rod's frame (origin P, x axis at alpha) is at
W_j(b) = P_j + R(alpha_j) b.

- The crank's dyad: any rod point a is a moving pivot; its three positions fix the crank's
  ground pivot O2 at their circumcentre (the "circle point" and "centre point" of three
  positions: two free parameters).
- The slider's dyad: a point b whose three positions lie on one line (the slide: its centre
  point at infinity). With d_j = P_j - P_1 and R(alpha_j) - R(alpha_1) = m_j R(phi_j) (m_j =
  2 sin((alpha_j - alpha_1) / 2), phi_j = (alpha_j + alpha_1) / 2 + 90 deg), collinearity
  cross(W_2 - W_1, W_3 - W_1) = 0 reads k |b|^2 + g . b + c0 = 0 with k = m_2 m_3 sin(phi_3 -
  phi_2), c0 = cross(d_2, d_3): the slider points of three poses lie on a circle of the
  rod's frame (one free parameter, its angle tau).

Each pair (a, b) is a slider-crank through the three poses exactly: O2 the circumcentre,
the slide through W_1(b), W_2(b), W_3(b), unless it meets them on two assemblies (B ahead of
A's foot on the slide at one pose, behind at another: a branch defect the construction does
not see; left out).
"""

from __future__ import annotations

import math

import numpy as np

_J = np.array([[0.0, 1.0], [-1.0, 0.0]])  # cross(u, v) = u @ _J @ v


def _rotation(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def _cross(u: np.ndarray, v: np.ndarray) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


def slider_circle(places: np.ndarray, angles: np.ndarray) -> tuple[np.ndarray, float] | None:
    """The circle of the rod's frame whose points' three positions are collinear: its
    centre (2,) and radius [m]; None where the poses do not turn the rod twice (k = 0: the
    points are then on a line) or the circle is imaginary."""
    d2, d3 = places[1] - places[0], places[2] - places[0]
    M2 = _rotation(angles[1]) - _rotation(angles[0])
    M3 = _rotation(angles[2]) - _rotation(angles[0])
    m2, m3 = 2 * math.sin((angles[1] - angles[0]) / 2), 2 * math.sin((angles[2] - angles[0]) / 2)
    k = m2 * m3 * math.sin((angles[2] - angles[1]) / 2)
    scale = max(float(np.abs(d2).max()), float(np.abs(d3).max()), 1e-300)
    if abs(k) < 1e-9:
        return None
    g = M3.T @ _J.T @ d2 + M2.T @ _J @ d3
    c0 = _cross(d2, d3)
    centre = -g / (2 * k)
    r2 = float(centre @ centre) - c0 / k
    if not r2 > (1e-12 * scale) ** 2:
        return None
    return centre, math.sqrt(r2)


def _circumcentre(p: np.ndarray) -> np.ndarray | None:
    """The centre of the circle through three points (3, 2), None if they are collinear."""
    a, b = p[1] - p[0], p[2] - p[0]
    den = 2 * _cross(a, b)
    if abs(den) < 1e-12 * max(float(a @ a + b @ b), 1e-300):
        return None
    return p[0] + np.array([b[1] * (a @ a) - a[1] * (b @ b), a[0] * (b @ b) - b[0] * (a @ a)]) / den


def slider_crank_row(places: np.ndarray, angles: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """The motion-search row (O2x, O2y, slide, offset, crank, rod, along, across, gamma)
    (slider.NAMES and the angle from A -> B to the part's line) of the crank's
    moving pivot a and the slider point b (rod frame, [m]), and its assembly s; None where
    a's positions are collinear, a = b, or the block's pin is ahead of A's foot on the slide
    at one pose and behind it at another (the construction meets the poses on two
    assemblies: a branch defect)."""
    A = np.array([places[j] + _rotation(angles[j]) @ a for j in range(3)])
    B = np.array([places[j] + _rotation(angles[j]) @ b for j in range(3)])
    O2 = _circumcentre(A)
    rod = float(np.linalg.norm(b - a))
    if O2 is None or rod < 1e-9:
        return None
    line = B[2] - B[0] if np.linalg.norm(B[2] - B[0]) >= np.linalg.norm(B[1] - B[0]) else B[1] - B[0]
    psi = math.remainder(math.atan2(line[1], line[0]), math.pi)  # the slide's direction within +-90 deg
    u, n = np.array([math.cos(psi), math.sin(psi)]), np.array([-math.sin(psi), math.cos(psi)])
    w = (B[0] - A[0]) / rod
    r = places[0] - A[0]
    ahead = (B - A) @ u > 0  # B ahead of A's foot on the slide, at each pose
    if ahead.min() != ahead.max():  # the poses on both assemblies: a branch defect, no slider-crank
        return None
    row = [*O2, psi, float((B[0] - O2) @ n), float(np.linalg.norm(A[0] - O2)), rod, float(r @ w), _cross(w, r),
           math.remainder(angles[0] - math.atan2(w[1], w[0]), 2 * math.pi)]
    return np.array([*row, 1.0 if ahead[0] else -1.0])


def slider_crank_rows(places: np.ndarray, angles: np.ndarray, low: np.ndarray, high: np.ndarray, reach: float,
                      grid: int = 9, turns: int = 24) -> np.ndarray:
    """Rows (k, 10) of `slider_crank_row` (its assembly last) for crank pivots O2 at the
    centres of a grid x grid of cells over the box low..high (2,) [m] and `turns` slider
    points on the circle's arc within `reach` [m] of P (the arc where |b| <= reach: a few poses close together make the circle
    large, and most of it gives rods far too long).

    A centre point O2 gives its circle point a by the inverse motion: seen from the rod, O2
    is at o_j = R(alpha_j)^T (O2 - P_j), and a is the circumcentre of o_1, o_2, o_3."""
    if len(places) != 3:
        raise ValueError("the slider-crank's classical construction takes exactly three poses")
    circle = slider_circle(places, angles)
    arc = _arc(*circle, reach) if circle is not None else None
    if arc is None:
        return np.zeros((0, 10))
    centre, radius = circle
    sliders = [centre + radius * np.array([math.cos(tau), math.sin(tau)]) for tau in np.linspace(*arc, turns)]
    rows = []
    cells = (np.arange(grid) + 0.5) / grid  # the grid cells' centres: inside the box, off its edges
    for x in low[0] + cells * (high[0] - low[0]):
        for y in low[1] + cells * (high[1] - low[1]):
            seen = np.array([_rotation(angles[j]).T @ (np.array([x, y]) - places[j]) for j in range(3)])
            a = _circumcentre(seen)
            for b in sliders if a is not None else ():
                row = slider_crank_row(places, angles, a, b)
                if row is not None:
                    rows.append(row)
    return np.array(rows).reshape(-1, 10)


def _arc(centre: np.ndarray, radius: float, reach: float) -> tuple[float, float] | None:
    """The circle's angles (from its centre) whose points are within reach of the origin:
    |b|^2 = |c|^2 + r^2 - 2 |c| r cos(tau - tau0) <= reach^2; None if there are none."""
    c = float(np.hypot(*centre))
    kappa = (c * c + radius * radius - reach * reach) / (2 * c * radius) if c > 0 else -2.0
    if kappa > 1:
        return None
    tau0, half = math.atan2(-centre[1], -centre[0]), math.acos(max(kappa, -1.0))
    return tau0 - half, tau0 + half
