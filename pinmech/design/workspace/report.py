"""A workspace study's results for people and programs: a terminal summary, a table (one row
a grid point and working mode; CSV, and Parquet through pyarrow) and a JSON summary.
Lengths in the unit of the study file's grid (its x `from`), angles in deg."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pinmech.design.study.report import write_tables
from pinmech.design.workspace.run import WorkspaceResult


def summary(result: WorkspaceResult) -> dict:
    """The JSON summary: the grid, L, and per working mode the area or volume with its bound
    (and the refinement that got it), per assembly mode likewise, the least and median
    kappa, and the loci's sizes."""
    spec, u = result.spec, result.spec.unit_si
    power = len(result.coords)
    unit = f"{spec.unit}^{power}"
    modes = {}
    for k, mode in enumerate(result.modes):
        m = result.measures[mode]
        kappa = result.values["kappa"][..., k][result.reached[..., k]]
        finite = kappa[np.isfinite(kappa)]
        modes[mode] = {
            result.kind: m.value / u**power, "bound": m.bound / u**power, "reaches_grid_edge": m.edge,
            "assembly_modes": {a: {result.kind: result.measures[f"{mode}/{a}"].value / u**power,
                                   "bound": result.measures[f"{mode}/{a}"].bound / u**power} for a in "+-"},
            "points_reached": int(result.reached[..., k].sum()),
            "refinement": {"halvings": m.depth, "points_solved": m.points},
            "kappa_least": _finite(finite.min()) if finite.size else None,
            "kappa_median": _finite(np.median(finite)) if finite.size else None,
            "type1_locus_points": len(result.type1[mode]), "type2_locus_points": len(result.type2[mode]),
        }
    return {"study": str(spec.path), "title": spec.title, "kind": "workspace", "point": spec.point,
            "motors": list(result.motors), "unit": spec.unit, "measure": result.kind, "measure_unit": unit,
            "characteristic_length": result.length / u,
            "grid": {a.name: {"from": a.start / u, "to": a.stop / u, "count": a.count} for a in spec.axes},
            "locus_bound": result.locus_bound / u, "working_modes": modes}


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def text(result: WorkspaceResult) -> str:
    """The terminal summary."""
    s = summary(result)
    grid = " x ".join(f"{n} {g['from']:.6g}..{g['to']:.6g} ({g['count']})" for n, g in s["grid"].items())
    lines = [f"{s['title']} (workspace of '{s['point']}', motors {', '.join(s['motors'])})",
             f"grid {grid} {s['unit']}; characteristic length L = {s['characteristic_length']:.6g} {s['unit']} "
             f"(kappa of the Jacobian over L); loci within {s['locus_bound']:.3g} {s['unit']}",
             f"{'mode':<8}{s['measure'] + ' [' + s['measure_unit'] + ']':>26}{'assembly +':>26}{'assembly -':>26}"
             f"{'kappa min':>11}{'median':>9}"]
    for mode, e in s["working_modes"].items():
        parts = [_pm(e[s["measure"]], e["bound"])] + [_pm(a[s["measure"]], a["bound"])
                                                     for a in e["assembly_modes"].values()]
        kappa = "".join(f"{v:>11.4g}" if v is not None else f"{'-':>11}" for v in (e["kappa_least"],)) + (
            f"{e['kappa_median']:>9.4g}" if e["kappa_median"] is not None else f"{'-':>9}")
        edge = "  (reaches the grid's edge: the workspace may go on beyond it)" if e["reaches_grid_edge"] else ""
        lines.append(f"{mode:<8}{parts[0]:>26}{parts[1]:>26}{parts[2]:>26}{kappa}{edge}")
    refined = [f"{mode} {e['refinement']['halvings']} halvings, {e['refinement']['points_solved']} more points"
               for mode, e in s["working_modes"].items() if e["refinement"]["points_solved"]]
    if refined:
        lines.append("boundary cells refined: " + "; ".join(refined) + " (bounds hold if the boundary crosses "
                     "each cell edge at most once)")
    return "\n".join(lines)


def _pm(value: float, bound: float) -> str:
    """"35775 +- 9900": whole numbers above 100, else 4 significant digits."""
    if abs(value) >= 100:
        return f"{value:.0f} +- {bound:.0f}"
    return f"{value:.4g} +- {bound:.2g}"


def table(result: WorkspaceResult) -> dict[str, list]:
    """One row a grid point and working mode: coordinates, mode, reached, assembly mode, the
    motors [deg, or the unit], kappa, det and least singular value of K (type I) and
    Phi_p (type II), and the distances to both loci (NaN where not reached)."""
    u, unit = result.spec.unit_si, result.spec.unit
    shape = result.reached.shape
    n_points, n_modes = int(np.prod(shape[:-1])), shape[-1]
    mesh = np.meshgrid(*result.coords, indexing="ij")
    rows: dict[str, list] = {}
    for a, m in zip(result.spec.axes, mesh):
        rows[f"{a.name} [{unit}]"] = np.repeat(m.ravel() / u, n_modes).tolist()
    rows["mode"] = list(result.modes) * n_points
    reached = result.reached.reshape(n_points * n_modes)
    rows["reached"] = reached.tolist()
    det2 = result.values["det2"].reshape(-1)
    rows["assembly"] = [("+" if d > 0 else "-") if r else "" for d, r in zip(det2, reached)]
    motors = result.motor_q.reshape(n_points * n_modes, -1)
    for j, name in enumerate(result.motors):
        rows[f"{name} [deg]"] = np.degrees(motors[:, j]).tolist()
    for key, label in (("kappa", "kappa"), ("det1", "det K (type I)"), ("sigma1", "sigma_min K (type I)"),
                       ("det2", "det Phi_p (type II)"), ("sigma2", "sigma_min Phi_p (type II)")):
        rows[label] = result.values[key].reshape(-1).tolist()
    rows[f"distance to type I [{unit}]"] = (result.dist1.reshape(-1) / u).tolist()
    rows[f"distance to type II [{unit}]"] = (result.dist2.reshape(-1) / u).tolist()
    return rows


def write(result: WorkspaceResult, prefix: str | Path, *, parquet: bool = True) -> list[Path]:
    """PREFIX.csv, PREFIX.json and (with pyarrow) PREFIX.parquet; the paths written."""
    return write_tables(table(result), summary(result), prefix, parquet=parquet)
