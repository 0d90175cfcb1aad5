"""Grashof class of each four-bar loop of a planar linkage, and the slider-crank equivalent.

Four-bar (Norton, Design of Machinery, §2.12; Uicker, Theory of Machines and Mechanisms,
§1.10): with s and l the shortest and longest of the four lengths (ground included) and
p, q the others,

    s + l < p + q   Grashof: the shortest link turns fully relative to its neighbours;
                    shortest link adjacent to the ground: crank-rocker (it is the crank),
                    the ground: double-crank, the coupler: double-rocker (Grashof);
    s + l = p + q   change point (special Grashof): the links fall collinear twice a turn;
    s + l > p + q   non-Grashof: triple rocker, no link turns fully.

Slider-crank (crank r on a ground pivot, rod l, block on a ground slide whose line passes
at distance e from the crank's pivot): the crank turns fully iff r + |e| <= l (the rod
reaches the slide's line at every crank angle), else it rocks. Inverted slider-crank
(the block on the crank slides on a guide pivoted at distance d, its line through the
guide's pivot): the crank always turns; the guide rocks if r < d (a crank-shaper, a
quick return) and turns fully if r > d (Whitworth).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinmech.model.planar_linkage import Pair, PlanarLinkage
from pinmech.solve.barker import barker_class

#: Lengths are equal (a change point) within this share of the loop's perimeter.
EQUAL = 1e-9


@dataclass(frozen=True)
class LoopClass:
    """One four-bar-like loop of the linkage and its class.

    Attributes:
        kind: "four-bar", "slider-crank" or "inverted slider-crank".
        links: the loop's links, ground first, then round the loop.
        lengths: name -> length [m]: the four links of a four-bar; r, l, e of a slider-crank;
            r, d, e of an inverted one.
        condition: the inequality decided, with its numbers (text).
        label: the class ("crank-rocker", "double-crank", "double-rocker", "change point",
            "triple rocker"; "crank", "rocker"; "crank-shaper", "Whitworth").
        cranks: the links that turn fully relative to the ground.
    """

    kind: str
    links: tuple[str, ...]
    lengths: dict[str, float]
    condition: str
    label: str
    cranks: tuple[str, ...]

    def as_dict(self, input_link: str | None = None) -> dict:
        out = {"kind": self.kind, "links": list(self.links), "lengths": self.lengths, "condition": self.condition,
               "class": self.label, "cranks": list(self.cranks)}
        if self.kind == "four-bar":
            out["barker"] = self.barker(input_link)
        return out

    def barker(self, input_link: str | None = None) -> str:
        """Barker's type of a four-bar ("I-2 GCRR"), its links numbered from the ground with
        `input_link` (one of the two pivoted on it; default the first) as link 2; "" for
        another loop."""
        if self.kind != "four-bar":
            return ""
        ground, a, b, c = self.links
        order = (ground, c, b, a) if input_link == c else (ground, a, b, c)
        found = barker_class(*(self.lengths[n] for n in order))
        return f"{found.name} {found.code}"


def four_bar_class(d: float, a: float, b: float, c: float) -> tuple[str, str, tuple[bool, bool]]:
    """Grashof class of a four-bar of ground d, ground-pivoted links a and c, coupler b [m].

    Returns:
        (label, the inequality with its numbers, whether a and c turn fully).
    """
    lengths = [d, a, b, c]
    s, l = min(lengths), max(lengths)
    p_q = sum(lengths) - s - l
    tie = abs(s + l - p_q) <= EQUAL * sum(lengths)
    sign = "=" if tie else "<" if s + l < p_q else ">"
    condition = f"s + l = {s + l:.6g} m {sign} p + q = {p_q:.6g} m"
    if sign == ">":
        return "triple rocker", condition, (False, False)
    shortest = [abs(x - s) <= EQUAL * sum(lengths) for x in lengths]
    turns = (shortest[0] or shortest[1], shortest[0] or shortest[3])
    if tie:
        return "change point", condition, turns
    if shortest[0]:
        return "double-crank", condition, turns
    if shortest[2]:
        return "double-rocker", condition, turns
    return "crank-rocker", condition, turns


def slider_crank_class(r: float, l: float, e: float) -> tuple[str, str]:
    """Whether a slider-crank's crank turns fully: r + |e| < l; at r + |e| = l (within
    EQUAL) the rod falls normal to the slide once a turn, a singular pose the crank cannot
    be driven through (a change point). Lengths [m]."""
    reach = r + abs(e)
    if abs(reach - l) <= EQUAL * (r + l + abs(e)):
        return "change point", f"r + |e| = {reach:.6g} m = l = {l:.6g} m"
    if reach < l:
        return "crank", f"r + |e| = {reach:.6g} m <= l = {l:.6g} m"
    return "rocker", f"r + |e| = {reach:.6g} m > l = {l:.6g} m"


def loop_classes(linkage: PlanarLinkage) -> list[LoopClass]:
    """Every loop of four links through the ground (pins, or one slide), classified.

    The lengths are distances between the pairs on each link, read in the links' own
    frames (and, for a slide's offset, at the model's reference pose), so they do not
    depend on the pose.
    """
    out, seen = [], set()
    for loop in _four_loops(linkage):
        key = frozenset(id(p) for p in loop)
        if key in seen:
            continue
        seen.add(key)
        found = _classify(linkage, loop)
        if found is not None:
            out.append(found)
    return out


def _four_loops(linkage: PlanarLinkage) -> list[tuple[Pair, Pair, Pair, Pair]]:
    """Pairs (ground-a, a-b, b-c, c-ground) of every loop of four distinct links."""
    loops = []
    for a, p0 in linkage.neighbours(0):
        for b, p1 in linkage.neighbours(a):
            for c, p2 in linkage.neighbours(b):
                for g, p3 in linkage.neighbours(c):
                    if g == 0 and len({0, a, b, c}) == 4 and p3 is not p0:
                        loops.append((p0, p1, p2, p3))
    return loops


def _end(pair: Pair, link: int) -> np.ndarray:
    return pair.local[0] if pair.links[0] == link else pair.local[1]


def _classify(linkage: PlanarLinkage, loop: tuple[Pair, Pair, Pair, Pair]) -> LoopClass | None:
    kinds = "".join("R" if p.kind == "pin" else "P" for p in loop)
    if kinds == "RRRP":  # the slide on the ground last: a slider-crank as written
        return _slider_crank(linkage, loop)
    if kinds == "RRRR":
        return _four_bar(linkage, loop)
    if kinds in ("RPRR", "RRPR"):
        return _inverted(linkage, loop if kinds == "RPRR" else tuple(reversed(loop)))
    return None  # RRRP reversed (PRRR) is the same loop written from its other end


def _chain(linkage: PlanarLinkage, loop) -> tuple[int, int, int]:
    a = loop[0].other(0)
    b = loop[1].other(a)
    return a, b, loop[2].other(b)


def _four_bar(linkage: PlanarLinkage, loop) -> LoopClass | None:
    a, b, c = _chain(linkage, loop)
    d_len = float(np.linalg.norm(_end(loop[0], 0) - _end(loop[3], 0)))
    a_len = float(np.linalg.norm(_end(loop[0], a) - _end(loop[1], a)))
    b_len = float(np.linalg.norm(_end(loop[1], b) - _end(loop[2], b)))
    c_len = float(np.linalg.norm(_end(loop[2], c) - _end(loop[3], c)))
    if min(d_len, a_len, b_len, c_len) <= EQUAL * (d_len + a_len + b_len + c_len):
        return None  # two of its pins are one (a pin drawn on three links): no four-bar
    label, condition, turns = four_bar_class(d_len, a_len, b_len, c_len)
    n = linkage.names
    cranks = tuple(n[x] for x, t in zip((a, c), turns) if t)
    lengths = {n[0]: d_len, n[a]: a_len, n[b]: b_len, n[c]: c_len}
    return LoopClass("four-bar", (n[0], n[a], n[b], n[c]), lengths, condition, label, cranks)


def _slider_crank(linkage: PlanarLinkage, loop) -> LoopClass:
    crank, rod, block = _chain(linkage, loop)
    r = float(np.linalg.norm(_end(loop[0], crank) - _end(loop[1], crank)))
    l_len = float(np.linalg.norm(_end(loop[1], rod) - _end(loop[2], rod)))
    e = _offset(linkage, loop[0], 0, loop[2], block, loop[3])
    label, condition = slider_crank_class(r, l_len, e)
    n = linkage.names
    return LoopClass("slider-crank", (n[0], n[crank], n[rod], n[block]), {"r": r, "l": l_len, "e": e},
                     condition, label, (n[crank],) if label == "crank" else ())


def _inverted(linkage: PlanarLinkage, loop) -> LoopClass | None:
    """Written from the guide: ground-guide pin, guide-block slide, block-crank pin, crank-ground pin."""
    guide, block, crank = _chain(linkage, loop)
    r = float(np.linalg.norm(_end(loop[2], crank) - _end(loop[3], crank)))
    d_len = float(np.linalg.norm(_end(loop[0], 0) - _end(loop[3], 0)))
    e = _offset(linkage, loop[0], guide, loop[2], block, loop[1])
    n = linkage.names
    links, lengths = (n[0], n[crank], n[block], n[guide]), {"r": r, "d": d_len, "e": e}
    if abs(e) > EQUAL * (r + d_len):
        return LoopClass("inverted slider-crank", links, lengths, f"slide line {e:.6g} m off the guide's pivot",
                         "offset (not classified)", ())
    if abs(r - d_len) <= EQUAL * (r + d_len):
        label, sign = "change point", "="
    else:
        label, sign = ("crank-shaper", "<") if r < d_len else ("Whitworth", ">")
    cranks = (n[crank],) + ((n[guide],) if label == "Whitworth" else ())
    return LoopClass("inverted slider-crank", links, lengths, f"r = {r:.6g} m {sign} d = {d_len:.6g} m", label, cranks)


def _offset(linkage: PlanarLinkage, pivot: Pair, pivot_link: int, moving: Pair, moving_link: int,
            slide: Pair) -> float:
    """Signed distance [m] from a pivot to the line its partner's pin runs along, parallel
    to the slide, at the model's reference pose (the same at every pose)."""
    linkage.place(linkage.mechanism.neutral())
    u = linkage.direction(slide.links[0], slide.axis)
    u = u / np.linalg.norm(u)
    pivot_xy = linkage.point(pivot_link, _end(pivot, pivot_link))
    moving_xy = linkage.point(moving_link, _end(moving, moving_link))
    r = moving_xy - pivot_xy
    return float(u[0] * r[1] - u[1] * r[0])
