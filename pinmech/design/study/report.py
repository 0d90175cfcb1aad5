"""A study's results for people and programs: a terminal summary, a table (CSV, and Parquet
through pyarrow), a JSON summary, and figures (matplotlib). Users' units at this edge:
lengths in mm, angles in deg, sensitivities in mm/mm and deg/mm.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np

from pinmech.design.study.grid import cycle_range, failures
from pinmech.design.study.outputs import USER_UNITS as _SCALE
from pinmech.design.study.run import StudyResult
from pinmech.solve.certify import EVERY_POSE, certified_text, dial_note
from pinmech.design.study.tolerance import PERCENTILES, deviation
from pinmech.design.study.tolerance_report import pose_table, tolerance_lines, tolerance_summary
from pinmech.outputs import beside, write_whole, write_with



def _unit(kind: str) -> tuple[float, str]:
    return _SCALE[kind]


def _per(result: StudyResult, k: int) -> tuple[float, str]:
    """Parameter k's users' unit: (SI per unit, "mm" or "deg")."""
    return (1e-3, "mm") if result.param_kind(k) == "length" else (math.pi / 180, "deg")


def summary(result: StudyResult) -> dict:
    """The JSON summary: per output, the largest |dy/dp| over the cycle for each parameter,
    and for a tolerance study the spread beside the linear estimate and the failures."""
    spec = result.spec
    out = {"study": str(spec.path), "title": spec.title, "kind": spec.kind, "driver": result.driver,
           "poses": len(result.values), "parameters": {}, "outputs": {}}
    if result.certify != EVERY_POSE:  # each variant's cycle followed with fewer poses certified
        out["certified"] = certified_text(result.certify)
    for k, p in enumerate(spec.params):
        size, per = _per(result, k)
        out["parameters"][p.name] = {f"nominal_{per}": result.nominal_p[k] / size, "distribution": p.distribution,
                                     f"sigma_{per}": p.sigma / size}
    for j, name in enumerate(result.outputs):
        scale, unit = _unit(result.kinds[j])
        entry = {"unit": unit, "nominal_min": float(result.nominal[:, j].min() * scale),
                 "nominal_max": float(result.nominal[:, j].max() * scale)}
        for k, p in enumerate(result.params):
            size, per = _per(result, k)
            entry.setdefault(f"max_abs_sensitivity_{unit}_per_{per}", {})[p] = float(
                np.abs(result.sensitivity[:, j, k]).max() * scale * size)
        if result.spread is not None:
            s = result.spread
            entry.update(sigma_max=_finite(s.sigma[:, j].max() * scale),
                         sigma_linear_max=float(s.sigma_linear[:, j].max() * scale),
                         worst=_finite(s.worst[j] * scale), worst_linear=float(s.worst_linear[j] * scale),
                         percentiles={f"{q:g}": _finite(s.percentiles[i, :, j].min() * scale if q < 50 else
                                                        s.percentiles[i, :, j].max() * scale)
                                      for i, q in enumerate(PERCENTILES)})
        out["outputs"][name] = entry
    if spec.kind == "grid":
        out.update(_grid_summary(result))
    if result.spread is not None:
        out.update(samples=spec.samples, seed=spec.seed, solved=result.spread.solved,
                   failures=dict(result.spread.failures))
        out.update(tolerance_summary(result))
    return out


def _grid_summary(result: StudyResult) -> dict:
    """A grid study's axes [mm], its points that solved, and the failures by cause."""
    _, _, causes = result.variants
    units = {a.name: _per(result, a.param) for a in result.spec.grid}
    out = {"grid": {a.name: {f"from_{units[a.name][1]}": a.start / units[a.name][0],
                             f"to_{units[a.name][1]}": a.stop / units[a.name][0], "count": a.count}
                    for a in result.spec.grid},
           "points": len(causes), "solved": sum(not c for c in causes), "failures": failures(causes)}
    mu = result.transmission
    if mu is not None and not np.isnan(mu).all():
        out["transmission_angle_acute_least_deg"] = float(np.degrees(np.nanmin(mu)))  # as sweep's summary
    return out


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def text(result: StudyResult) -> str:
    """The terminal summary."""
    s = summary(result)
    lines = [f"{s['title']} ({s['kind']}, {s['poses']} poses of {s['driver']}"
             + (f", {s['samples']} variants, seed {s['seed']})" if "samples" in s else ")")]
    lines.append("parameters: " + ", ".join(_said_param(n, p) for n, p in s["parameters"].items()))
    note = dial_note(result.certify)
    if note:
        lines.append(f"each variant's cycle: {note}")
    lines.append("largest |dy/dp| over the cycle: " + "; ".join(
        f"{o}: " + ", ".join(f"{p} {v:.4g} {e['unit']}/{per}" for per in ("mm", "deg")
                             for p, v in e.get(f"max_abs_sensitivity_{e['unit']}_per_{per}", {}).items())
        for o, e in s["outputs"].items()))
    if "samples" in s:
        lines.append(f"{'output':<16}{'sigma max':>12}{'linear':>12}{'worst':>12}{'linear':>12}"
                     "   (largest over the cycle: Monte Carlo, linear)")
        for o, e in s["outputs"].items():
            lines.append(f"{o + ' [' + e['unit'] + ']':<16}" + "".join(
                f"{v:>12.4g}" if v is not None else f"{'-':>12}"
                for v in (e["sigma_max"], e["sigma_linear_max"], e["worst"], e["worst_linear"])))
        failed = ", ".join(f"{c}: {n}" for c, n in s["failures"].items()) or "none"
        lines.append(f"solved {s['solved']} of {s['samples']} variants; failed: {failed}")
        lines += tolerance_lines(s, s["driver"])
    if "points" in s:
        axes = " x ".join(f"{n} {g[f'from_{u}']:.6g}..{g[f'to_{u}']:.6g} {u} ({g['count']})"
                          for n, g in s["grid"].items() for u in ("mm" if "from_mm" in g else "deg",))
        failed = ", ".join(f"{c}: {n}" for c, n in s["failures"].items()) or "none"
        lines.append(f"grid {axes}: solved {s['solved']} of {s['points']} points; failed: {failed}")
        if "transmission_angle_acute_least_deg" in s:
            lines.append(f"least acute transmission angle (mu folded on 0-90 deg) over the grid: "
                         f"{s['transmission_angle_acute_least_deg']:.4g} deg")
    return "\n".join(lines)


