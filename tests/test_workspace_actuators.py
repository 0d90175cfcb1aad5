"""Actuator-space workspace studies (`[workspace.actuators]`) against the closed-form forward
kinematics derived here, apart from the engine's Newton:

* five-bar: with the motors held, the elbows B_i = A_i + l1 (cos t_i, sin t_i) are fixed
  and the end point lies on both circles |P - B_i| = l2: P = M +- h n with M the elbows'
  midpoint, h = sqrt(l2^2 - (d/2)^2), n the unit normal of B1B2 (none when d > 2 l2);
* Delta: the elbows E_i = b_i + la (cos a_i u_i - sin a_i z) are fixed and the tool p lies
  on the three spheres |p + r u_i - E_i| = lb: two points mirrored across the plane of the
  centres c_i = E_i - r u_i (trilateration).

Geometry as in tests/test_workspace_study.py (the URDFs' numbers).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import pinmech
from pinmech.cli import main
from pinmech.design.workspace.file import load_workspace
from pinmech.exceptions import SceneError
from tests.test_workspace_study import (A, BETA0, L1, L2, LA, LB, PHI, R_BASE, R_PLAT, SCENES, ZERO, cross2,
                                        delta_motors)


def _actuator_file(tmp_path: Path, scene: str, point: str, axes: dict[str, tuple[float, float, int]],
                   extra: str = "") -> Path:
    lines = "\n".join(f'{name} = {{ from = "{lo} deg", to = "{hi} deg", count = {n} }}'
                      for name, (lo, hi, n) in axes.items())
    path = tmp_path / "actuators.toml"
    path.write_text(f'scene = "{SCENES / scene}"\nkind = "workspace"\nbatch = 40\n[workspace]\npoint = "{point}"\n'
                    f'{extra}\n[workspace.actuators]\n{lines}\n', encoding="utf-8")
    return path


# ------------------------------------------------------------------ five-bar: two circles
def five_bar_elbows(q: np.ndarray) -> np.ndarray:
    """B_i [m] for motor readings q [rad] (URDF zero at 120 and 60 deg)."""
    t = ZERO + q
    return A + L1 * np.column_stack([np.cos(t), np.sin(t)])


def five_bar_forward(q: np.ndarray) -> list[np.ndarray]:
    """The end points [m] on both distal circles: the two circles' intersection."""
    b = five_bar_elbows(q)
    v = b[1] - b[0]
    d = float(np.linalg.norm(v))
    if d > 2 * L2:
        return []
    h = math.sqrt(L2**2 - (d / 2) ** 2)
    n = np.array([-v[1], v[0]]) / d
    mid = (b[0] + b[1]) / 2
    return [mid + h * n, mid - h * n]


def _five_bar_result(tmp_path, count: int = 19):
    path = _actuator_file(tmp_path, "five_bar.toml", "closedloop1_A",
                          {"mot1": (-180, 180, count), "mot2": (-180, 180, count)}, 'length = "60 mm"')
    return pinmech.study(path)


def test_five_bar_forward_kinematics_is_the_two_circles_intersection(tmp_path):
    """At every cell off the fold (|B1B2| not within 1 mm of 2 l2): both assemblies are found
    exactly where the circles meet, at the intersection points (to 1e-9 m: Newton's residual
    1e-10 of the loop size moves P by ~1e-11 m, the intersection is well conditioned there),
    and each assembly slot keeps one side of B1B2 (the sign of cross(P - B1, P - B2))."""
    result = _five_bar_result(tmp_path)
    sides = {0: set(), 1: set()}
    checked = 0
    for idx in np.ndindex(*result.reached.shape[:2]):
        q = np.array([result.coords[0][idx[0]], result.coords[1][idx[1]]])
        b = five_bar_elbows(q)
        if abs(np.linalg.norm(b[1] - b[0]) - 2 * L2) < 1e-3:
            continue
        expected = five_bar_forward(q)
        assert list(result.reached[idx]) == [bool(expected)] * 2, (q, expected)
        for k in range(2) if expected else ():
            p = result.end[idx][k]
            np.testing.assert_allclose(min(np.linalg.norm(p - e) for e in expected), 0.0, atol=1e-9)
            sides[k].add(np.sign(cross2(p - b[0], p - b[1])))
            checked += 1
    assert checked > 200
    assert len(sides[0]) == len(sides[1]) == 1 and sides[0] != sides[1], sides


