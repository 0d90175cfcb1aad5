"""Instant centres of a planar linkage at a pose, by the Aronhold-Kennedy theorem, and the
fixed and moving centrodes of a link over a sweep.

Primary centres come from the pairs: a pin is the centre of its two links; a slide puts
their centre at infinity, normal to the slide. Kennedy's theorem (Norton, Design of
Machinery, §6.4; Uicker, §3.17) then places every other centre I_ij on the line through
I_ik and I_kj for every third link k: two such lines meet at it. Points are kept in
homogeneous coordinates (x / s, y / s, w), s the mechanism's size, so a centre at
infinity (w = 0: a pure relative translation) is a point like any other, and of the
lines available the pair meeting at the widest angle is used.

A centre the theorem does not reach (a mechanism of mobility above one, a few six-bars'
"indeterminate" centres) is taken from the velocities instead: the point where the
relative velocity of the two links vanishes (`how = "velocities"`). Each centre is the
point of zero relative velocity of its links: tests check that, and finite differences.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from pinmech.model.planar_linkage import Pair, PlanarLinkage

#: Lines through coincident points, or meeting at an angle whose sine is below this, are
#: not used (the intersection would carry rounding / SINE).
SINE = 1e-8
#: A centre farther than this many mechanism sizes is reported at infinity (its direction).
FAR = 1e6


@dataclass(frozen=True)
class InstantCentre:
    """The instant centre of two links.

    Attributes:
        links: the two links' names (the lower index first; ground is index 0).
        point: plane coordinates [m] (world x, y for a mechanism in the xy plane), or None
            at infinity (a relative translation).
        direction: for a centre at infinity, the unit direction in which it lies (normal
            to the relative velocity), else None.
        how: "pin", "slide" (the primary centres), "Kennedy" or "velocities".
    """

    links: tuple[str, str]
    point: np.ndarray | None
    direction: np.ndarray | None
    how: str

    @property
    def primary(self) -> bool:
        return self.how in ("pin", "slide")

    def as_dict(self) -> dict:
        return {"links": list(self.links), "position": None if self.point is None else [float(x) for x in self.point],
                "at_infinity_along": None if self.direction is None else [float(x) for x in self.direction],
                "how": self.how, "primary": self.primary}


def instant_centres(linkage: PlanarLinkage, *, velocities: bool = False) -> dict[tuple[int, int], InstantCentre]:
    """All n (n - 1) / 2 centres at the pose `linkage.place` was last given.

    Args:
        velocities: `place` was given velocities: centres Kennedy's theorem does not
            reach are taken from them (else left out).

    Returns:
        (i, j) with i < j -> the centre, for the links of the linkage's pairs.
    """
    scale = linkage.mechanism.length_scale
    links = sorted({x for p in linkage.pairs for x in p.links})
    known, how = _primary(linkage, scale)
    progress = True
    while progress:
        progress = False
        for i, j in itertools.combinations(links, 2):
            if (i, j) in known:
                continue
            found = _kennedy(known, links, i, j)
            if found is not None:
                known[(i, j)], how[(i, j)] = found, "Kennedy"
                progress = True
    out = {}
    for i, j in itertools.combinations(links, 2):
        if (i, j) in known:
            out[(i, j)] = _centre(linkage, i, j, known[(i, j)], scale, how[(i, j)])
        elif velocities:
            found = relative_centre(linkage, i, j)
            if found is not None:
                out[(i, j)] = _centre(linkage, i, j, found, scale, "velocities")
    return out


def relative_centre(linkage: PlanarLinkage, i: int, j: int) -> np.ndarray | None:
    """The point of zero relative velocity of links i and j, homogeneous (x / s, y / s, w),
    from the velocities `place` was given; None when they do not move relative to each other."""
    scale = linkage.mechanism.length_scale
    origin = np.zeros(2)
    v = linkage.velocity(i, origin) - linkage.velocity(j, origin)
    w = linkage.omega(i) - linkage.omega(j)
    # v + w k x P = 0  =>  P = (-v_y, v_x) / w; homogeneous: (-v_y / s, v_x / s, w)
    h = np.array([-v[1] / scale, v[0] / scale, w])
    n = np.linalg.norm(h)
    return None if n == 0 else h / n


def _primary(linkage: PlanarLinkage, scale: float) -> tuple[dict, dict]:
    known: dict[tuple[int, int], np.ndarray] = {}
    how: dict[tuple[int, int], str] = {}
    for pair in linkage.pairs:
        key = tuple(sorted(pair.links))
        if pair.kind == "pin":
            xy = linkage.pair_point(pair) / scale
            h = np.array([xy[0], xy[1], 1.0])
        else:
            u = linkage.direction(pair.links[0], pair.axis)
            h = np.array([-u[1], u[0], 0.0])
        known[key], how[key] = h / np.linalg.norm(h), pair.kind
    return known, how


def _kennedy(known: dict, links: list[int], i: int, j: int) -> np.ndarray | None:
    """I_ij from the two best lines I_ik - I_kj, or None."""
    lines = []
    for k in links:
        a, b = known.get(_key(i, k)), known.get(_key(k, j))
        if k in (i, j) or a is None or b is None:
            continue
        line = np.cross(a, b)
        n = np.linalg.norm(line)
        if n > SINE:
            lines.append(line / n)
    best, size = None, SINE
    for l1, l2 in itertools.combinations(lines, 2):
        x = np.cross(l1, l2)
        n = np.linalg.norm(x)
        if n > size:
            best, size = x / n, n
    return best


def _key(a: int, b: int) -> tuple[int, int]:
    return (a, b) if a < b else (b, a)


def _centre(linkage: PlanarLinkage, i: int, j: int, h: np.ndarray, scale: float, how: str) -> InstantCentre:
    names = (linkage.names[i], linkage.names[j])
    if abs(h[2]) * FAR > np.hypot(h[0], h[1]):
        return InstantCentre(names, h[:2] / h[2] * scale, None, how)
    d = h[:2] / np.hypot(h[0], h[1])
    return InstantCentre(names, None, d if (d[0], d[1]) >= (0.0, 0.0) else -d, how)


def centrode_points(linkage: PlanarLinkage, link: int) -> tuple[np.ndarray, np.ndarray]:
    """The centre of `link` relative to the ground at the placed pose: in the plane
    (a point of the fixed centrode) and in the link's frame (of the moving centrode) [m];
    NaN at infinity."""
    centres = instant_centres(linkage)
    centre = centres.get(_key(0, link))
    if centre is None or centre.point is None:
        return np.full(2, np.nan), np.full(3, np.nan)
    return centre.point, linkage.to_link(link, centre.point)


def centrodes(linkage: PlanarLinkage, link: int, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Fixed centrode (plane coordinates, (N, 2)) and moving centrode (in the link's frame,
    (N, 3)) [m] of a link over closed configurations qs (N, nq); NaN rows at infinity."""
    fixed, moving = np.full((len(qs), 2), np.nan), np.full((len(qs), 3), np.nan)
    for row, q in enumerate(qs):
        linkage.place(q)
        fixed[row], moving[row] = centrode_points(linkage, link)
    return fixed, moving


def primary_pairs(linkage: PlanarLinkage) -> list[Pair]:
    """The pairs whose centres are primary (every pin and slide)."""
    return list(linkage.pairs)
