"""A study's outputs: their names and kinds, their values over a cycle (all poses in one
call of the compiled core's `frames_along`), and their Jacobians at a pose.

Outputs, in this order (`[outputs]` of the study file):

    points = ["P"]        P.x, P.y (P.z for a spatial mechanism): world position [m]
    links = ["rocker"]    rocker.angle: its x axis about the plane normal [rad]
    sliders = ["slide"]   slide.s: a prismatic joint's coordinate [m]
    sliders (again)       slide.s_dot: its speed [m/s]
    transmission = ["B"]  B.mu: the transmission angle of the dyad whose middle pin is B [rad]
                          (transmission.py)
    omega = ["rocker"]    rocker.omega: angular speed about the plane normal [rad/s]
    alpha = ["rocker"]    rocker.alpha: angular acceleration about the plane normal [rad/s^2]
                          (its sensitivity: accel_sensitivity.py)
    strokes = ["slide"]   slide.stroke: max - min of s over the cycle [m], the same at every
                          pose (stroke.py)
    torque = ["O2"]       O2.torque: the driver's torque [N m] (a prismatic one's force [N])
                          from the scene's masses and loads (torque.py; its
                          sensitivity: variant_differences.py)

Speeds and accelerations are those of the scene's driver speed and acceleration.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmech.exceptions import SceneError
from pinmech.design.study.stroke import Stroke

#: An output's kind -> (users' units per SI unit, the users' unit): lengths in mm, angles in deg.
USER_UNITS = {"length": (1e3, "mm"), "angle": (180 / np.pi, "deg"), "speed": (1e3, "mm/s"),
              "angular speed": (180 / np.pi, "deg/s"), "angular acceleration": (180 / np.pi, "deg/s^2"),
              "torque": (1.0, "N m"), "force": (1.0, "N")}
from pinmech.design.study.torque import DriverTorques
from pinmech.design.study.transmission import dyad_pins, transmission_row, transmission_values
from pinmech.solve.core import _core

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class StudyOutputs:
    """A study's outputs on a StudyMechanism `sm`.

    Attributes:
        names: "P.x", "rocker.angle", "B.mu", "slide.s", "slide.s_dot", "rocker.omega",
            "rocker.alpha", "slide.stroke", "O2.torque" (in this order).
        kinds: "length", "angle", "speed", "angular speed", "angular acceleration", "torque"
            (or "force"), each.
        n_pose: how many outputs (the first ones) depend on q alone.
        alpha_at, strokes_at, torque_at: where those outputs sit in `names` (slices).
    """

    def __init__(self, sm) -> None:
        mech, spec = sm.mechanism, sm.spec
        self.sm, self.normal = sm, mech.plane_normal
        planar = [("links", spec.links), ("omega", spec.omega), ("alpha", spec.alpha)]
        for key, names in planar:
            if names and self.normal is None:
                raise SceneError("link angles and their rates are outputs of planar mechanisms; name points instead",
                                 path=str(spec.path), key=f"outputs.{key}")
            for name in names:
                if name not in mech.links:
                    raise SceneError(f"unknown link '{name}' (the model has: {', '.join(mech.links)})",
                                     path=str(spec.path), key=f"outputs.{key}")
        self.sliders = [_slider(mech, name, spec) for name in spec.sliders]
        self.torques = DriverTorques(sm, spec.torque)
        self.strokes = [Stroke(sm, name, *_slider(mech, name, spec, "outputs.strokes")) for name in spec.strokes]
        self.points = [mech.frame_id(_checked_point(mech, name, spec)) for name in spec.points]
        self.links = [mech.links[name] for name in spec.links]
        self.omega = [mech.links[name] for name in spec.omega]
        self.alpha = [mech.links[name] for name in spec.alpha]
        self.dyads = (dyad_pins(mech, list(sm.solver.drivers), spec.transmission, str(spec.path))
                      if spec.transmission else [])
        self.axes = _plane_axes(self.normal)
        self.names = ([f"{n}.{'xyz'[k]}" for n in spec.points for k in self.axes] + [f"{n}.angle" for n in spec.links]
                      + [f"{n}.mu" for n in spec.transmission] + [f"{n}.s" for n in spec.sliders] + [f"{n}.s_dot" for n in spec.sliders]
                      + [f"{n}.omega" for n in spec.omega] + [f"{n}.alpha" for n in spec.alpha]
                      + [f"{n}.stroke" for n in spec.strokes] + self.torques.names)
        self.kinds = (["length"] * (len(spec.points) * len(self.axes)) + ["angle"] * len(spec.links)
                      + ["angle"] * len(spec.transmission)
                      + ["length"] * len(spec.sliders) + ["speed"] * len(spec.sliders)
                      + ["angular speed"] * len(spec.omega) + ["angular acceleration"] * len(spec.alpha)
                      + ["length"] * len(spec.strokes) + self.torques.kinds)
        end = len(self.names)
        self.torque_at = slice(end - len(spec.torque), end)
        self.strokes_at = slice(self.torque_at.start - len(spec.strokes), self.torque_at.start)
        self.alpha_at = slice(self.strokes_at.start - len(spec.alpha), self.strokes_at.start)
        self.n_pose = len(self.points) * len(self.axes) + len(self.links) + len(self.dyads) + len(self.sliders)
        if self.normal is not None:
            e1 = np.eye(3)[int(np.argmin(np.abs(self.normal)))]
            e1 = e1 - self.normal * (self.normal @ e1)
            self.e1 = e1 / np.linalg.norm(e1)
            self.e2 = np.cross(self.normal, self.e1)
        self.pins = sorted({f for d in self.dyads for f in (d.near, d.joint, d.ground) if f >= 0})
        rows = {f: i for i, f in enumerate(dict.fromkeys(self.points + self.links + self.omega + self.alpha
                                                          + self.pins))}
        self._frames = np.array(list(rows), dtype=np.int32)  # read with the variant's placements at each call
        self._data = sm.model.createData()
        self._index = {key: [rows[f] for f in fs] for key, fs in
                       (("points", self.points), ("links", self.links), ("omega", self.omega), ("alpha", self.alpha),
                        ("pins", self.pins))}
        self._columns(len(spec.sliders))

    def _kinematics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """The frames' kinematics rows (n, F, KINEMATICS_COLUMNS): position 0:3, rotation 3:12,
        linear and angular velocity 12:18, classical linear and angular acceleration 18:24."""
        K = np.empty((len(q), len(self._frames), _core.KINEMATICS_COLUMNS))
        _core.frames_along(self.sm.model, self._data, q, v, a, self._frames, K)
        return K

    def _columns(self, n_sliders: int) -> None:
        """Where each kind of output sits in a row of `names` (slices), and the kinematics
        entries the points and the links' x axes are gathered from, set once."""
        ends = np.cumsum([0, len(self.points) * len(self.axes), len(self.links), len(self.dyads), n_sliders,
                          n_sliders, len(self.omega)])
        _, self._links_at, self._mu_at, self._s_at, self._s_dot_at, self._omega_at = (
            slice(a, b) for a, b in zip(ends[:-1], ends[1:]))
        at = self._index
        self._point_entries = list(enumerate((i, k) for i in at["points"] for k in self.axes))  # (column, (row, k))
        self._x_axes = (np.array(at["links"], dtype=np.intp)[:, None], np.array([3, 6, 9]))  # rotation's 1st column
        self._iq = [iq for iq, _ in self.sliders]
        self._iv = [iv for _, iv in self.sliders]

    def cycle(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """The outputs (steps, n_out) at the poses q with rates v, a (steps, nq / nv) of the
        variant now written in the model [m, rad, m/s, rad/s, rad/s^2], written into `out`
        (steps, n_out) where given (a batch's row), else into a new array."""
        q, v, a = (np.ascontiguousarray(x, dtype=float).reshape(len(q), -1) for x in (q, v, a))
        out = np.empty((len(q), len(self.names))) if out is None else out
        K = self._kinematics(q, v, a) if len(self._frames) else None
        self._pose_into(q, K, out)
        if self.sliders:
            out[:, self._s_dot_at] = v[:, self._iv]
        if self.omega:
            out[:, self._omega_at] = K[:, self._index["omega"], 15:18] @ self.normal
        if self.alpha:
            out[:, self.alpha_at] = K[:, self._index["alpha"], 21:24] @ self.normal
        for j, stroke in enumerate(self.strokes):
            top, _, low, _ = stroke.extremes(q)
            out[:, self.strokes_at.start + j] = top - low
        if self.torques.names:
            out[:, self.torque_at] = self.torques.values(q, v, a)
        return out

    def pose_values(self, q: np.ndarray) -> np.ndarray:
        """The pose outputs (the first n_pose) at one pose q (nq,) [m, rad]."""
        q = np.ascontiguousarray(q, dtype=float).reshape(1, -1)
        out = np.empty((1, self.n_pose))
        zero = np.zeros((1, self.sm.model.nv))
        self._pose_into(q, self._kinematics(q, zero, zero) if len(self._frames) else None, out)
        return out[0]

    def _pose_into(self, q: np.ndarray, K: np.ndarray | None, out: np.ndarray) -> None:
        """Points, link angles, transmission angles, sliders' s at the poses q (n, nq) into
        out's first n_pose columns, from the frames' kinematics rows K (n, F, 24)."""
        if K is not None:
            for column, (row, k) in self._point_entries:  # one strided column each: cheaper than a gather
                out[:, column] = K[:, row, k]
            if self.links:
                x_axes = K[:, self._x_axes[0], self._x_axes[1]]  # (n, links, 3): each link's x axis, world
                out[:, self._links_at] = np.arctan2(x_axes @ self.e2, x_axes @ self.e1)
            x = {f: K[:, i, 0:3] for f, i in zip(self.pins, self._index["pins"])} if self.dyads else {}
            for j, d in enumerate(self.dyads):
                out[:, self._mu_at.start + j] = transmission_values(d, x, self.e1, self.e2)
        if self.sliders:
            out[:, self._s_at] = q[:, self._iq]

    def jacobians(self, data: pin.Data) -> tuple[np.ndarray, np.ndarray]:
        """The pose outputs' (dy/dq on the tangent space (n_pose, nv), dy/dp at fixed q
        (n_pose, n_par)), `data` at q with joint Jacobians and frame placements."""
        model, sm = self.sm.model, self.sm
        n_par = len(sm.placements)
        rows_q, rows_p = [], []
        for f in self.points:
            J = pin.getFrameJacobian(model, data, f, _LWA).reshape(6, -1)
            direct = np.array([place.direction(data) if place.moves_frame(f, sm.subtree) else np.zeros(3)
                               for place in sm.placements]).reshape(-1, 3).T
            rows_q += [J[k] for k in self.axes]
            rows_p += [direct[k] for k in self.axes]
        for f in self.links:
            J = pin.getFrameJacobian(model, data, f, _LWA).reshape(6, -1)
            rows_q.append(self.normal @ J[3:])
            rows_p.append(np.zeros(n_par))
        if self.dyads:
            x = {f: data.oMf[f].translation for f in self.pins}
            J = {f: pin.getFrameJacobian(model, data, f, _LWA).reshape(6, -1)[:3] for f in self.pins}
            direct = {f: np.array([place.direction(data) if place.moves_frame(f, sm.subtree) else np.zeros(3)
                                   for place in sm.placements]).reshape(-1, 3).T for f in self.pins}
            for d in self.dyads:
                rows_q.append(transmission_row(d, x, J, self.e1, self.e2))
                rows_p.append(transmission_row(d, x, direct, self.e1, self.e2))
        for _, iv in self.sliders:
            rows_q.append(np.eye(model.nv)[iv])
            rows_p.append(np.zeros(n_par))
        return np.array(rows_q).reshape(-1, model.nv), np.array(rows_p).reshape(-1, n_par)


def _slider(mech, name: str, spec, key: str = "outputs.sliders") -> tuple[int, int]:
    """(idx_q, idx_v) of a prismatic joint named in outputs.sliders (or `key`)."""
    joint = mech.joints.get(name)
    if joint is None or joint.kind != "prismatic":
        sliders = [n for n, j in mech.joints.items() if j.kind == "prismatic"]
        raise SceneError(f"'{name}' is not a prismatic joint of the model (its sliders: "
                         f"{', '.join(sliders) or 'none'})", path=str(spec.path), key=key)
    return joint.idx_q, joint.idx_v


def _plane_axes(normal: np.ndarray | None) -> tuple[int, ...]:
    """World components reported for points: those in the plane when it is a coordinate plane."""
    if normal is None:
        return (0, 1, 2)
    axis = int(np.argmax(np.abs(normal)))
    return tuple(k for k in range(3) if k != axis) if abs(normal[axis]) > 1 - 1e-12 else (0, 1, 2)


def _checked_point(mech, name: str, spec) -> str:
    if name not in mech.points and name not in mech.links:
        raise SceneError(f"unknown point '{name}' (the model has: {', '.join(mech.points)})", path=str(spec.path),
                         key="outputs.points")
    return name
