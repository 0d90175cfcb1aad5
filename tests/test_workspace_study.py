"""Workspace studies (`kind = "workspace"`) against closed forms derived here, apart from the
engine's Newton: the five-bar's workspace is the intersection of two annuli (its area by the
lens formula), its type II locus is where the distal links are collinear, and the Delta's
inverse kinematics is Clavel's (one equation A cos a + B sin a = C per arm). Conditioning
is checked against the Jacobian of these closed forms by central differences.

Five-bar (models/five_bar/robot.urdf): motors A1 = (0, 0), A2 = (100 mm, 0); proximal
links l1 = 60 mm at 120 deg and 60 deg when the motors read 0; distal links l2 = 90 mm.
Delta (models/delta/robot.urdf): motor i at R = 100 mm on the base circle at phi_i = 0,
120, 240 deg, its arm (la = 100 mm) along R_z(phi_i) R_y(beta0 + q_i) x with beta0 =
0.15637 rad; forearms lb = 250 mm; platform joints at r = 30 mm, u_i = (cos phi_i, sin phi_i, 0).
"""

from __future__ import annotations

import math
from pathlib import Path

import closed_form
import numpy as np
import pytest

import pinmech
from pinmech.cli import main
from pinmech.design.workspace.batch import built
from pinmech.design.workspace.file import WorkspaceSpec, load_workspace
from pinmech.exceptions import FrameNotFound, SceneError

SCENES = Path(__file__).resolve().parents[1] / "models" / "scenes"

# five-bar geometry [m] and the motors' zero directions [rad] (the URDF's rpy)
A = np.array([[0.0, 0.0], [0.1, 0.0]])
L1, L2 = 0.06, 0.09
ZERO = np.radians([120.0, 60.0])

# Delta geometry [m, rad]
R_BASE, R_PLAT, LA, LB, BETA0 = 0.1, 0.03, 0.1, 0.25, 0.1563663122422725
PHI = np.radians([0.0, 120.0, 240.0])


def _study_file(tmp_path: Path, scene: str, body: str, name: str = "ws.toml") -> Path:
    path = tmp_path / name
    path.write_text(f'scene = "{SCENES / scene}"\nkind = "workspace"\n{body}', encoding="utf-8")
    return path


TINY = 'x = { from = "0 mm", to = "1 mm", count = 2 }\ny = { from = "0 mm", to = "1 mm", count = 2 }\n'


def _five_bar(tmp_path: Path, x: str, y: str, modes: str = "", batch: int = 500) -> Path:
    return _study_file(tmp_path, "five_bar.toml", f'batch = {batch}\n[workspace]\npoint = "closedloop1_A"\n'
                       f"x = {x}\ny = {y}\n{modes}\n")


# ------------------------------------------------------------------ five-bar closed forms
def lens_area(r1: float, r2: float, d: float) -> float:
    """Area common to two discs of radii r1, r2 whose centres are d apart: two circular
    segments, each r^2 acos(...) less the kite's triangle (the usual lens formula)."""
    if d >= r1 + r2:
        return 0.0
    if d <= abs(r1 - r2):
        return math.pi * min(r1, r2) ** 2
    a1 = r1**2 * math.acos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1))
    a2 = r2**2 * math.acos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2))
    kite = 0.5 * math.sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2))
    return a1 + a2 - kite


def annuli_area() -> float:
    """|annulus 1 & annulus 2| by inclusion-exclusion over the discs (outer R, inner r):
    |O1 O2| - |O1 I2| - |I1 O2| + |I1 I2|."""
    outer, inner, d = L1 + L2, L2 - L1, float(np.linalg.norm(A[1] - A[0]))
    return lens_area(outer, outer, d) - 2 * lens_area(outer, inner, d) + lens_area(inner, inner, d)


def in_annuli(p: np.ndarray) -> np.ndarray:
    """Whether points p (..., 2) are within l2 - l1 .. l1 + l2 of both motors."""
    d = [np.linalg.norm(p - a, axis=-1) for a in A]
    return np.all([(L2 - L1 <= di) & (di <= L1 + L2) for di in d], axis=0)