def _said_param(name: str, p: dict) -> str:
    per = "mm" if "nominal_mm" in p else "deg"
    spread = f" (sigma {p[f'sigma_{per}']:.3g} {per}, {p['distribution']})" if p["distribution"] != "fixed" else ""
    return f"{name} {p[f'nominal_{per}']:.6g} {per}{spread}"


def table(result: StudyResult) -> dict[str, list]:
    """The study's table as columns: one row a pose and output (sensitivity), one row a
    variant (tolerance: its parameters, its cause, its largest deviation of each output), or
    one row a grid point (grid: its parameters, its cause, each output's min and max, its
    least transmission angle)."""
    if result.spec.kind == "grid":
        return grid_table(result)
    if result.spread is None:
        rows: dict[str, list] = {f"{result.driver} [deg]": [], "output": [], "unit": [], "value": []}
        columns = [f"d/d {p} [per {_per(result, k)[1]}]" for k, p in enumerate(result.params)]
        rows.update({c: [] for c in columns})
        for i, x in enumerate(result.values):
            for j, name in enumerate(result.outputs):
                scale, unit = _unit(result.kinds[j])
                rows[f"{result.driver} [deg]"].append(math.degrees(x))
                rows["output"].append(name), rows["unit"].append(unit)
                rows["value"].append(result.nominal[i, j] * scale)
                for k, c in enumerate(columns):
                    rows[c].append(result.sensitivity[i, j, k] * scale * _per(result, k)[0])
        return rows
    p, y, causes = result.variants
    rows = {"variant": list(range(len(causes)))}
    rows.update(_param_columns(result, p))
    rows["cause"] = list(causes)
    dev = np.abs(deviation(y, result.nominal, result.kinds)).max(axis=1)
    for j, name in enumerate(result.outputs):
        scale, unit = _unit(result.kinds[j])
        rows[f"max |d {name}| [{unit}]"] = (dev[:, j] * scale).tolist()
    return rows


