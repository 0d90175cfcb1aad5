"""The design summary of a sweep as one object, at full precision, in SI: what `pinmech
sweep --summary-json FILE` writes and `design_summary(sweep)` returns (the text summary
on stderr prints the same numbers to 6 significant figures).

Fields (docs/reference/outputs.md, "Design summary"):

- driver, driver_unit ("rad" or "m"), poses (solved poses counted), fold_end (the driver
  value where a fold ended the sweep, else null);
- loops: each loop of four links through the ground: kind, links, lengths [m], class,
  condition, cranks, and for a four-bar Barker's type ("I-2 GCRR", the swept driver's
  link as link 2);
- dyads: per pin B, the transmission angle mu [rad] on [0, pi], least and largest, the
  largest pressure angle |pi/2 - mu| [rad], the least acute mu, each with its driver
  value, in_line_at (coupler and output in line), located (refined between poses) and
  transmission_angle_constant (mu one value at every pose, to 1e-9 deg);
- folds: the driver's folds met [rad or m];
- outputs: per output link, its limit positions (kind, label "max"/"min" with TDC/BDC,
  driver value, place [rad or m], toggle), swing [rad] or stroke [m], time ratio Q and
  the driver angles of the slow and quick strokes [rad] (one whole turn only), and the
  least mechanical advantage over the poses (not refined between them) and where.

Precision: limit positions and folds are located to 1e-12 of the driver; an angle's extreme
inside the range is its value to rounding, but its driver value only to about sqrt(eps)
(1e-8 rad: the extreme is flat there); in line points to 1e-10 (or to where the poses stop
closing beside a change point, ~1e-10).

Driver values are as swept (not wrapped): a sweep from 300 deg to 660 deg reports a limit
at 410 deg as 7.16 rad; `driver_wrapped` beside each gives it on [0, 2 pi) for an angle.
"""

from __future__ import annotations

import math

from pinmech.solve.grashof import loop_classes
from pinmech.solve.limit_positions import travel


def design_summary(sweep, span: float | None = None) -> dict:
    """The design summary of a sweep whose poses were fed to its `DesignSweep` (`design_of`),
    as a JSON-ready dict; `span` 2 pi when the sweep was one whole turn (then Q)."""
    from pinmech.solve.diagnostics_sweep import design_of

    design = design_of(sweep)
    out = {"driver": sweep.driver, "driver_unit": "rad" if sweep.is_angular else "m"}
    if not design.applicable:
        return {**out, "planar": False, "not_applicable": design.reason}
    wrap = _wrapper(sweep.is_angular)
    dyads = [{**x.as_dict(), "coupler_output": d.name(design.linkage)}
             for d, x in zip(design.dyads, design.angle_extremes())] if design.count else []
    outputs = []
    for output, found, stat in zip(design.outputs, design.limits(), design.advantages):
        t = travel(found, span)
        limits = [{**x.as_dict(), "driver_wrapped": wrap(x.driver)} for x in (t.limits if t else ())]
        entry = {"output": design.linkage.names[output.output], "kind": "rocker" if output.kind == "pin" else "slider",
                 "limits": limits, "swing" if output.kind == "pin" else "stroke": t.travel if t else None,
                 "time_ratio": t.ratio if t else None, "slow_stroke_driver_angle": t.alpha if t else None,
                 "quick_stroke_driver_angle": t.beta if t else None,
                 "mechanical_advantage_least_over_the_poses": stat.low if math.isfinite(stat.low) else None,
                 "mechanical_advantage_least_over_the_poses_at": stat.low_at if math.isfinite(stat.low) else None,
                 "mechanical_advantage_unit": design._unit(output),
                 "mechanical_advantage_constant": stat.constant}
        outputs.append(entry)
    return {**out, "planar": True, "poses": design.count, "fold_end": sweep.fold_end,
            "loops": [x.as_dict(design.input_link) for x in loop_classes(design.linkage)],
            "dyads": dyads, "folds": design.folds(), "outputs": outputs}


def _wrapper(angular: bool):
    if angular:
        return lambda x: x % (2 * math.pi)
    return lambda x: x