def near_circle(p: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Points within tol of a boundary circle (reachable only at a stretched or folded leg)."""
    d = [np.linalg.norm(p - a, axis=-1) for a in A]
    return np.any([(np.abs(di - (L2 - L1)) < tol) | (np.abs(di - (L1 + L2)) < tol) for di in d], axis=0)


def elbow(p: np.ndarray, leg: int, sign: float) -> np.ndarray:
    """B_i with |B - A_i| = l1, |P - B| = l2 and the turn A_i -> B -> P of the given sign
    (the law of cosines, scripts/closed_form.py)."""
    return closed_form.five_bar_elbow(p, A[leg], L1, L2, sign)


def five_bar_motors(p: np.ndarray, mode: str) -> np.ndarray:
    """The motors' readings [rad] (URDF zero at 120 deg and 60 deg) reaching p in `mode`."""
    return closed_form.five_bar_motors(p, mode, A, L1, L2, ZERO)


def collinearity(p: np.ndarray, mode: str) -> float:
    """sin of the angle between the distal links (P - B1, P - B2): 0 on the type II locus."""
    b1, b2 = (elbow(p, i, 1.0 if s == "+" else -1.0) for i, s in enumerate(mode))
    return cross2(p - b1, p - b2) / L2**2


def cross2(a: np.ndarray, b: np.ndarray) -> float:
    """z of the cross product of two plane vectors."""
    return float(a[0] * b[1] - a[1] * b[0])


def wrapped(a: np.ndarray) -> np.ndarray:
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


# ------------------------------------------------------------------ five-bar tests
def test_five_bar_area_is_the_intersection_of_the_two_annuli(tmp_path):
    """The reached area in mode +- equals the lens-formula area within the bound the study states,
    and each grid point is reached exactly where it lies in both annuli."""
    path = _five_bar(tmp_path, '{ from = "-60 mm", to = "160 mm", count = 45 }',
                     '{ from = "-150 mm", to = "150 mm", count = 61 }', 'modes = ["+-"]')
    result = pinmech.study(path)
    exact = annuli_area()  # 0.035596 m^2
    m = result.measures["+-"]
    assert not m.edge
    assert abs(m.value - exact) <= m.bound, (m.value, exact, m.bound)
    # the bound is not vacuous: the boundary strip of a 5 mm grid, under half the area
    assert m.bound < 0.5 * exact
    mesh = np.stack(np.meshgrid(*result.coords, indexing="ij"), axis=-1)
    expected = in_annuli(mesh)
    sure = ~near_circle(mesh)
    np.testing.assert_array_equal(result.reached[..., 0][sure], expected[sure])


def test_five_bar_every_mode_reaches_the_annuli_with_closed_form_motors(tmp_path):
    """All four working modes reach the same region (the annuli), and at each point the
    motors' readings are those of the law-of-cosines elbows of that mode (to 1e-8 rad:
    Newton stops at a residual of 1e-10 of the loop size, and the elbows are well
    conditioned away from the circles)."""
    path = _five_bar(tmp_path, '{ from = "-55 mm", to = "155 mm", count = 15 }',
                     '{ from = "-145 mm", to = "145 mm", count = 21 }')
    result = pinmech.study(path)
    assert result.modes == ("++", "+-", "-+", "--")
    mesh = np.stack(np.meshgrid(*result.coords, indexing="ij"), axis=-1)
    expected, sure = in_annuli(mesh), ~near_circle(mesh, 1e-3)
    for k, mode in enumerate(result.modes):
        np.testing.assert_array_equal(result.reached[..., k][sure], expected[sure], err_msg=mode)
        for idx in zip(*np.nonzero(expected & sure)):
            want = five_bar_motors(mesh[idx], mode)
            np.testing.assert_allclose(wrapped(result.motor_q[idx][k] - want), 0.0, atol=1e-8)


@pytest.mark.parametrize("leg", [0, 1])
@pytest.mark.parametrize("radius", [L2 - L1, L1 + L2])
def test_five_bar_reachability_across_each_annulus_circle(tmp_path, leg, radius):
    """0.1 mm inside a leg's circle the point is reached in every mode; 0.1 mm outside, in none
    (the other leg's distance kept well inside its annulus)."""
    path = _five_bar(tmp_path, '{ from = "0 mm", to = "1 mm", count = 2 }', '{ from = "0 mm", to = "1 mm", count = 2 }')
    wm = built(load_workspace(path))
    # a direction from motor `leg` whose point stays 50 .. 140 mm from the other motor
    direction = {(0, L2 - L1): 90.0, (0, L1 + L2): 60.0, (1, L2 - L1): 90.0, (1, L1 + L2): 120.0}[(leg, radius)]
    u = np.array([math.cos(math.radians(direction)), math.sin(math.radians(direction))])
    inward = 1.0 if radius == L2 - L1 else -1.0  # towards the annulus's inside
    for offset, reached in ((1e-4, True), (-1e-4, False)):
        p = A[leg] + (radius + inward * offset) * u
        other = float(np.linalg.norm(p - A[1 - leg]))
        assert L2 - L1 + 0.02 < other < L1 + L2 - 0.01
        assert [wm.solve(p, mode).reached for mode in wm.modes] == [reached] * 4, (p, offset)


def test_five_bar_type_two_locus_is_where_the_distal_links_are_collinear(tmp_path):
    """Every type II locus point sits on a grid edge across which the closed-form distal links
    swap sides (sin of their angle changes sign: collinear within the edge, i.e. to the grid's
    resolution), and every such edge between reached points is on the locus."""
    path = _five_bar(tmp_path, '{ from = "-50 mm", to = "150 mm", count = 41 }',
                     '{ from = "-140 mm", to = "140 mm", count = 57 }', 'modes = ["+-", "++"]')
    result = pinmech.study(path)
    h = result.steps
    coords = result.coords
    for k, mode in enumerate(result.modes):
        locus = result.type2[mode]
        kept = 0
        for m in locus:
            ends = [(m - np.eye(2)[a] * h[a] / 2, m + np.eye(2)[a] * h[a] / 2) for a in range(2)]
            on_grid = [e for e in ends if all(np.min(np.abs(coords[i] - e[0][i])) < 1e-9 for i in range(2))]
            assert len(on_grid) == 1
            lo, hi = on_grid[0]
            if near_circle(lo) or near_circle(hi):  # a leg stretched there: type I and II meet, no elbow sign
                continue
            c_lo, c_hi = collinearity(lo, mode), collinearity(hi, mode)
            if min(abs(c_lo), abs(c_hi)) < 1e-9:  # a grid point on the locus itself (by symmetry): det's sign is noise
                continue
            assert c_lo * c_hi < 0, (mode, m)
            kept += 1
        assert kept > 10, mode
        # completeness: the closed form's sign changes between reached neighbours (off the circles)
        sign = np.full(result.reached.shape[:2], np.nan)
        for idx in zip(*np.nonzero(result.reached[..., k])):
            p = np.array([coords[0][idx[0]], coords[1][idx[1]]])
            if not near_circle(p) and abs(collinearity(p, mode)) >= 1e-9:
                sign[idx] = np.sign(collinearity(p, mode))
        changes = int(np.sum(sign[1:, :] * sign[:-1, :] < 0) + np.sum(sign[:, 1:] * sign[:, :-1] < 0))
        assert changes == kept, mode


def test_five_bar_kappa_is_that_of_the_closed_form_jacobian(tmp_path):
    """kappa = cond(J) with J = dP/dq_motors, the inverse of the closed-form motors' Jacobian
    dq/dP by central differences (step 1e-7 m: truncation ~1e-14 relative, rounding ~1e-9;
    tolerance 1e-6 relative). With revolute motors and a point, J over L scales uniformly:
    kappa does not depend on L."""
    path = _five_bar(tmp_path, '{ from = "0 mm", to = "1 mm", count = 2 }', '{ from = "0 mm", to = "1 mm", count = 2 }')
    wm = built(load_workspace(path))
    step = 1e-7
    for p, mode in ((np.array([0.05, 0.09]), "+-"), (np.array([0.02, -0.07]), "++"), (np.array([0.11, 0.05]), "-+")):
        dq_dp = np.column_stack([wrapped(five_bar_motors(p + step * e, mode) - five_bar_motors(p - step * e, mode))
                                 / (2 * step) for e in np.eye(2)])
        expected = np.linalg.cond(np.linalg.inv(dq_dp))
        np.testing.assert_allclose(wm.solve(p, mode).kappa, expected, rtol=1e-6)


def test_five_bar_determinants_are_the_closed_form_sines(tmp_path):
    """det K (type I) goes as sin(elbow 1) sin(elbow 2), each leg's det being l1 l2 sin(elbow);
    det Phi_p (type II) as the sine between the distal links, cross(P - B1, P - B2). The rows'
    scales are constant, so ratios between points equal the closed forms' ratios (to 1e-8:
    Newton's residual of 1e-10 moves the sines by about that)."""
    wm = built(load_workspace(_five_bar(tmp_path, '{ from = "0 mm", to = "1 mm", count = 2 }',
                                        '{ from = "0 mm", to = "1 mm", count = 2 }')))

    def sines(p: np.ndarray, mode: str) -> tuple[float, float]:
        b = [elbow(p, i, 1.0 if s == "+" else -1.0) for i, s in enumerate(mode)]
        elbows = [cross2(b[i] - A[i], p - b[i]) / (L1 * L2) for i in range(2)]
        return elbows[0] * elbows[1], collinearity(p, mode)
    reference = np.array([0.05, 0.09])
    for mode in ("+-", "++", "--"):
        s0 = wm.solve(reference, mode)
        k0, c0 = sines(reference, mode)
        for p in (np.array([0.02, -0.07]), np.array([0.11, 0.05]), np.array([-0.02, 0.08]), np.array([0.1, 0.0305])):
            s = wm.solve(p, mode)
            k, c = sines(p, mode)
            np.testing.assert_allclose(s.det1 / s0.det1, k / k0, rtol=1e-8, err_msg=mode)
            np.testing.assert_allclose(s.det2 / s0.det2, c / c0, rtol=1e-8, err_msg=mode)


# ------------------------------------------------------------------ Delta: Clavel's closed form
def delta_roots(p: np.ndarray, leg: int) -> list[tuple[float, float]] | None:
    """Arm i's angles a (from the base plane, positive downwards) whose forearm reaches the
    platform joint p + r u_i, with each root's working-mode sign; None if out of reach.

    Elbow E(a) = b_i + la (cos a u_i - sin a z); |E - (p + r u_i)| = lb with
    D = (R - r) u_i - p gives A cos a + B sin a = C, A = D.u_i, B = -D.z,
    C = (lb^2 - |D|^2 - la^2) / (2 la), so a = atan2(B, A) +- acos(C / hypot(A, B)).
    The mode sign is that of dE/da . (p + r u_i - E): which side of the forearm the arm swings."""
    u = np.array([math.cos(PHI[leg]), math.sin(PHI[leg]), 0.0])
    z = np.array([0.0, 0.0, 1.0])
    D = (R_BASE - R_PLAT) * u - p
    a_, b_ = D @ u, -D @ z
    c_ = (LB**2 - D @ D - LA**2) / (2 * LA)
    rho = math.hypot(a_, b_)
    if abs(c_) > rho:
        return None
    out = []
    for s in (1.0, -1.0):
        a = math.atan2(b_, a_) + s * math.acos(c_ / rho)
        e = R_BASE * u + LA * (math.cos(a) * u - math.sin(a) * z)
        de = LA * (-math.sin(a) * u - math.cos(a) * z)
        out.append((a, float(np.sign(de @ (p + R_PLAT * u - e)))))
    return out


def delta_motors(p: np.ndarray, mode: str) -> np.ndarray | None:
    """The motors' readings q_i = a_i - beta0 [rad] reaching p in `mode`, or None."""
    q = []
    for i, s in enumerate(mode):
        roots = delta_roots(p, i)
        if roots is None:
            return None
        q.append(next(a for a, sign in roots if sign == (1.0 if s == "+" else -1.0)) - BETA0)
    return np.array(q)


def test_delta_reachability_and_motors_are_clavels(tmp_path):
    """Over a box grid, in two working modes: reached exactly where every arm's equation has a
    root (points within 1e-3 of the reach limit |C| = hypot(A, B) left out), and the motors'
    readings are those roots (to 1e-8 rad)."""
    body = ('batch = 200\n[workspace]\npoint = "tool"\nx = { from = "-240 mm", to = "240 mm", count = 9 }\n'
            'y = { from = "-210 mm", to = "210 mm", count = 8 }\nz = { from = "-340 mm", to = "-40 mm", count = 7 }\n'
            'modes = ["+++", "-+-"]\n')
    result = pinmech.study(_study_file(tmp_path, "delta.toml", body))
    mesh = np.stack(np.meshgrid(*result.coords, indexing="ij"), axis=-1)
    checked = 0
    for k, mode in enumerate(result.modes):
        for idx in np.ndindex(*mesh.shape[:3]):
            p = mesh[idx]
            margins = []
            for i in range(3):
                u = np.array([math.cos(PHI[i]), math.sin(PHI[i]), 0.0])
                D = (R_BASE - R_PLAT) * u - p
                margins.append(math.hypot(D @ u, D[2]) - abs((LB**2 - D @ D - LA**2) / (2 * LA)))
            if min(abs(m) for m in margins) < 1e-3:
                continue
            want = delta_motors(p, mode)
            assert result.reached[idx][k] == (want is not None), (mode, p)
            if want is not None:
                np.testing.assert_allclose(wrapped(result.motor_q[idx][k] - want), 0.0, atol=1e-8)
                checked += 1
    assert checked >= 200


def test_delta_kappa_is_that_of_clavels_jacobian(tmp_path):
    """kappa against cond of the inverse of dq/dp from Clavel's closed form by central
    differences (step 1e-7 m; tolerance 1e-6 relative, as for the five-bar)."""
    body = '[workspace]\npoint = "tool"\nx = { from = "0 mm", to = "1 mm", count = 2 }\n' \
           'y = { from = "0 mm", to = "1 mm", count = 2 }\nz = { from = "-200 mm", to = "-199 mm", count = 2 }\n'
    wm = built(load_workspace(_study_file(tmp_path, "delta.toml", body)))
    step = 1e-7
    for p, mode in ((np.array([0.0, 0.0, -0.2]), "+++"), (np.array([0.05, 0.02, -0.25]), "+++"),
                    (np.array([-0.04, 0.06, -0.18]), "-+-")):
        dq_dp = np.column_stack([(delta_motors(p + step * e, mode) - delta_motors(p - step * e, mode)) / (2 * step)
                                 for e in np.eye(3)])
        np.testing.assert_allclose(wm.solve(p, mode).kappa, np.linalg.cond(np.linalg.inv(dq_dp)), rtol=1e-6)


# ------------------------------------------------------------------ Dask, outputs, errors
def test_two_workers_give_the_serial_result_bit_for_bit(tmp_path):
    """A LocalCluster of 2 worker processes solves the same grid, and the same refinement
    points (one halving of the boundary's cells), to the same bits."""
    path = _five_bar(tmp_path, '{ from = "-60 mm", to = "160 mm", count = 9 }',
                     '{ from = "-150 mm", to = "150 mm", count = 11 }', 'modes = ["+-", "-+"]\nrefine_depth = 1',
                     batch=17)
    serial, spread = pinmech.study(path), pinmech.study(path, workers=2)
    assert serial.measures == spread.measures and serial.measures["+-"].points > 0
    np.testing.assert_array_equal(serial.reached, spread.reached)
    np.testing.assert_array_equal(serial.motor_q, spread.motor_q)
    for key in serial.values:
        np.testing.assert_array_equal(serial.values[key], spread.values[key], err_msg=key)


def test_cli_writes_the_table_summary_and_map(tmp_path, capsys):
    """`pinmech study` on a workspace file: the terminal summary names L, the CSV has a row a
    point and mode, the JSON the area with its bound, and the map is a PNG."""
    import json

    path = _five_bar(tmp_path, '{ from = "-60 mm", to = "160 mm", count = 12 }',
                     '{ from = "-150 mm", to = "150 mm", count = 16 }', 'modes = ["+-"]\nlength = "60 mm"')
    out = tmp_path / "ws"
    assert main(["study", str(path), "--workers", "0", "--out", str(out), "--plot"]) == 0
    printed = capsys.readouterr().out
    assert "L = 60 mm" in printed and "area [mm^2]" in printed
    assert len((tmp_path / "ws.csv").read_text().splitlines()) == 1 + 12 * 16
    summary = json.loads((tmp_path / "ws.json").read_text())
    entry = summary["working_modes"]["+-"]
    assert abs(entry["area"] - annuli_area() * 1e6) <= entry["bound"]
    assert (tmp_path / "ws_workspace.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_mechanism_that_is_not_parallel_is_refused(tmp_path, capsys):
    path = _study_file(tmp_path, "four_bar.toml", '[workspace]\npoint = "P"\n' + TINY)
    with pytest.raises(SceneError, match="scene: a workspace study needs a parallel mechanism.*driven by 1"):
        pinmech.study(path)
    assert main(["study", str(path), "--workers", "0"]) == SceneError.exit_code
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(path) in err[0]


def test_a_grid_that_reaches_no_point_is_refused(tmp_path):
    path = _five_bar(tmp_path, '{ from = "300 mm", to = "400 mm", count = 3 }',
                     '{ from = "0 mm", to = "100 mm", count = 3 }', 'modes = ["+-"]')
    with pytest.raises(SceneError, match=r"workspace: no grid point is reachable.*x 300 to 400 mm"):
        pinmech.study(path)


def test_a_missing_or_unknown_end_point_is_named(tmp_path):
    with pytest.raises(SceneError, match="workspace.point.*name the end point"):
        pinmech.study(_study_file(tmp_path, "five_bar.toml", "[workspace]\n" + TINY))
    with pytest.raises(FrameNotFound, match="nowhere"):
        pinmech.study(_study_file(tmp_path, "five_bar.toml", '[workspace]\npoint = "nowhere"\n' + TINY))


def test_modes_of_the_wrong_length_and_axes_of_the_wrong_number_are_named(tmp_path):
    path = _five_bar(tmp_path, '{ from = "0 mm", to = "1 mm", count = 2 }', '{ from = "0 mm", to = "1 mm", count = 2 }',
                     'modes = ["+-+"]')
    with pytest.raises(SceneError, match="workspace.modes.*2 legs"):
        pinmech.study(path)
    body = ('[workspace]\npoint = "closedloop1_A"\nx = { from = "0 mm", to = "1 mm", count = 2 }\n'
            'y = { from = "0 mm", to = "1 mm", count = 2 }\nz = { from = "0 mm", to = "1 mm", count = 2 }\n')
    with pytest.raises(SceneError, match="workspace: 2 motors need 2 grid axes"):
        pinmech.study(_study_file(tmp_path, "five_bar.toml", body))


def test_spec_is_a_workspace_spec(tmp_path):
    path = _five_bar(tmp_path, '{ from = "0 mm", to = "2 mm", count = 3 }', '{ from = "0 mm", to = "1 mm", count = 2 }')
    spec = load_workspace(path)
    assert isinstance(spec, WorkspaceSpec) and spec.size == 6 and spec.unit == "mm"


def test_five_bar_refined_area_holds_the_annuli_area_within_the_tolerance_asked(tmp_path):
    """With area_tolerance = 0.05 on a 10 mm grid, the study's refined interval (the boundary's
    cells halved and their new corners solved by the engine) holds the lens-formula area, and
    its half width is under 5 % of the area; the assembly modes' intervals add up to hold it too."""
    path = _five_bar(tmp_path, '{ from = "-60 mm", to = "160 mm", count = 23 }',
                     '{ from = "-160 mm", to = "160 mm", count = 33 }', 'modes = ["+-"]\narea_tolerance = 0.05')
    result = pinmech.study(path)
    exact = annuli_area()
    m = result.measures["+-"]
    lo, hi = m.interval
    assert lo <= exact <= hi and m.bound <= 0.05 * m.value and m.depth >= 1, (lo, exact, hi, m)
    plus, minus = result.measures["+-/+"].interval, result.measures["+-/-"].interval
    assert plus[0] + minus[0] <= exact <= plus[1] + minus[1]


@pytest.mark.parametrize("line, message", [
    ("area_tolerance = 1.5", r"workspace.area_tolerance: area_tolerance = 1.5 must be a share of the area between 0 and 1"),
    ("area_tolerance = \"1 %\"", r"workspace.area_tolerance: area_tolerance = '1 %' must be a share"),
    ("refine_depth = 11", r"workspace.refine_depth: refine_depth = 11 must be a whole number of halvings from 0 to 10"),
    ("refine_depth = 2.5", r"workspace.refine_depth: refine_depth = 2.5 must be a whole number"),
])
def test_bad_refinement_keys_are_named_with_their_values(tmp_path, line, message):
    path = _five_bar(tmp_path, '{ from = "0 mm", to = "1 mm", count = 2 }', '{ from = "0 mm", to = "1 mm", count = 2 }',
                     line)
    with pytest.raises(SceneError, match=message) as info:
        load_workspace(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


def test_the_map_draws_the_type_two_locus_as_a_curve_within_a_grid_step_of_the_closed_form(tmp_path, monkeypatch):
    """The figure, read back: the type II locus is a contour line (red), not scattered dots,
    and each of its vertices lies within one grid step of the closed form's locus (the distal
    links collinear: their sine changes sign within one step h of the vertex); the edge of
    the workspace is a curve on the annuli's circles (round holes, not the grid's octagons);
    no panel draws dots; the robot's links and its motors' triangles are on every panel."""
    import matplotlib
    import matplotlib.pyplot as plt

    matplotlib.use("Agg")
    kept = []
    monkeypatch.setattr(plt, "close", lambda fig=None: kept.append(fig))
    path = _five_bar(tmp_path, '{ from = "-50 mm", to = "150 mm", count = 21 }',
                     '{ from = "-140 mm", to = "140 mm", count = 29 }', 'modes = ["+-"]')
    assert main(["study", str(path), "--workers", "0", "--quiet", "--out", str(tmp_path / "ws"), "--plot"]) == 0
    (ax,) = [a for a in kept[0].axes if a.get_title().startswith("mode")]
    assert not [x for x in ax.get_lines() if x.get_marker() == "."]  # no dots
    red = [c for c in ax.collections if hasattr(c, "get_paths") and c.get_edgecolor().size
           and np.allclose(c.get_edgecolor()[0][:3], matplotlib.colors.to_rgb("red"))]
    vertices = np.vstack([p.vertices for c in red for p in c.get_paths() if len(p.vertices)]) / 1000.0
    assert len(vertices) > 20
    h = 0.01
    around = h * np.array([[math.cos(a), math.sin(a)] for a in np.linspace(0, 2 * math.pi, 16, endpoint=False)])
    checked = 0
    for v in vertices:
        ring = v + around
        if near_circle(v, 2 * h) or np.any([np.linalg.norm(ring - a, axis=1).min() < L2 - L1 + 1e-6 for a in A]):
            continue  # beside a leg's stretched or folded circle: no elbow there to compare
        try:
            here, signs = collinearity(v, "+-"), [collinearity(p, "+-") for p in ring]
        except ValueError:  # a ring point out of reach
            continue
        assert abs(here) < 1e-12 or min(here * s for s in signs) < 0, v
        checked += 1
    assert checked > 10
    # the edge (type I, black): on the annuli's circles |P - A_i| = l2 - l1 or l1 + l2, most of
    # it well inside a grid step (a drawn staircase of the grid sat h/2 off everywhere; where
    # two circles meet, a corner, the curve cuts across by up to about h/2)
    black = [c for c in ax.collections if hasattr(c, "get_paths") and c.get_edgecolor().size
             and np.allclose(c.get_edgecolor()[0][:3], 0.0)]
    edge = np.vstack([p.vertices for c in black for p in c.get_paths() if len(p.vertices)]) / 1000.0
    off = np.min([np.minimum(np.abs(np.linalg.norm(edge - a, axis=1) - (L2 - L1)),
                             np.abs(np.linalg.norm(edge - a, axis=1) - (L1 + L2))) for a in A], axis=0)
    assert np.median(off) <= 0.15 * h and np.percentile(off, 90) <= 0.35 * h and off.max() <= 0.6 * h
    robot = [x for x in ax.get_lines() if x.get_linewidth() == 4]
    assert len(robot) >= 4  # two proximal and two distal links
    assert sum(type(p).__name__ == "Polygon" for p in ax.patches) >= 2  # the motors' triangles
