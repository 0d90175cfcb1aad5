"""A redrawn linkage's placements written in place (model/linkage_placements.py): a design
study's or a synthesis candidate's variant without a URDF written or a model built.

References: the compass construction written here with numpy (two circles' intersection)
for where the redrawn linkage's joints are, and the model Pinocchio loads from the
redrawn linkage's own URDF for which placements those are."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pinmech.exceptions import ModelError
from pinmech.model.linkage import linkage_from_spec, linkage_params
from pinmech.model.linkage_model import linkage_mechanism
from pinmech.model.linkage_placements import DrawnPlacements
from pinmech.model.linkage_spec import read_linkage_spec
from tests.tolerance import rounding

LINKAGES = Path(__file__).resolve().parents[1] / "models" / "linkages"


def _circles(a: np.ndarray, b: np.ndarray, r1: float, r2: float) -> np.ndarray:
    """The point at r1 from a and r2 from b, left of a -> b (law of cosines) [m]."""
    d = np.linalg.norm(b - a)
    along = (d * d + r1 * r1 - r2 * r2) / (2 * d)
    u = (b - a) / d
    return a + along * u + math.sqrt(r1 * r1 - along * along) * np.array([-u[1], u[0]])


def test_watt_redrawn_in_place_closes_at_the_compass_points():
    """models/linkages/watt_params.toml with every param changed by up to 5 %: the
    placements written into the template's model are those of the model loaded from the
    redrawn linkage's URDF (to 1e-15 m: the same float operations up to rounding), and at
    that model's drawn pose the written model's cut frames meet and its pins and P sit at
    the compass points computed here in numpy from the new params (1e-12 m: rounding of a
    few trigonometric operations on 0.2 m)."""
    spec, source = read_linkage_spec(LINKAGES / "watt_params.toml")
    params = linkage_params(spec, source)
    template = linkage_mechanism(linkage_from_spec(spec, source))
    model = pin.Model(template.model)
    placed = DrawnPlacements(linkage_from_spec(spec, source, params), model)
    rng = np.random.default_rng(3)
    p = {n: v * (1 + 0.05 * rng.uniform(-1, 1)) for n, v in params.items()}
    placed.write(placed.placements(linkage_from_spec(spec, source, p)))
    fresh = linkage_mechanism(linkage_from_spec(spec.with_params(**p), source))
    for j in range(1, model.njoints):
        assert np.allclose(model.jointPlacements[j].homogeneous, fresh.model.jointPlacements[j].homogeneous,
                           rtol=0, atol=rounding(1.0))
    data = model.createData()
    pin.framesForwardKinematics(model, data, fresh.reference)
    at = {f.name: data.oMf[i].translation[:2] for i, f in enumerate(model.frames)}
    O4, O6 = np.array([p["ground"], 0.0]), np.array([p["O6x"], p["O6y"]])  # O2 at the origin
    A = np.array([p["crank"], 0.0])
    B = _circles(A, O4, p["coupler"], p["rocker"])
    C = _circles(B, O4, p["BC"], p["O4C"])  # right of O4 -> B is left of B -> O4
    D = _circles(C, O6, p["link5"], p["link6"])
    P = _circles(C, D, p["CP"], p["DP"])
    for name, want in (("B", B), ("D", D), ("P", P), ("B__parent", B), ("B__child", B), ("D__parent", D),
                       ("D__child", D)):
        assert np.allclose(at[name], want, rtol=0, atol=rounding(0.2)), name
    assert np.allclose(data.oMi[model.getJointId("C")].translation[:2], C, rtol=0, atol=rounding(0.2))


def test_a_param_that_turns_a_slide_is_refused(tmp_path):
    """A slider whose line runs along O -> S, S drawn at a param: redrawn with S elsewhere,
    the slide turns (its joint's axis, not a placement): refused by name, not written."""
    path = tmp_path / "turned.toml"
    path.write_text('ground = ["O", "S"]\n[params]\nsy = "50 mm"\n'
                    '[joints]\nO = ["0 mm", "0 mm"]\nS = ["200 mm", "sy"]\nA = ["40 mm", "0 mm"]\n'
                    'B = { from = ["A", "O"], lengths = ["130 mm", "150 mm"], side = "left" }\n'
                    '[links]\ncrank = ["O", "A"]\nrod = ["A", "B"]\npiston = ["B"]\n'
                    '[sliders]\nslide = { block = "piston", on = "ground", at = "B", along = ["O", "S"] }\n')
    spec, source = read_linkage_spec(path)
    mech = linkage_mechanism(linkage_from_spec(spec, source))
    placed = DrawnPlacements(linkage_from_spec(spec, source, {"sy": 0.05}), mech.model)
    placed.placements(linkage_from_spec(spec, source, {"sy": 0.05}))  # as drawn: accepted
    with pytest.raises(ModelError, match="slide slide turns"):
        placed.placements(linkage_from_spec(spec, source, {"sy": 0.06}))