def test_five_bar_actuator_type_two_locus_is_where_the_elbows_are_two_distal_links_apart(tmp_path):
    """Every actuator-space type II point sits on a grid edge across which |B1B2| - 2 l2
    changes sign (the distal links fold collinear within the edge), and every such edge is on
    the locus (the number of edges matches)."""
    result = _five_bar_result(tmp_path)
    h, coords = result.steps, result.coords

    def gap(q: np.ndarray) -> float:
        b = five_bar_elbows(q)
        return float(np.linalg.norm(b[1] - b[0]) - 2 * L2)

    for assembly in ("+", "-"):
        locus = result.type2[assembly]
        for m in locus:
            ends = [(m - np.eye(2)[a] * h[a] / 2, m + np.eye(2)[a] * h[a] / 2) for a in range(2)]
            lo, hi = next(e for e in ends if all(np.min(np.abs(coords[i] - e[0][i])) < 1e-9 for i in range(2)))
            assert gap(lo) * gap(hi) < 0, (assembly, m)
        grid = np.array([[gap(np.array([x, y])) for y in coords[1]] for x in coords[0]])
        crossings = int(np.sum(grid[1:] * grid[:-1] < 0) + np.sum(grid[:, 1:] * grid[:, :-1] < 0))
        assert len(locus) == crossings, (assembly, len(locus), crossings)


def test_five_bar_actuator_map_on_two_workers_is_the_serial_one_bit_for_bit(tmp_path):
    path = _actuator_file(tmp_path, "five_bar.toml", "closedloop1_A", {"mot1": (-90, 90, 7), "mot2": (-90, 90, 9)})
    serial, spread = pinmech.study(path), pinmech.study(path, workers=2)
    np.testing.assert_array_equal(serial.reached, spread.reached)
    np.testing.assert_array_equal(serial.end, spread.end)
    for key in serial.values:
        np.testing.assert_array_equal(serial.values[key], spread.values[key], err_msg=key)


# ------------------------------------------------------------------ Delta: three spheres
def delta_forward(q: np.ndarray) -> list[np.ndarray]:
    """The tool positions [m] for motor readings q [rad]: the three spheres about
    c_i = E_i - r u_i of radius lb meet in two points mirrored across the centres' plane.
    Trilateration: with e_x, e_y, e_z a frame on c_1, c_2, c_3, x = (d^2) / (2 d) ..."""
    z = np.array([0.0, 0.0, 1.0])
    c = []
    for i in range(3):
        u = np.array([math.cos(PHI[i]), math.sin(PHI[i]), 0.0])
        a = q[i] + BETA0
        elbow = R_BASE * u + LA * (math.cos(a) * u - math.sin(a) * z)
        c.append(elbow - R_PLAT * u)
    ex = (c[1] - c[0]) / np.linalg.norm(c[1] - c[0])
    i_ = ex @ (c[2] - c[0])
    ey = c[2] - c[0] - i_ * ex
    ey /= np.linalg.norm(ey)
    ez = np.cross(ex, ey)
    d, j = float(np.linalg.norm(c[1] - c[0])), float(ey @ (c[2] - c[0]))
    x = d / 2  # equal radii: r1^2 - r2^2 = 0
    y = (i_**2 + j**2 - 2 * i_ * x) / (2 * j)
    h2 = LB**2 - x**2 - y**2
    if h2 < 0:
        return []
    base = c[0] + x * ex + y * ey
    return [base + math.sqrt(h2) * ez, base - math.sqrt(h2) * ez]


def test_delta_forward_kinematics_is_the_three_spheres_intersection(tmp_path):
    """Over a 5 x 5 x 5 grid of motor readings: both assemblies at the trilateration points
    (to 1e-9 m, Newton's residual as above), and the lower one reads back through Clavel's
    inverse kinematics (tests/test_workspace_study.py) to the cell's motors in its mode (1e-8 rad)."""
    path = _actuator_file(tmp_path, "delta.toml", "tool", {f"mot{i}": (-50, 70, 5) for i in (1, 2, 3)})
    result = pinmech.study(path)
    checked = 0
    for idx in np.ndindex(*result.reached.shape[:3]):
        q = np.array([result.coords[k][idx[k]] for k in range(3)])
        expected = delta_forward(q)
        assert list(result.reached[idx]) == [bool(expected)] * 2, (q, expected)
        for k in range(2) if expected else ():
            p = result.end[idx][k]
            np.testing.assert_allclose(min(np.linalg.norm(p - e) for e in expected), 0.0, atol=1e-9)
            checked += 1
            if p[2] < 0:
                back = delta_motors(p, result.modes[idx][k])
                np.testing.assert_allclose((back - q + np.pi) % (2 * np.pi) - np.pi, 0.0, atol=1e-8)
    assert checked == 2 * 125


