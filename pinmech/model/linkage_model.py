"""A drawn linkage as a Mechanism: its URDF written (`pinmech build`) or cached, loaded
with the drawn pose as the reference, and its pins added as points (`linkage.py` reads the
file, `linkage_urdf.py` writes the tree)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pinmech.exceptions import ModelError
from pinmech.model.linkage import Linkage, parse_linkage

def build_urdf(path: str | Path, output: str | Path) -> Linkage:
    """`pinmech build`: write the URDF of a linkage file to `output` (whole, or not at all)."""
    from pinmech.model.linkage_urdf import linkage_urdf

    linkage = parse_linkage(path)
    text, _ = linkage_urdf(linkage)
    _write_whole(Path(output), text)
    return linkage


def _write_whole(path: Path, text: str) -> None:
    """Through a temporary file beside `path`, renamed when whole (outputs.write_whole:
    never a half-written URDF; the mode an ordinary write gives, or the old file's)."""
    from pinmech.outputs import write_whole

    write_whole(path, text)


def _cached_urdf(text: str) -> Path:
    """The generated URDF in this user's private cache folder, named by its content (for
    drawings); see `pinmech.user_cache`."""
    from pinmech.user_cache import cached_text

    return cached_text("linkage", ".urdf", text)


def load_linkage(path: str | Path, *, locked: dict[str, float] | None = None):
    """A linkage file as a Mechanism, its reference configuration the drawn pose.

    Args:
        path: the linkage file (TOML).
        locked: joints to lock, name -> value [rad or m] (as `Mechanism.from_urdf`).

    Raises:
        ModelError: anything wrong in the file (one line naming the file and the key).
    """
    return linkage_mechanism(parse_linkage(path), locked=locked)


def linkage_mechanism(linkage: Linkage, *, locked: dict[str, float] | None = None):
    """A drawn linkage (`linkage_from_spec`, `parse_linkage`) as a Mechanism, its reference
    configuration the drawn pose and its pins named points.

    Args:
        linkage: the linkage, drawn in SI.
        locked: joints to lock, name -> value [rad or m] (as `Mechanism.from_urdf`).

    Raises:
        ModelError: a URDF pinmech generated that Pinocchio refuses (named as such), a
            locked joint the linkage lacks.
    """
    from pinmech.model.linkage_urdf import linkage_urdf
    from pinmech.model.mechanism import Mechanism

    text, reference = linkage_urdf(linkage)
    urdf = _cached_urdf(text)

    def built(held: dict[str, float] | None):
        try:
            mech = Mechanism.from_urdf(urdf, locked=held, reference=reference)
        except ModelError as exc:  # pinmech's own URDF refused: say so, never "the user's file is no URDF"
            said = str(exc).replace(f"{urdf}: ", "").replace(str(urdf), "it")
            raise ModelError(f"the URDF pinmech generated from it ({urdf}) is refused: {said}",
                             path=linkage.source) from exc
        mech.source, mech.urdf_path = linkage.source, str(urdf)
        mech.mass_source = "mass under the linkage's [masses]"
        mech.massless_links = tuple(n for n in mech.links if n not in linkage.links or n in linkage.hidden)
        mech.limits = {}  # a drawing states no limits: the URDF's slide <limit> is a formality
        return mech

    from pinmech.model.linkage_pins import add_pin_frames, pin_places

    mech = built(None)
    _check_closed(mech)  # as drawn; a joint held at another value than drawn opens the drawn pose,
    pins = {n: p for n, p in linkage.points.items()
            if n not in linkage.point_links and any(n in names for names in linkage.links.values())}
    places = pin_places(mech, pins, linkage.links)  # (which the solver closes from there)
    mech = built(locked) if locked else mech
    add_pin_frames(mech, places)
    return mech


def joint_kinds(path: str | Path) -> dict[str, str]:
    """Joint name -> "revolute" or "prismatic" of a linkage file's tree and cut joints."""
    linkage = parse_linkage(path)
    return {e.name: e.kind for e in linkage.edges}


def _check_closed(mech) -> None:
    """The drawn pose closes every loop (a guard: it does by construction)."""
    from pinmech.model.closure_core import closure_rows

    rows = closure_rows(mech)
    residual = rows.residual(mech.reference)
    for closure, at in zip(mech.closures, rows.slices):
        gap = float(np.max(np.abs(residual[at]), initial=0.0))
        if gap > 1e-9:
            raise ModelError(f"loop cut {closure.name} is open by {gap:.3g} (relative) at the drawn pose",
                             path=mech.source)