def grid_table(result: StudyResult) -> dict[str, list]:
    """One row a grid point: its index, parameters [mm], cause ("" if it solved) and each
    output's min and max over the cycle (NaN where the point failed; angles unwrapped), and
    the least acute transmission angle over the cycle (mu folded on 0-90 deg, as sweep's
    `transmission_angle_acute_least`) for a planar linkage with dyads."""
    p, y, causes = result.variants
    rows: dict[str, list] = {"point": list(range(len(causes)))}
    rows.update(_param_columns(result, p))
    rows["cause"] = list(causes)
    lo, hi = cycle_range(y, result.kinds)
    for j, name in enumerate(result.outputs):
        scale, unit = _unit(result.kinds[j])
        rows[f"min {name} [{unit}]"] = (lo[:, j] * scale).tolist()
        rows[f"max {name} [{unit}]"] = (hi[:, j] * scale).tolist()
    if result.transmission is not None:
        rows["least acute transmission angle [deg]"] = np.degrees(result.transmission).tolist()
    return rows


def _param_columns(result: StudyResult, p: np.ndarray) -> dict[str, list]:
    """The variants' parameters (N, n_par) [m or rad] as columns in mm or deg."""
    out = {}
    for k, name in enumerate(result.params):
        size, per = _per(result, k)
        out[f"{name} [{per}]"] = (p[:, k] / size).tolist()
    return out


def write(result: StudyResult, prefix: str | Path, *, parquet: bool = True) -> list[Path]:
    """PREFIX.csv, PREFIX.json and (with pyarrow) PREFIX.parquet, and for a tolerance study
    PREFIX_poses.csv (every pose's stack-up: tolerance_report.pose_table); the paths written."""
    comment = dial_note(result.certify)
    paths = write_tables(table(result), summary(result), prefix, parquet=parquet, comment=comment)
    if result.spread is not None:
        paths.append(write_csv(pose_table(result), Path(f"{prefix}_poses.csv"), comment))
    return paths


def write_csv(columns: dict[str, list], path: Path, comment: str | None = None) -> Path:
    """Columns to a CSV file (written whole), after a `# comment` line where one is given."""
    text = io.StringIO(newline="")
    if comment:
        text.write(f"# {comment}\n")
    writer = csv.writer(text)
    writer.writerow(columns)
    writer.writerows(zip(*columns.values()))
    write_whole(path, text.getvalue())
    return path


def write_tables(columns: dict[str, list], summary_: dict, prefix: str | Path, *, parquet: bool = True,
                 comment: str | None = None) -> list[Path]:
    """Columns to PREFIX.csv (after a `# comment` line where one is given; and PREFIX.parquet
    with pyarrow), a summary to PREFIX.json."""
    paths = [beside(prefix, ".csv"), beside(prefix, ".json")]
    write_csv(columns, paths[0], comment)
    write_whole(paths[1], json.dumps(summary_, indent=2) + "\n")
    if parquet:
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError as exc:
            raise ImportError(f'a Parquet table needs pyarrow: pip install "pinmech[study]" ({exc})') from exc
        paths.append(write_with(beside(prefix, ".parquet"), lambda path: pq.write_table(pa.table(columns), path)))
    return paths