# ------------------------------------------------------------------ outputs and errors
def test_cli_writes_the_actuator_table_summary_and_maps(tmp_path, capsys):
    import json

    path = _actuator_file(tmp_path, "five_bar.toml", "closedloop1_A", {"mot1": (-90, 90, 7), "mot2": (-90, 90, 9)})
    out = tmp_path / "act"
    assert main(["study", str(path), "--workers", "0", "--out", str(out), "--plot"]) == 0
    printed = capsys.readouterr().out
    assert "actuator space" in printed and "assembly +" in printed
    assert len((tmp_path / "act.csv").read_text().splitlines()) == 1 + 7 * 9 * 2
    summary = json.loads((tmp_path / "act.json").read_text())
    assert summary["space"] == "actuator" and set(summary["assembly_modes"]) == {"+", "-"}
    assert (tmp_path / "act_workspace.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("body, key, message", [
    ('mot1 = { from = "-90 deg", to = "90 deg", count = 5 }\nmotX = { from = "0 deg", to = "9 deg", count = 2 }',
     "workspace.actuators", r"axes \(mot1, motX\) must be the motors \(mot1, mot2\)"),
    ('mot1 = { from = "90 deg", to = "-90 deg", count = 5 }\nmot2 = { from = "0 deg", to = "9 deg", count = 2 }',
     "workspace.actuators.mot1", "from 90 deg is not below to -90 deg"),
    ('mot1 = { from = "-90 deg", to = "90 deg", count = 1 }\nmot2 = { from = "0 deg", to = "9 deg", count = 2 }',
     "workspace.actuators.mot1.count", "count = 1 must be a whole number from 2 to 10000"),
    ('mot1 = { from = "-90 deg", to = "90 deg", count = 5 }', "workspace.actuators", "give 2 or 3 motors' ranges"),
    ('mot1 = { from = "-90 kg", to = "90 deg", count = 5 }\nmot2 = { from = "0 deg", to = "9 deg", count = 2 }',
     "workspace.actuators.mot1.from", "-90 kg. is neither an angle nor a length"),
])
def test_bad_actuator_axes_are_named(tmp_path, body, key, message):
    path = tmp_path / "bad.toml"
    path.write_text(f'scene = "{SCENES / "five_bar.toml"}"\nkind = "workspace"\n[workspace]\npoint = "closedloop1_A"\n'
                    f"[workspace.actuators]\n{body}\n", encoding="utf-8")
    with pytest.raises(SceneError, match=message) as info:
        pinmech.study(path)
    assert key in str(info.value) and str(path) in str(info.value) and "\n" not in str(info.value)


def test_task_axes_beside_actuator_axes_are_refused(tmp_path):
    path = _actuator_file(tmp_path, "five_bar.toml", "closedloop1_A", {"mot1": (-90, 90, 5), "mot2": (-90, 90, 5)},
                          'x = { from = "0 mm", to = "1 mm", count = 2 }')
    with pytest.raises(SceneError, match=r"workspace.x: an actuator-space grid .* takes no x"):
        load_workspace(path)


def test_the_actuator_map_draws_the_assemblys_end_as_a_curve_near_the_closed_form(tmp_path, monkeypatch):
    """The figure, read back: no dots; the type II locus (red) is a contour line whose
    vertices lie where the distal links fold collinear, |B1B2| = 2 l2, to well within a grid
    step h: |B1B2| - 2 l2 changes by at most |d|B1B2|/dq| h, 2 l1 h over a step, and the drawn
    curve is within a quarter of that at 90 % of its vertices (the grid's staircase, which the
    map drew before, sits h/2 off)."""
    import matplotlib
    import matplotlib.pyplot as plt

    matplotlib.use("Agg")
    kept = []
    monkeypatch.setattr(plt, "close", lambda fig=None: kept.append(fig))
    path = _actuator_file(tmp_path, "five_bar.toml", "closedloop1_A", {"mot1": (-180, 180, 37), "mot2": (-180, 180, 37)})
    assert main(["study", str(path), "--workers", "0", "--quiet", "--out", str(tmp_path / "act"), "--plot"]) == 0
    maps = [a for a in kept[0].axes if a.get_xlabel().startswith("mot1")]
    assert len(maps) == 2
    h = math.radians(10.0)
    for ax in maps:
        assert not [x for x in ax.get_lines() if x.get_marker() == "."]
        red = [c for c in ax.collections if hasattr(c, "get_paths") and c.get_edgecolor().size
               and np.allclose(c.get_edgecolor()[0][:3], matplotlib.colors.to_rgb("red"))]
        q = np.radians(np.vstack([p.vertices for c in red for p in c.get_paths() if len(p.vertices)]))
        assert len(q) > 20
        off = np.array([abs(np.linalg.norm(np.subtract(*five_bar_elbows(v)[::-1])) - 2 * L2) for v in q])
        assert np.percentile(off, 90) <= 0.25 * 2 * L1 * h
