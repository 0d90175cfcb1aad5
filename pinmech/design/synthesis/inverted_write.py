"""A synthesised inverted slider-crank as a drawn linkage's tables (models/linkages/*.toml,
read by model.linkage_spec): ground pivots O2 (the crank's) and O4 (the guide's), the crank
O2 -> A, the block pinned to the crank at A (carrying the coupler point P of a path), and
the guide O4 -> G along the slot's direction, on which the block slides along the line
through A parallel to O4 -> G (the slot `offset` to the left of O4). Drawn at the first
target's pose; the scene's driver is the crank's pin O2, its outputs P (path) or the
guide's angle (function: the guide link's x axis runs O4 -> G, the slot's direction)."""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.synthesis.inverted import guide_angle, pose
from pinmech.design.synthesis.result import Linkage
from pinmech.design.synthesis.written import mm_text


def _mm(v: float) -> str:
    return mm_text(v)


def inverted_tables(lk: Linkage, title: str) -> dict:
    """The drawn linkage's tables of an inverted slider-crank at its first target's pose."""
    z, S, T = lk.z[None], np.array([lk.s]), lk.theta[:1][None]
    A, P = pose(z, S, T).A[0, 0], pose(z, S, T).P[0, 0]
    phi = float(guide_angle(z, S, T)[0, 0])
    reach = max(lk.size, 1e-3)  # G: the guide's end, one size along the slot's direction from O4
    G = lk.z[2:4] + reach * np.array([math.cos(phi), math.sin(phi)])
    path = lk.task != "function"
    joints = {"O2": [_mm(z[0, 0]), _mm(z[0, 1])], "O4": [_mm(z[0, 2]), _mm(z[0, 3])], "A": [_mm(A[0]), _mm(A[1])],
              "G": [_mm(G[0]), _mm(G[1])]}
    if path:
        joints["P"] = [_mm(P[0]), _mm(P[1])]
    return {"title": title, "ground": ["O2", "O4"], "joints": joints,
            "links": {"crank": ["O2", "A"], "block": ["A", "P"] if path else ["A"], "guide": ["O4", "G"]},
            "sliders": {"slot": {"block": "block", "on": "guide", "at": "A", "along": ["O4", "G"]}}}
