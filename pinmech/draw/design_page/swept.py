"""A planar linkage over every solved pose of a turn at once, from the poses the turn
already swept: each link's frame at each pose (placement, and its first and second
derivatives with respect to the driver) by one compiled call (`frame_paths`), so that the
engine's own diagnostics formulas (`transmission.dyad_angles`) give every pose's angles as
arrays, and the outputs' rates and their derivatives bracket and locate the limit
positions between the poses without solving the turn again.
"""

from __future__ import annotations

import numpy as np

from pinmech.exceptions import DiagnosticError

#: The swept links must sit where the engine's planar linkage puts them (checked at the
#: first pose): lengths ~0.1 m from the same forward kinematics, to rounding.
AGREE_M = 1e-9


class SweptLinkage:
    """`PlanarLinkage`'s `point` and `direction` over N poses: (2, N) arrays (x row, y row).

    Args:
        linkage: the engine's `PlanarLinkage` of the mechanism.
        q: (N, nq) closed configurations; dq, ddq: (N, nv) their first and second
            derivatives with respect to the driver [per rad or per m].
    """

    def __init__(self, linkage, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray) -> None:
        from pinmech.solve.sweep_frames import frame_paths

        self.linkage, self.count = linkage, len(q)
        self.plane = np.array([linkage.e1, linkage.e2])  # (2, 3): world -> plane coordinates
        links = [i for i in linkage.names if i != 0]
        paths = frame_paths(linkage.mechanism, [linkage.names[i] for i in links], q, dq, ddq)
        self._at = {i: k for k, i in enumerate(links)}
        self.paths = paths
        self._check(q[0])

    def point(self, link: int, local: np.ndarray) -> np.ndarray:
        """A point of a link, given in its frame [m], at every pose: (2, N) [m]."""
        if link == 0:
            world = np.broadcast_to(np.asarray(local, dtype=float), (self.count, 3))
        else:
            k = self._at[link]
            world = self.paths.rotation[:, k] @ np.asarray(local, dtype=float) + self.paths.position[:, k]
        return self.plane @ world.T

    def direction(self, link: int, local_axis: np.ndarray) -> np.ndarray:
        """A direction fixed in a link at every pose: (2, N)."""
        if link == 0:
            return np.broadcast_to((self.plane @ np.asarray(local_axis, dtype=float))[:, None], (2, self.count))
        return self.plane @ (self.paths.rotation[:, self._at[link]] @ np.asarray(local_axis, dtype=float)).T

    def turn_rate(self, link: int) -> tuple[np.ndarray, np.ndarray]:
        """A link's turn per unit driver and its derivative [rad per rad or m, and per its square]."""
        k, normal = self._at[link], self.linkage.normal
        return self.paths.angular_velocity[:, k] @ normal, self.paths.angular_acceleration[:, k] @ normal

    def slide_rate(self, link: int, along: np.ndarray, sign: float) -> tuple[np.ndarray, np.ndarray]:
        """A block's travel along the unit plane direction `along` per unit driver, and its
        derivative (a block on a ground slide does not turn: its frame's motion is its own)."""
        k = self._at[link]
        u = along if along.ndim == 2 else along[:, None]
        rate = (self.plane @ self.paths.velocity[:, k].T * u).sum(axis=0)
        change = (self.plane @ self.paths.acceleration[:, k].T * u).sum(axis=0)
        return sign * rate, sign * change

    def _check(self, q0: np.ndarray) -> None:
        """Every pair's place at the first pose as the engine's linkage has it, or DiagnosticError."""
        self.linkage.place(q0)
        for pair in self.linkage.pairs:
            for link, local in zip(pair.links, pair.local):
                gap = np.linalg.norm(self.point(link, local)[:, 0] - self.linkage.point(link, local))
                if gap > AGREE_M:
                    raise DiagnosticError(f"the swept frame of link {self.linkage.names[link]} is {gap:.3g} m "
                                          "from the engine's: the page cannot read its diagnostics from the turn")


def unit_rates(turn) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The turn's solved poses: (driver values x, q, dq/dx, d2q/dx2), from the swept rates
    (v = dq/dx w, a = d2q/dx2 w^2 + dq/dx dw/dt, w the driver's speed)."""
    sweep = turn.sweep
    k = list(sweep.drivers.names).index(sweep.driver)
    w, dw = float(sweep.drivers.v[k]), float(sweep.drivers.a[k])
    solved = ~np.isnan(turn.q).any(axis=1)
    if w == 0.0:
        raise DiagnosticError("the driver's speed is zero: the page's diagnostics need a moving driver")
    dq = turn.v[solved] / w
    return turn.values[solved], turn.q[solved], dq, (turn.a[solved] - dq * dw) / w**2
