"""A tolerance study as a designer reads it, in users' units: the stack-up side by side
(worst case, RSS, 3 sigma linear, 3 sigma Monte Carlo) with each dimension's share of the
variance, the capability against the study's `[spec]` (Cp, Cpk, parts per million), and a
table of every pose (stackup.py, capability.py hold the definitions)."""

from __future__ import annotations

import math

import numpy as np

from pinmech.design.study.capability import capability
from pinmech.design.study.outputs import USER_UNITS as _SCALE
from pinmech.design.study.stackup import stackup, survivors



def _deg(result, i: int) -> float:
    return math.degrees(result.values[i]) % 360.0


def tolerance_summary(result) -> dict:
    """The JSON summary's tolerance part: sigma over the survivors, the stack-up at each
    output's pose of largest linear sigma (and each column's largest over the cycle), and
    the capability at each spec'd output's pose of least Cpk."""
    st = stackup(result)
    out = {"sigma_over": {"solved": st.solved, "samples": st.samples, "failed": st.samples - st.solved},
           "stackup": {}, "capability": {}}
    columns = {"worst_case": st.worst, "rss": st.rss, "three_sigma_linear": 3 * st.sigma_linear,
               "three_sigma_monte_carlo": 3 * st.sigma, "mean_monte_carlo": st.mean}
    for j, name in enumerate(result.outputs):
        scale, unit = _SCALE[result.kinds[j]]
        i = int(np.argmax(st.sigma_linear[:, j]))
        entry = {"unit": unit, "at_deg": _deg(result, i)}
        entry.update({k: _finite(v[i, j] * scale) for k, v in columns.items()})
        entry["largest_over_the_cycle"] = {k: _finite(np.nanmax(np.abs(v[:, j])) * scale) if st.solved or
                                           k not in ("three_sigma_monte_carlo", "mean_monte_carlo") else None
                                           for k, v in columns.items()}
        entry["contribution_percent"] = {p: 100.0 * float(st.contribution[i, j, k]) for k, p in enumerate(result.params)}
        out["stackup"][name] = entry
    dev = survivors(result)
    for name, (lo, hi) in result.limits.items():
        j = result.outputs.index(name)
        scale, unit = _SCALE[result.kinds[j]]
        if not dev.shape[0]:
            out["capability"][name] = None
            continue
        c = capability(dev[:, :, j], lo, hi)
        i = c.worst
        out["capability"][name] = {"unit": unit, "lower": lo * scale, "upper": hi * scale, "at_deg": _deg(result, i),
                                   "cp": _finite(c.cp[i]), "cpk": _finite(c.cpk[i]), "mean": c.mean[i] * scale,
                                   "sigma": c.sigma[i] * scale, "ppm_normal": float(c.ppm[i]),
                                   "ppm_counted": c.ppm_observed}
    return out


def tolerance_lines(s: dict, driver: str) -> list[str]:
    """The terminal summary's tolerance lines, from `tolerance_summary`'s dict."""
    over = s["sigma_over"]
    failed = f", {over['failed']} failed" if over["failed"] else ""
    lines = [f"Monte Carlo sigma over the {over['solved']} of {over['samples']} variants that solved{failed}",
             "stack-up at each output's pose of largest sigma (t: a uniform's half width, else 3 sigma):",
             f"{'output':<18}{driver + ' [deg]':>12}{'worst case':>12}{'RSS':>10}{'3s linear':>11}{'3s MC':>10}"
             "  largest shares of the variance"]
    for name, e in s["stackup"].items():
        shares = sorted(e["contribution_percent"].items(), key=lambda kv: -kv[1])[:3]
        lines.append(f"{name + ' [' + e['unit'] + ']':<18}{e['at_deg']:>12.1f}" + "".join(
            f"{v:>{w}.4g}" if v is not None else f"{'-':>{w}}" for v, w in
            ((e["worst_case"], 12), (e["rss"], 10), (e["three_sigma_linear"], 11), (e["three_sigma_monte_carlo"], 10)))
            + "  " + ", ".join(f"{p} {v:.0f}%" for p, v in shares))
    for name, c in s["capability"].items():
        if c is None:
            lines.append(f"spec {name}: no variant solved")
            continue
        cpk = f"{c['cpk']:.3g}" if c["cpk"] is not None else "inf"
        cp = f"{c['cp']:.3g}" if c["cp"] is not None else "inf"
        lines.append(f"spec {name} {c['lower']:.4g} .. {c['upper']:.4g} {c['unit']}: Cp {cp}, Cpk {cpk} at "
                     f"{driver} = {c['at_deg']:.1f} deg; {c['ppm_normal']:.3g} ppm out there (normal), "
                     f"{c['ppm_counted']:.3g} ppm of the variants out at some pose (counted)")
    return lines


def pose_table(result) -> dict[str, list]:
    """One row a pose and output: the nominal, the Monte Carlo mean and sigma, sigma linear,
    worst case, RSS, each parameter's share of the variance [%], and Cp, Cpk and ppm (normal)
    where the output has a spec."""
    st, dev = stackup(result), survivors(result)
    rows: dict[str, list] = {f"{result.driver} [deg]": [], "output": [], "unit": [], "nominal": [],
                             "mean MC": [], "sigma MC": [], "sigma linear": [], "worst case": [], "RSS": []}
    rows.update({f"share {p} [%]": [] for p in result.params})
    caps = {name: capability(dev[:, :, result.outputs.index(name)], *lim) for name, lim in result.limits.items()
            if dev.shape[0]}
    if caps:
        rows.update({"Cp": [], "Cpk": [], "ppm out (normal)": []})
    for i, x in enumerate(result.values):
        for j, name in enumerate(result.outputs):
            scale, unit = _SCALE[result.kinds[j]]
            rows[f"{result.driver} [deg]"].append(math.degrees(x))
            rows["output"].append(name), rows["unit"].append(unit)
            for key, v in (("nominal", result.nominal), ("mean MC", st.mean), ("sigma MC", st.sigma),
                           ("sigma linear", st.sigma_linear), ("worst case", st.worst), ("RSS", st.rss)):
                rows[key].append(float(v[i, j] * scale))
            for k, p in enumerate(result.params):
                rows[f"share {p} [%]"].append(100.0 * float(st.contribution[i, j, k]))
            if caps:
                c = caps.get(name)
                rows["Cp"].append(float(c.cp[i]) if c else math.nan)
                rows["Cpk"].append(float(c.cpk[i]) if c else math.nan)
                rows["ppm out (normal)"].append(float(c.ppm[i]) if c else math.nan)
    return rows


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None
