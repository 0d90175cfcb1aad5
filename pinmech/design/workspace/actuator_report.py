"""An actuator-space workspace study's results for people and programs: a terminal summary,
a table (one row a cell of the motors' grid and assembly mode; CSV, and Parquet through
pyarrow) and a JSON summary. Motor turns in deg, lengths in the study's unit (that of
`length`, mm by default)."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

import numpy as np

from pinmech.design.study.report import write_tables
from pinmech.design.workspace.actuator import ActuatorResult
from pinmech.design.workspace.actuator_batch import ASSEMBLIES

_AXES = "xyz"


def _scales(result: ActuatorResult) -> list[tuple[float, str]]:
    """Each motor axis's (SI -> shown factor, unit): deg for a turn, the study's unit for a slide."""
    u, unit = result.spec.unit_si, result.spec.unit
    return [(math.degrees(1.0), "deg") if a else (1.0 / u, unit) for a in result.angular]


def summary(result: ActuatorResult) -> dict:
    """The JSON summary: the grid, L, and per assembly mode the cells found, the region's
    area (volume) in actuator space with its bound, its working modes, the box its end
    points fill, kappa's least and median value and the loci's sizes."""
    spec, u = result.spec, result.spec.unit_si
    scales = _scales(result)
    power = math.prod(s for s, _ in scales)
    region_unit = "*".join(unit for _, unit in scales)
    out = {}
    for k, a in enumerate(ASSEMBLIES):
        here = result.reached[..., k]
        kappa = result.values["kappa"][..., k][here]
        finite = kappa[np.isfinite(kappa)]
        ends = result.end[..., k, :][here] / u
        m = result.measures[a]
        out[a] = {"cells": int(here.sum()), "region": m.value * power, "bound": m.bound * power,
                  "reaches_grid_edge": m.edge,
                  "working_modes": dict(sorted(Counter(result.modes[..., k][here].tolist()).items())),
                  "end_point_box": {_AXES[i]: [float(ends[:, i].min()), float(ends[:, i].max())] if len(ends) else None
                                    for i in range(ends.shape[1])},
                  "kappa_least": float(finite.min()) if finite.size else None,
                  "kappa_median": float(np.median(finite)) if finite.size else None,
                  "type1_locus_points": len(result.type1[a]), "type2_locus_points": len(result.type2[a])}
    either = result.measures["any"]
    return {"study": str(spec.path), "title": spec.title, "kind": "workspace", "space": "actuator",
            "point": spec.point, "motors": list(result.motors), "unit": spec.unit, "region_unit": region_unit,
            "characteristic_length": result.length / u,
            "grid": {a.name: {"from": a.start * s, "to": a.stop * s, "count": a.count, "unit": unit}
                     for a, (s, unit) in zip(spec.axes, scales)},
            "locus_bound": [step / 2 * s for step, (s, _) in zip(result.steps, scales)],
            "either_assembly": {"region": either.value * power, "bound": either.bound * power},
            "assembly_modes": out}


def text(result: ActuatorResult) -> str:
    """The terminal summary."""
    s = summary(result)
    grid = " x ".join(f"{n} {g['from']:.6g}..{g['to']:.6g} {g['unit']} ({g['count']})" for n, g in s["grid"].items())
    lines = [f"{s['title']} (actuator space: forward kinematics of '{s['point']}', motors {', '.join(s['motors'])})",
             f"grid {grid}; L = {s['characteristic_length']:.6g} {s['unit']} (kappa of the Jacobian over L)",
             f"{'assembly':<10}{'cells':>7}{'region [' + s['region_unit'] + ']':>26}{'kappa min':>11}{'median':>9}"
             f"  working modes; end point box [{s['unit']}]"]
    for a, e in s["assembly_modes"].items():
        kappa = (f"{e['kappa_least']:>11.4g}{e['kappa_median']:>9.4g}" if e["kappa_least"] is not None
                 else f"{'-':>11}{'-':>9}")
        box = ", ".join(f"{n} {v[0]:.4g}..{v[1]:.4g}" for n, v in e["end_point_box"].items() if v)
        modes = " ".join(f"{m} {c}" for m, c in e["working_modes"].items())
        lines.append(f"{'assembly ' + a:<10}{e['cells']:>7}{_pm(e['region'], e['bound']):>26}{kappa}  {modes}; {box}")
    either = s["either_assembly"]
    lines.append(f"either assembly: {_pm(either['region'], either['bound'])} {s['region_unit']}; type II locus: "
                 "where an assembly mode ends (the solutions of both signs meet)")
    return "\n".join(lines)


def _pm(value: float, bound: float) -> str:
    return f"{value:.0f} +- {bound:.0f}" if abs(value) >= 100 else f"{value:.4g} +- {bound:.2g}"


def table(result: ActuatorResult) -> dict[str, list]:
    """One row a cell and assembly mode: the motors, assembly, found, working modes, the end
    point, kappa, det and least singular value of K (type I) and Phi_p (type II)."""
    u, unit = result.spec.unit_si, result.spec.unit
    shape = result.reached.shape
    cells = int(np.prod(shape[:-1]))
    mesh = np.meshgrid(*result.coords, indexing="ij")
    rows: dict[str, list] = {}
    for name, m, (s, shown) in zip(result.motors, mesh, _scales(result)):
        rows[f"{name} [{shown}]"] = np.repeat(m.ravel() * s, 2).tolist()
    rows["assembly"] = list(ASSEMBLIES) * cells
    rows["found"] = result.reached.reshape(-1).tolist()
    rows["working modes"] = result.modes.reshape(-1).tolist()
    ends = result.end.reshape(cells * 2, -1)
    for i in range(ends.shape[1]):
        rows[f"{_AXES[i]} [{unit}]"] = (ends[:, i] / u).tolist()
    for key, label in (("kappa", "kappa"), ("det1", "det K (type I)"), ("sigma1", "sigma_min K (type I)"),
                       ("det2", "det Phi_p (type II)"), ("sigma2", "sigma_min Phi_p (type II)")):
        rows[label] = result.values[key].reshape(-1).tolist()
    return rows


def write(result: ActuatorResult, prefix: str | Path, *, parquet: bool = True) -> list[Path]:
    """PREFIX.csv, PREFIX.json and (with pyarrow) PREFIX.parquet; the paths written."""
    return write_tables(table(result), summary(result), prefix, parquet=parquet)
