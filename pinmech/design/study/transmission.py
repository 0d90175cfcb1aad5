"""Transmission angles as study outputs: a dyad's angle from its pins' places, and its
derivative by the chain rule through the pins' position derivatives.

A pin dyad A-B-O (coupler pins A and B, the output's ground pivot O) has the transmission
angle mu = angle(A - B, O - B) in [0, pi] (solve/transmission.py's `dyad_angles`); a
slider dyad (the output a block on a ground slide of direction u) has mu = pi/2 - phi,
phi = the acute angle between the rod A - B and u. In the plane, with the signed angle
psi = arg(b) - arg(a): d psi = (b_perp . db) / |b|^2 - (a_perp . da) / |a|^2, a_perp =
(-a_y, a_x), and mu = |psi| moves by sign(psi) d psi. Each pin is a Pinocchio frame (a
tree joint's own frame, or a loop cut's frame on its parent side), whose position
derivative the study already has (outputs.py), so the derivative is exact wherever
mu is not 0 or pi (a dead centre, where the angle has a corner).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmech.exceptions import DiagnosticError, SceneError
from pinmech.model.planar_linkage import planar_linkage
from pinmech.solve.transmission import find_dyads


@dataclass(frozen=True)
class DyadPins:
    """A dyad's pins as frame ids: near A, joint B, ground pivot O (-1 for a slider
    dyad), and the slide's world direction u (slider dyad) [unit]."""

    name: str
    near: int
    joint: int
    ground: int
    slide: np.ndarray | None


def dyad_pins(mechanism, drivers: list[str], names: tuple[str, ...], path: str) -> list[DyadPins]:
    """The dyads named by their middle pin (`transmission = ["B"]`).

    Raises:
        SceneError: a mechanism without dyads, or a name that is not a dyad's middle pin
            (naming the study file and the dyads there are).
    """
    try:
        linkage = planar_linkage(mechanism)
        dyads = [d for d in find_dyads(linkage, drivers) if d.kind in ("pin", "slide")]
    except DiagnosticError as exc:
        raise SceneError(f"transmission angles are outputs of planar linkages of pins and slides: {exc}",
                         path=path, key="outputs.transmission") from exc
    by_pin = {d.joint.name: d for d in dyads}
    out = []
    for name in names:
        if name not in by_pin:
            raise SceneError(f"'{name}' is not the middle pin of a pin or slider dyad (the dyads' pins: "
                             f"{', '.join(by_pin) or 'none'})", path=path, key="outputs.transmission")
        d = by_pin[name]
        frames = [_pin_frame(mechanism, pair) for pair in (d.near, d.joint)]
        if d.kind == "pin":
            out.append(DyadPins(name, *frames, _pin_frame(mechanism, d.ground), None))
        else:
            u = linkage.data.oMi[d.ground.links[0]].rotation @ d.ground.axis
            out.append(DyadPins(name, *frames, -1, u / np.linalg.norm(u)))
    return out


def transmission_values(pins: DyadPins, x: dict[int, np.ndarray], e1: np.ndarray, e2: np.ndarray) -> np.ndarray:
    """mu at each pose [rad], from the pins' world positions x[frame] (n, 3) [m]."""
    a, b = _vectors(pins, x, e1, e2)
    psi = np.arctan2(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0], np.sum(a * b, axis=-1))
    mu = np.abs(psi)
    return mu if pins.ground >= 0 else np.pi / 2 - np.minimum(mu, np.pi - mu)


def transmission_row(pins: DyadPins, x: dict[int, np.ndarray], dx: dict[int, np.ndarray], e1: np.ndarray,
                     e2: np.ndarray) -> np.ndarray:
    """d mu / d(anything) at one pose: x[frame] (3,) positions, dx[frame] (3, m) their
    derivatives [m per unit] -> (m,) [rad per unit]."""
    plane = np.vstack([e1, e2])
    a, b = _vectors(pins, {f: v[None] for f, v in x.items()}, e1, e2)
    a, b = a[0], b[0]
    da = plane @ (dx[pins.near] - dx[pins.joint])
    db = plane @ (dx[pins.ground] - dx[pins.joint]) if pins.ground >= 0 else np.zeros_like(da)
    perp = lambda w: np.array([-w[1], w[0]])  # noqa: E731
    dpsi = perp(b) @ db / (b @ b) - perp(a) @ da / (a @ a)
    psi = np.arctan2(a[0] * b[1] - a[1] * b[0], a @ b)
    dmu = np.sign(psi) * dpsi
    if pins.ground >= 0:
        return dmu
    return -dmu if abs(psi) < np.pi / 2 else dmu


def _vectors(pins: DyadPins, x: dict[int, np.ndarray], e1: np.ndarray, e2: np.ndarray):
    """(A - B, O - B or the slide's direction) in plane coordinates, (n, 2) each."""
    plane = np.vstack([e1, e2]).T
    a = (x[pins.near] - x[pins.joint]) @ plane
    b = (x[pins.ground] - x[pins.joint]) @ plane if pins.ground >= 0 else np.broadcast_to(pins.slide @ plane, a.shape)
    return a, b


def _pin_frame(mechanism, pair) -> int:
    """The frame at a pin: a tree joint's own frame, or a loop cut's frame on its parent side."""
    model = mechanism.model
    if pair.name in mechanism.joints:
        return int(model.getFrameId(pair.name, pin.FrameType.JOINT))
    for c in mechanism.closures:
        if c.name == pair.name:
            return int(c.parent_frame)
    raise SceneError(f"the pin '{pair.name}' of a dyad is neither a joint nor a loop cut of the model",
                     path=mechanism.source, key="outputs.transmission")
