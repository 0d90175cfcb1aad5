"""What a designer reads first, at one pose: the Grashof class of each loop, the
transmission and pressure angles of each dyad, the mechanical advantage of each output,
and the instant centres. `pinmech solve` prints them (text, `--json`); figures call the
functions of grashof.py, transmission.py, instant_centres.py and limit_positions.py.

Mechanical advantage here is the ideal (frictionless, massless) ratio of output effort to
driver effort, equal by virtual power to the driver's rate over the output's:
T_out / T_in = omega_in / omega_out [1] for a rocker driven by a crank, F_out / T_in =
omega_in / v_out [1/m] for a piston; infinite at a limit position (a toggle).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pinmech.exceptions import DiagnosticError
from pinmech.solve.grashof import LoopClass, loop_classes
from pinmech.solve.instant_centres import InstantCentre, instant_centres
from pinmech.solve.limit_watch import ZERO_RATE
from pinmech.model.planar_linkage import PlanarLinkage, planar_linkage
from pinmech.solve.transmission import (
    Dyad,
    DyadAngles,
    Output,
    dyad_angles,
    find_dyads,
    find_outputs,
    input_links,
    output_rate,
)


@dataclass
class Design:
    """The design diagnostics of a mechanism at one pose.

    Attributes:
        applicable: False for a mechanism they do not apply to (`reason` says why).
        loops: Grashof class of each four-bar-like loop.
        dyads: (dyad, its angles [deg]) for each dyad.
        advantage: output name -> (mechanical advantage, its unit), per unit driver rate
            of the first driver; inf at a limit position.
        centres: every instant centre at the pose.
    """

    applicable: bool
    reason: str = ""
    linkage: PlanarLinkage | None = None
    loops: list[LoopClass] = field(default_factory=list)
    dyads: list[tuple[Dyad, DyadAngles]] = field(default_factory=list)
    advantage: dict[str, tuple[float, str]] = field(default_factory=dict)
    centres: list[InstantCentre] = field(default_factory=list)
    input_link: str | None = None  # the first driver's link: Barker's link 2


def advantage_unit(driver_angular: bool, output: Output) -> str:
    """The unit of driver rate / output rate: [1], [1/m] or [m]."""
    out_angular = output.kind == "pin"
    return "1" if driver_angular == out_angular else "1/m" if driver_angular else "m"


def mechanical_advantage(linkage: PlanarLinkage, output: Output, unit_rates: np.ndarray, q: np.ndarray) -> float:
    """Driver rate over the output's rate at q, from the joint rates per unit driver rate
    `unit_rates` (inf where the output stops: a limit position)."""
    linkage.place(q, unit_rates)
    return advantage_of(output_rate(linkage, output), output, linkage.mechanism.length_scale)


def advantage_of(rate: float, output: Output, size: float) -> float:
    """1 / the output's rate per unit driver rate; inf where that rate is zero to rounding
    (limit_watch.ZERO_RATE of its scale: 1 for a rocker, the mechanism's size `size` [m]
    for a piston), a limit position: not 1 / rounding noise (2.4e17 at a dead centre)."""
    scale = 1.0 if output.kind == "pin" else size
    return math.inf if abs(rate) <= ZERO_RATE * scale else 1.0 / rate


def design_at(mechanism, drivers: list[str], q: np.ndarray, v: np.ndarray, unit_rates: np.ndarray | None,
              driver_angular: bool = True) -> Design:
    """The diagnostics at a closed pose q with joint rates v (for centres Kennedy's theorem
    does not reach) and rates per unit first-driver rate `unit_rates` (mechanical advantage;
    None: not computed). A spatial mechanism gives a `Design` that says why not."""
    try:
        linkage = planar_linkage(mechanism)
    except DiagnosticError as exc:
        return Design(False, reason=str(exc).split(": ", 1)[-1])
    inputs = input_links(linkage, drivers[:1])
    design = Design(True, linkage=linkage, loops=loop_classes(linkage),
                    input_link=linkage.names[inputs[0]] if inputs else None)
    linkage.place(q, v)
    design.centres = list(instant_centres(linkage, velocities=bool(np.any(v))).values())
    design.dyads = [(d, dyad_angles(linkage, d)) for d in find_dyads(linkage, drivers)]
    if unit_rates is not None:
        for output in find_outputs(linkage, drivers):
            value = mechanical_advantage(linkage, output, unit_rates, q)
            design.advantage[linkage.names[output.output]] = (value, advantage_unit(driver_angular, output))
    return design


def analysis_design(analysis, unit_rates: np.ndarray | None = None) -> Design:
    """The diagnostics of a solved scene (`pinmech.analyse`); `unit_rates`: its joint
    rates per unit driver rate, for the mechanical advantage (`unit_rates_of`)."""
    mech, names = analysis.mechanism, list(analysis.drivers.names)
    angular = mech.joint(names[0]).is_angular if names else True
    return design_at(mech, names, analysis.solution.q, analysis.solution.v, unit_rates, angular)


# ---------------------------------------------------------------------- reports
def design_dict(design: Design) -> dict:
    """The `design` section of `pinmech solve --json` (SI: angles [rad], lengths [m])."""
    if not design.applicable:
        return {"planar": False, "not_applicable": design.reason}
    linkage = design.linkage
    return {
        "planar": True,
        "loops": [x.as_dict(design.input_link) for x in design.loops],
        "dyads": [{"name": d.name(linkage), "kind": d.kind, "pin": d.joint.name,
                   "coupler": linkage.names[d.coupler], "output": linkage.names[d.output],
                   "transmission_angle": math.radians(a.mu), "transmission_angle_acute": math.radians(a.mu_acute),
                   "pressure_angle": math.radians(a.pressure)} for d, a in design.dyads],
        "mechanical_advantage": {n: {"value": v, "unit": u} for n, (v, u) in design.advantage.items()},
        "instant_centres": [_centre_dict(linkage, c) for c in design.centres],
    }


def _centre_dict(linkage: PlanarLinkage, c: InstantCentre) -> dict:
    """A centre in the world frame: a point [m], or the direction it lies in at infinity."""
    out = c.as_dict()
    if c.point is not None:
        out["position"] = [float(x) for x in linkage.to_world(c.point)]
    else:
        out["at_infinity_along"] = [float(x) for x in c.direction[0] * linkage.e1 + c.direction[1] * linkage.e2]
    return out


def design_lines(design: Design) -> list[str]:
    """The text report's section."""
    title = "Design diagnostics (docs/howto/diagnostics.md)"
    lines = ["", title, "-" * len(title)]
    if not design.applicable:
        return lines + [f"  planar diagnostics: not applicable ({design.reason})"]
    for loop in design.loops:
        turns = ", ".join(loop.cranks) or "none"
        lines.append(f"  loop {'-'.join(loop.links):<28} {loop.kind}: {loop.label}{barker_words(loop, design.input_link)} "
                     f"({loop.condition}); turning fully: {turns}")
    for d, a in design.dyads:
        if d.kind == "pin":
            lines.append(f"  {d.name(design.linkage):<33} transmission angle mu = {a.mu:.6g} deg "
                         f"(acute {a.mu_acute:.6g} deg), pressure angle {a.pressure:.6g} deg")
        else:
            lines.append(f"  {d.name(design.linkage):<33} pressure angle phi = {a.pressure:.6g} deg, "
                         f"transmission angle 90 - phi = {a.mu:.6g} deg")
    for name, (value, unit) in design.advantage.items():
        lines.append(f"  {name:<33} mechanical advantage {value:.6g} [{unit}] (driver rate / {name}'s rate)")
    if design.centres:
        plane = "" if abs(design.linkage.normal[2]) == 1.0 else " (in the plane's own x, y: see --json for world)"
        lines += [f"  instant centres{plane} (* primary: pins, slides; the others by Kennedy's theorem):"]
        lines += [f"    {_centre_text(c)}" for c in design.centres]
    return lines


def barker_words(loop: LoopClass, input_link: str | None) -> str:
    """', Barker I-2 GCRR (input crank)' for a four-bar, else ''."""
    code = loop.barker(input_link)
    return f", Barker {code} (input {input_link or loop.links[1]})" if code else ""


def _centre_text(c: InstantCentre) -> str:
    star = "*" if c.primary else " "
    where = (f"({c.point[0] + 0.0:.6g}, {c.point[1] + 0.0:.6g}) m" if c.point is not None  # + 0.0: no -0
             else f"at infinity along ({c.direction[0] + 0.0:.6g}, {c.direction[1] + 0.0:.6g})")
    how = "" if c.how in ("pin", "slide", "Kennedy") else f"   (from the {c.how})"
    return f"I({c.links[0]}, {c.links[1]}){star} {where}{how}"
