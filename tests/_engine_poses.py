"""Poses of the bundled drawn four-bar's coupler solved by the engine: the independent
targets of the motion-synthesis and Burmester tests."""

from __future__ import annotations

from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def engine_poses(crank_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """P [m] and the coupler's angle [rad] (its bar A -> B from x) of the bundled drawn
    four-bar (O2 (0, 0), O4 (100 mm, 0), crank 40, coupler 120, rocker 80 mm), solved by the
    engine at these crank angles [deg] (from the scene's 60 deg, one way)."""
    from pinmech.io.scene import Scene
    from pinmech.io.sweep import Sweep

    sweep = Sweep.from_scene(Scene.load(ROOT / "models/scenes/four_bar_drawn.toml"))
    wanted = np.radians(crank_deg)
    dense = np.unique(np.concatenate((np.radians(np.arange(60.0, 340.0, 1.0)), wanted)))
    rows = {round(p.value, 12): (p.motion.points["P"].position[:2], p.motion.links["coupler"].angle)
            for p in sweep.poses(dense)}
    got = [rows[round(w, 12)] for w in wanted]
    return np.array([g[0] for g in got]), np.array([g[1] for g in got])
