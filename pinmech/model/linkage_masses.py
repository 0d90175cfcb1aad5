"""Masses of a drawn linkage's links, as its file states them (`[masses]`), never invented.

    [masses]
    crank = { mass = "0.4 kg", at = "O", izz = "2e-4 kg*m^2" }          # at: a joint's name
    rod = { mass = "0.6 kg", at = ["100 mm", "25 mm"], izz = "7.2e-4 kg*m^2" }   # or coordinates

`at` is the centre of mass at the drawn pose (a name of `[joints]` or world coordinates,
lengths as anywhere in the file); `izz` the moment of inertia about the centre of mass and
the plane's normal. A spatial linkage gives the whole tensor about the centre of mass, in
world axes at the drawn pose: `inertia = [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`, each with units.
A link the table leaves out has no mass: forces on it are refused unless the scene lists it
in `[forces] massless`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pinmech.exceptions import ModelError, UnitError
from pinmech.model.linkage_entries import MassSpec
from pinmech.units import to_si

_PLANAR_KEYS = {"mass", "at", "izz"}
_SPATIAL_KEYS = {"mass", "at", "inertia"}


@dataclass(frozen=True)
class LinkMass:
    """One link's mass as the file gives it, world frame at the drawn pose.

    Attributes:
        mass: [kg], positive.
        centre: centre of mass [m], world frame at the drawn pose (2 or 3 coordinates).
        inertia: about the centre of mass, world axes at the drawn pose [kg m^2], (3, 3);
            for a planar linkage diag(izz/2, izz/2, izz) (a lamina: the in-plane answers
            use izz alone).
    """

    mass: float
    centre: np.ndarray
    inertia: np.ndarray


def parse_masses(masses: dict[str, MassSpec], points: dict[str, np.ndarray], spatial: bool, length,
                 source: str) -> dict[str, LinkMass]:
    """The `[masses]` table (its links and names checked by `LinkageSpec`): link -> LinkMass.

    Args:
        length: the file's reader of lengths, (value, where) -> [m].

    Raises:
        ModelError: izz in a spatial linkage or inertia in a planar one, a key missing, a
            unit of the wrong kind, a mass that is not positive, a tensor that is not a
            physical inertia.
    """
    out = {}
    for link, spec in masses.items():
        where = f"[masses] {link}"
        keys = _SPATIAL_KEYS if spatial else _PLANAR_KEYS
        if {key for key in _SPATIAL_KEYS | _PLANAR_KEYS if getattr(spec, key) is not None} != keys:
            example = ('{ mass = "0.4 kg", at = "G", inertia = ["1e-4 kg*m^2", ...6 values] }' if spatial
                       else '{ mass = "0.4 kg", at = "G", izz = "2e-4 kg*m^2" }')
            raise ModelError(f"give exactly {', '.join(sorted(keys))}: {example}", path=source, element=where)
        out[link] = LinkMass(_mass(spec.mass, source, where), _centre(spec.at, points, length, where),
                             _inertia(spec, spatial, source, where))
    return out


def _quantity(value: Any, kind: str, source: str, where: str) -> float:
    try:
        return to_si(value, kind, where=where)
    except UnitError as exc:
        raise ModelError(str(exc), path=source) from exc


def _mass(value: Any, source: str, where: str) -> float:
    mass = _quantity(value, "mass", source, f"{where} mass")
    if not mass > 0:
        raise ModelError(f"mass = {value!r}: a mass is positive (leave a massless link out of [masses] and "
                         "list it in the scene's [forces] massless)", path=source, element=where)
    return mass


def _centre(value: str | tuple, points: dict[str, np.ndarray], length, where: str) -> np.ndarray:
    """A joint's position (a name, checked by the spec) or [x, y] / [x, y, z] as written [m]."""
    if isinstance(value, str):
        return points[value]
    return np.array([length(v, f"{where} at {c}") for v, c in zip(value, "xyz")])


def _inertia(spec: MassSpec, spatial: bool, source: str, where: str) -> np.ndarray:
    """About the centre of mass, world axes [kg m^2]; physical (symmetric, eigenvalues >= 0
    and each at most the sum of the other two)."""
    if not spatial:
        izz = _quantity(spec.izz, "moment_of_inertia", source, f"{where} izz")
        if izz < 0:
            raise ModelError(f"izz = {spec.izz!r} is negative", path=source, element=where)
        return np.diag([izz / 2, izz / 2, izz])
    values = list(spec.inertia)
    if len(values) != 6:
        raise ModelError(f"inertia = {values!r}: give [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] about the centre of mass, "
                         "world axes at the drawn pose, each with units", path=source, element=where)
    xx, yy, zz, xy, xz, yz = (_quantity(v, "moment_of_inertia", source, f"{where} inertia") for v in values)
    tensor = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    principal = np.linalg.eigvalsh(tensor)
    slack = 1e-12 * max(float(np.max(np.abs(principal))), 1e-300)
    if principal[0] < -slack or principal[2] > principal[0] + principal[1] + slack:
        raise ModelError(f"inertia = {values!r} is no body's: its principal moments {principal.tolist()} kg m^2 "
                         "must be positive, each at most the sum of the other two", path=source, element=where)
    return tensor
