"""Which rows of the compiled kinematics (csrc/kinematics.cpp) each output of
`evaluate_motion` reads: the frames and joints to evaluate for a choice of points,
coincident points and links, resolved by name once per mechanism and choice."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pinmech.exceptions import FrameNotFound
from pinmech.model.mechanism import Mechanism


@dataclass(frozen=True)
class MotionPlan:
    """What evaluate_motion reads for one choice of points, coincident points and links:
    the frames and joints the core evaluates (rows of its answer, in order), and where each
    output finds its rows. Depends on names only: built once per mechanism and choice."""

    frames: np.ndarray  # Pinocchio frame ids (int32)
    joints: np.ndarray  # Pinocchio joint ids (int32), rows after the frames'
    rows: int  # frames and joints
    plane: tuple[list[float], list[float]] | None  # the plane's normal and reference direction (see _plane_angle)
    links: tuple[tuple[str, int], ...]  # name, row
    points: tuple[tuple[str, int, int | None, str], ...]  # name, row, the link's row if coincident, link
    sliders: tuple[tuple[str, str, tuple], ...]  # name, "joint" or "cut", what _slider / _cut_slider read


def motion_plan(mechanism: Mechanism, points: tuple[str, ...] | None, coincident: tuple,
                links: tuple[str, ...] | None, plane_of: Callable) -> MotionPlan:
    """The plan for these names (`coincident`: CoincidentPoints), from the mechanism's cache
    (FrameNotFound for a name it lacks); `plane_of(normal)` gives its `plane`."""
    cache = mechanism.__dict__.setdefault("_motion_plans", {})
    key = (points, coincident, links)
    plan = cache.get(key)
    if plan is None:
        if len(cache) >= _PLANS:
            cache.clear()
        plan = cache[key] = _build_plan(mechanism, points, coincident, links, plane_of)
    return plan


#: Plans kept per mechanism (a caller that asks ever new names rebuilds them).
_PLANS = 64


def _build_plan(mechanism: Mechanism, points: tuple[str, ...] | None, coincident: tuple,
                links: tuple[str, ...] | None, plane_of: Callable) -> MotionPlan:
    frames: dict[int, int] = {}

    def frame(fid: int) -> int:
        return frames.setdefault(int(fid), len(frames))

    def link_frame(name: str) -> int:
        if name not in mechanism.links:
            raise FrameNotFound("link", name, list(mechanism.links), path=mechanism.source)
        return frame(mechanism.links[name])

    link_rows = [(n, link_frame(n)) for n in (links if links is not None else _moving_links(mechanism))]
    point_rows = {}
    for name in points if points is not None else list(mechanism.points):
        match = [c for c in coincident if c.name == name]
        point_rows[name] = (_coincident_plan(mechanism, match[0], frame, link_frame) if match
                            else _point_plan(mechanism, name, frame))
    for c in coincident:
        if c.name not in point_rows:
            point_rows[c.name] = _coincident_plan(mechanism, c, frame, link_frame)
    cuts = [(c.name, "cut", (c, frame(c.parent_frame), frame(c.child_frame))) for c in mechanism.closures
            if c.cut_type == "prismatic" and not (c.name in mechanism.joints
                                                  and mechanism.joints[c.name].kind == "prismatic")]
    joints: dict[int, int] = {}

    def joint_row(jid: int) -> int:  # joint rows follow the frame rows
        return len(frames) + joints.setdefault(int(jid), len(joints))

    tree = []
    for name, j in mechanism.joints.items():
        if j.kind == "prismatic":
            parent = mechanism.model.parents[j.id]
            tree.append((name, "joint", (j, joint_row(j.id), joint_row(parent) if parent else None)))
    return MotionPlan(np.array(list(frames), dtype=np.int32), np.array(list(joints), dtype=np.int32),
                 len(frames) + len(joints), plane_of(mechanism.plane_normal), tuple(link_rows), tuple((n, *r) for n, r in point_rows.items()), tuple(tree + cuts))


def _point_plan(mechanism: Mechanism, name: str, frame: Callable) -> tuple[int, None, str]:
    """A named point's row, None and its link."""
    fid = mechanism.frame_id(name)
    return frame(fid), None, mechanism.link_of_frame(fid)


def _coincident_plan(mechanism: Mechanism, point, frame: Callable, link_frame: Callable) -> tuple[int, int, str]:
    """A CoincidentPoint's row (the point it sits at), its link's row and its link."""
    link = link_frame(point.link)
    return frame(mechanism.frame_id(point.at)), link, point.link


def _moving_links(mechanism: Mechanism) -> list[str]:
    model = mechanism.model
    return [n for n, fid in mechanism.links.items() if model.frames[fid].parentJoint != 0]
