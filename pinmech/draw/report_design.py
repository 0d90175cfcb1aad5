"""The report's design table: the design summary of the page's sweep (`pinmech.design_summary`,
not recomputed here) as a lecturer reads it: each loop's Grashof class and Barker's type, the
transmission angle's least and largest values and where, the largest pressure angle, each
output's limit positions, its swing or stroke, the time ratio Q and which stroke is slow.

Angles in degrees, driver positions on [0, 360) deg, lengths in mm. Each number's cell carries
`data-key` (its place in the summary, e.g. `outputs.0.swing`) so a program can read it back.
"""

from __future__ import annotations

import html
import math

#: Significant figures of the table's numbers: the summary's stderr lines print 6.
FIGURES = 6


def design_table(summary: dict, sense: float = 1.0) -> str:
    """The design table (an HTML <table class="design">) of a design summary; `sense` the
    sign of the driver's speed (which stroke is slow depends on the way the driver turns)."""
    if not summary.get("planar"):
        reason = summary.get("not_applicable", "not a planar linkage")
        return f'<p class="design-none">No design table: {html.escape(reason)}.</p>'
    rows = design_rows(summary, sense)
    if not rows:
        return '<p class="design-none">No design table: no loop, dyad or output found in the sweep.</p>'
    body = "".join(f"<tr><th>{html.escape(h)}</th><td>{cell}</td></tr>" for h, cell in rows)
    return f'<table class="design">{body}</table>'


def design_rows(summary: dict, sense: float = 1.0) -> list[tuple[str, str]]:
    """(heading, HTML cell) of each row of the design table of a planar linkage's summary."""
    driver, angular = summary["driver"], summary["driver_unit"] == "rad"
    rows = [_loop(x) for x in summary["loops"]]
    for i, dyad in enumerate(summary["dyads"]):
        rows += _dyad(i, dyad, driver, angular)
    if summary["folds"]:
        rows.append((f"{driver} folds (its limits)", ", ".join(_at(driver, x, angular) for x in summary["folds"])))
    for i, output in enumerate(summary["outputs"]):
        rows += _output(i, output, driver, angular, sense)
    return rows


def _loop(loop: dict) -> tuple[str, str]:
    barker = f", Barker {html.escape(loop['barker'])}" if loop.get("barker") else ""
    return (f"loop {'-'.join(loop['links'])}",
            f"{html.escape(loop['kind'])}: <b>{html.escape(loop['class'])}</b>{barker} ({html.escape(loop['condition'])})")


def _dyad(i: int, dyad: dict, driver: str, angular: bool) -> list[tuple[str, str]]:
    key = f"dyads.{i}."
    where = "" if dyad["located"] else " (over the poses)"

    def angle(name: str) -> str:
        return f"{_number(key + name, math.degrees(dyad[name]))}°"

    if dyad.get("transmission_angle_constant"):
        return [(f"μ at {dyad['pin']} ({dyad['coupler_output']})",
                 f"{angle('transmission_angle_least')} at every pose (constant)")]
    rows = [(f"μ at {dyad['pin']} ({dyad['coupler_output']})",
             f"least {angle('transmission_angle_least')} at {_at(driver, dyad['transmission_angle_least_at'], angular)}; "
             f"largest {angle('transmission_angle_largest')} at "
             f"{_at(driver, dyad['transmission_angle_largest_at'], angular)}{where}"),
            (f"pressure angle at {dyad['pin']}",
             f"largest |90° − μ| = {angle('pressure_angle_largest')} at "
             f"{_at(driver, dyad['pressure_angle_largest_at'], angular)}")]
    if dyad["in_line_at"]:
        rows.append((f"in line at {dyad['pin']}", "μ = 0° or 180° at "
                     + ", ".join(_at(driver, x, angular) for x in dyad["in_line_at"])))
    return rows


def _output(i: int, out: dict, driver: str, angular: bool, sense: float) -> list[tuple[str, str]]:
    key, name, rocker = f"outputs.{i}.", out["output"], out["kind"] == "rocker"
    limits = []
    for j, x in enumerate(out["limits"]):
        place = (f"{_number(f'{key}limits.{j}.value', math.degrees(x['value']))}°" if rocker
                 else f"{_number(f'{key}limits.{j}.value', 1000 * x['value'])} mm along the slide")
        toggle = f", {x['toggle']} (toggle)" if x["toggle"] else ""
        limits.append(f"{html.escape(x['label'])}: {place} at {_at(driver, x['driver'], angular)}{toggle}")
    rows = [(f"{name}: limit positions", "<br>".join(limits) or "none in the sweep")]
    if rocker and out.get("swing") is not None:
        rows.append((f"{name}: swing", f"{_number(key + 'swing', math.degrees(out['swing']))}°"))
    if not rocker and out.get("stroke") is not None:
        rows.append((f"{name}: stroke", f"{_number(key + 'stroke', 1000 * out['stroke'])} mm"))
    if out.get("time_ratio") is not None:
        rows.append((f"{name}: time ratio Q", f"{_number(key + 'time_ratio', out['time_ratio'])}; "
                     + _slow_stroke(out, driver, key, sense)))
    return rows


def _slow_stroke(out: dict, driver: str, key: str, sense: float) -> str:
    """Which stroke is slow: the one from limit to limit over the larger driver angle, the
    driver turning the way its speed says."""
    first, second = out["limits"]
    ahead = (sense if sense else 1.0) * (second["driver"] - first["driver"]) % (2 * math.pi)
    slow, quick = out["slow_stroke_driver_angle"], out["quick_stroke_driver_angle"]
    start, end = (first, second) if abs(ahead - slow) <= abs(ahead - quick) else (second, first)
    return (f"slow stroke {html.escape(start['label'])} → {html.escape(end['label'])} over "
            f"{_number(key + 'slow_stroke_driver_angle', math.degrees(slow))}° of {html.escape(driver)}, quick stroke "
            f"over {_number(key + 'quick_stroke_driver_angle', math.degrees(quick))}°")


def _at(driver: str, value: float, angular: bool) -> str:
    """A driver position: an angle on [0, 360) deg (as the summary prints it), or a length in mm."""
    if angular:
        from pinmech.angles import position_text

        return f"{html.escape(driver)} = {position_text(math.degrees(value))}°"
    return f"{html.escape(driver)} = {_text(1000 * value)} mm"


def _number(key: str, value: float) -> str:
    """A number of the table (degrees, mm or Q) rounded to 1e-6 first: a pressure angle of
    1e-13 deg at rounding reads 0."""
    return f'<span data-key="{html.escape(key)}">{_text(round(value, 6) + 0.0)}</span>'


def _text(value: float) -> str:
    return f"{value:.{FIGURES}g}"
