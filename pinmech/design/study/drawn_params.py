"""A drawn linkage's `[params]` as study parameters (`param = "crank"` in a study file).

A param written with an angle's unit ("25 deg": a bearing construction's angle) is an
angle parameter: its values in rad, its sensitivities per rad.

A variant is the linkage's points redrawn with the changed lengths (`linkage_from_spec`
with the values: the compass and polar constructions move other drawn points and turn the
frames built from them) and its joint and frame placements, rotations included, computed
from them (model/linkage_placements.py) and written into the study's `pin.Model` in place;
no URDF is written and no model built (frames the scene adds, such as its own [points],
keep theirs in their links).

The exact sensitivity needs the drawing's derivative: the placements at p +- STEP (the
drawing is a closed-form construction, smooth away from a compass that cannot close) are
kept, and the closure residual's and the pose outputs' derivatives at fixed q (and the
velocity rows' and frames' velocities at fixed q and v, rate_sensitivity.py) are their
central differences over those two drawings; sensitivity.py composes them exactly with the
implicit-function theorem. Truncation (STEP / L)^2 ~ 1e-10 of a 0.1 m linkage, rounding
1e-16 L / STEP ~ 1e-11: far below the 1e-7 the tests hold them to.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.exceptions import FrameNotFound, ModelError, SceneError

STEP = 1e-6  # [m] the drawing's central differences (see the module)


class Drawing:
    """A scene's drawn linkage bound to the study's model: its params' values [m] and the
    placements each set of values draws."""

    def __init__(self, scene, mechanism, where: str) -> None:
        from pinmech.model.linkage import linkage_params, param_kinds
        from pinmech.model.linkage_spec import read_linkage_spec

        if scene.model_kind != "linkage":
            raise SceneError(f"param = names a drawn linkage's [params]; this scene's model is given by "
                             f"'{scene.model_kind}'", path=where, key="params")
        self.spec, self.source = read_linkage_spec(scene.model_file("linkage"))
        self.model, self.urdf_path = mechanism.model, getattr(mechanism, "urdf_path", None)
        self.values: dict[str, float] = linkage_params(self.spec, self.source)  # [m], angles [rad]
        self.kinds = param_kinds(self.spec)
        self._drawn: dict[tuple, list] = {}
        self._placed = None  # the placements' rules (model/linkage_placements.py), at the first drawing

    def placements(self, values: dict[str, float]) -> list[tuple[str, int, np.ndarray, np.ndarray]]:
        """The placements the linkage draws with these params: (kind, index in the study's
        model, rotation, translation [m]) for each joint and frame it has (kept per set of values)."""
        key = tuple(sorted(values.items()))
        if key not in self._drawn:
            if len(self._drawn) > 64:  # a tolerance study's nominals do not repeat: keep the cache small
                self._drawn.clear()
            self._drawn[key] = self._draw(values)
        return self._drawn[key]

    def write(self, values: dict[str, float]) -> None:
        """Draw with `values` [m] and write the placements into the study's model in place."""
        self.apply(self._draw(values))
        self.values = dict(values)

    def set(self, changed: dict[str, float]) -> None:
        """Write these params' values [m or rad] (the others kept): one redrawing, none if
        nothing changed."""
        if any(self.values[n] != v for n, v in changed.items()):
            self.write({**self.values, **changed})

    def apply(self, placements: list[tuple[str, int, np.ndarray, np.ndarray]]) -> None:
        """Write drawn placements (DrawnPlacements.placements) into the study's model in place."""
        self._placed.write(placements)

    def _draw(self, values: dict[str, float]) -> list[tuple[str, int, np.ndarray, np.ndarray]]:
        from pinmech.model.linkage import linkage_from_spec

        try:  # every value given: the spec holds the file's, not the last drawing's
            linkage = linkage_from_spec(self.spec, self.source, values)
            if self._placed is None:  # the rules checked once against the loaded model
                from pinmech.model.linkage_placements import DrawnPlacements

                self._placed = DrawnPlacements(linkage_from_spec(self.spec, self.source, self.values), self.model)
            return self._placed.placements(linkage)
        except ModelError as exc:
            changed = {n: v for n, v in values.items() if v != self.values.get(n)} or values
            shown = ", ".join(f"{n} = {np.degrees(v):.6g} deg" if self.kinds.get(n) == "angle" else
                              f"{n} = {v * 1e3:.6g} mm" for n, v in changed.items())
            raise ModelError(f"the linkage cannot be drawn with {shown}: {exc}", path=self.source) from exc


class DrawnPlacement:
    """One drawn param as a study parameter (the Placement protocol of params.py:
    read, write), with the drawing's central differences for the exact sensitivity."""

    drawn = True
    written_in = 0  # no translation of its own (rate_sensitivity.py reads it, with u = 0)

    def __init__(self, drawing: Drawing, param, where: str) -> None:
        name = param.element
        if name not in drawing.values:
            raise FrameNotFound("param (a drawn linkage's [params])", name, list(drawing.values), path=where)
        self.drawing, self.name, self.kind = drawing, name, drawing.kinds[name]
        given = param.nominal is not None or param.spread > 0 or np.isfinite([param.lower, param.upper]).any()
        if given and param.kind != self.kind:
            unit = "deg" if self.kind == "angle" else "mm"
            raise SceneError(f"the linkage's {name} is {'an' if self.kind == 'angle' else 'a'} {self.kind}, and this "
                             f"parameter's values are {param.kind}s: give them in {unit}", path=where, key="params")

    def read(self) -> float:
        return float(self.drawing.values[self.name])

    def write(self, value: float) -> None:
        self.drawing.set({self.name: float(value)})

    def direction(self, data: pin.Data) -> np.ndarray:
        """No translation of its own (the study's exact rows take `column` instead)."""
        return np.zeros(3)

    def moves_frame(self, frame: int, subtree: dict) -> bool:
        return False

    def column(self, evaluate) -> np.ndarray:
        """d evaluate()/dp at fixed q: evaluate() read on the drawings at p +- STEP (the
        other params as they are), the model given back its placements afterwards."""
        drawing, values = self.drawing, self.drawing.values
        ends = []
        for sign in (+1.0, -1.0):
            drawing.apply(drawing.placements({**values, self.name: values[self.name] + sign * STEP}))
            ends.append(np.asarray(evaluate(), dtype=float))
        drawing.apply(drawing.placements(values))
        return (ends[0] - ends[1]) / (2.0 * STEP)
