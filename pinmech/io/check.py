"""Hand values against pinmech: one verdict per printed quantity.

A hand file (TOML) lists values as they were printed, as strings so that their printed
precision is kept:

    scene = "r_rtr.toml"
    [[value]]
    label = "v_D (text)"
    quantity = "points.D.velocity"     # a path into `pinmech solve --json`
    hand = ["0.386", "-0.282"]         # x, y as printed
    unit = "m/s"

A list of values goes with a vector path; a component (.x, .y, .z, .norm) takes one. The
unit must measure the quantity's own kind (a declared `kind`, needed for a joint's q, v
and a, must agree with it), and any key but these is refused as a typo.

A printed value is an interval: "0.386" means [0.3855, 0.3865]. Verdicts::

    ok        within half a unit of the last printed digit: correctly rounded;
    rounding  within `slack` units: truncated, or carried rounding of the hand work's
              own rounded intermediate values; right at the printed precision;
    MISMATCH  further off: the print (or the model) is wrong.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from pathlib import Path
from typing import Any

from pinmech.exceptions import SceneError, UnitError
from pinmech.units import JOINT_KINDS, SI_UNITS, format_si, to_si

from pinmech.io.hand_tables import HandEntry, HandTables
from pinmech.toml_file import read_toml

#: How many units of the last printed digit count as "rounding" rather than a mismatch,
#: and the most a user may allow (more would call any value rounding).
DEFAULT_SLACK = 2.0
MAX_SLACK = 100.0
_COMPONENTS: dict[str, int | str] = {"x": 0, "y": 1, "z": 2, "norm": "norm"}
_KINDS = {
    "position": "length",
    "velocity": "velocity",
    "acceleration": "acceleration",
    "relative_velocity": "velocity",
    "relative_acceleration": "acceleration",
    "coriolis_acceleration": "acceleration",
    "s": "length",          # a slider's position along its guide (sliders.S.s)
    "s_dot": "velocity",
    "s_ddot": "acceleration",
    "angle": "angle",
    "angular_velocity": "angular_velocity",
    "angular_acceleration": "angular_acceleration",
}
#: The kind of each number of a joint reaction (forces.reactions.B.force ...).
_REACTION_KINDS = {"force": "force", "normal_force": "force", "axial_force": "force", "magnitude": "force",
                   "moment": "torque", "axial_moment": "torque", "point": "length", "angle": "angle"}
#: Numbers of the result without a unit (counts, signs, ratios of the solver): no hand
#: value of a unit measures them. Paths as (first key, last key); None: any.
PURE_NUMBERS = {("assembly", "sign"), ("accuracy", None), ("route", "continuation_steps"),
                ("task", "condition_number"), ("task", "rank"), ("task", "nullspace_dim"), ("task", "sigma_min"),
                ("forces", "condition_number"), ("forces", "equation_residual"), ("forces", "residual")}
#: The kind a path of pure numbers has for `_path_kind`.
NUMBER = "pure number"
#: A joint type of the result, as a key of JOINT_KINDS.
_JOINT_FAMILIES = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic"}


@dataclass(frozen=True)
class HandValue:
    """One printed number: its label, where it lives in the result, and its precision."""

    label: str
    quantity: str
    component: int | str | None  # 0, 1, 2 (x, y, z), "norm" (the vector's magnitude) or None
    printed: str
    unit: str
    kind: str
    file: str = ""  # the hand file, for error messages ("" when built in Python)
    entry: str = ""  # its [[value]] table: "value[3]"

    @property
    def where(self) -> str:
        """The entry and its label, for error messages: "value[3] (text: omega_3)"."""
        return f"{self.entry} ({self.label})" if self.entry else self.label

    @property
    def value(self) -> float:
        return float(self.printed)

    @property
    def ulp(self) -> float:
        """One unit of the last printed digit, in the hand unit."""
        exponent = Decimal(self.printed).as_tuple().exponent
        return 10.0 ** int(exponent)


@dataclass(frozen=True)
class Verdict:
    """Hand value, pinmech value (in the hand unit), difference and verdict."""

    hand: HandValue
    computed: float
    difference: float
    verdict: str


@dataclass(frozen=True)
class HandFile:
    path: Path
    scene: Path
    source: str
    values: list[HandValue]


def load_hand_file(path: str | Path) -> HandFile:
    """Read a hand-value file; its scene path is relative to the file's folder.

    Raises:
        SceneError: malformed TOML, an unknown key, no value to check, a value that is not
            a printed number, an unknown unit.
    """
    path = Path(path)
    return hand_file(read_toml(path, "hand-value", SceneError), path)


def hand_file(toml_tables: dict[str, Any], path: Path) -> HandFile:
    """A hand file from its TOML tables as read (`path`: the file, for its scene and messages).

    Raises:
        SceneError: as `load_hand_file`.
    """
    tables = HandTables.read(toml_tables, path)
    values = []
    for i, entry in enumerate(tables.value):
        values.extend(_hand_values(entry, f"value[{i}]", str(path)))
    scene = (path.parent / tables.scene).resolve()
    if not scene.is_file():
        raise SceneError(f"scene = {tables.scene!r}: no such scene file ({scene})", path=str(path), key="scene")
    return HandFile(path, scene, tables.source, values)


def _hand_values(entry: HandEntry, where: str, path: str) -> list[HandValue]:
    """The printed values of one `[[value]]` (typed by hand_tables.py), checked against the
    result's kinds: a path of the result, a unit of its kind, numbers as printed."""
    quantity, hand = entry.quantity, list(entry.hand)
    base, component = _split_component(quantity)
    declared = entry.kind or ""
    if declared and declared not in SI_UNITS:
        raise SceneError(f"kind = {declared!r} is not one of {', '.join(SI_UNITS)}", path=path, key=where)
    if component == "norm" and len(hand) > 1:
        raise SceneError(f"{quantity!r} is a magnitude: give one printed value", path=path, key=where)
    if component is not None and len(hand) > 1:
        raise SceneError(f"{quantity!r} is one component: give one printed value, or list x, y (, z) on {base!r}",
                         path=path, key=where)
    known, _ = _path_kind(base)
    if known == NUMBER:
        raise SceneError(f"{base!r} is a pure number of the solver (a sign, a count or a ratio, without unit), "
                         f"not {_a(declared) if declared else 'a quantity'} with unit = {entry.unit!r}: a hand "
                         "file checks lengths, angles, their rates, forces and torques", path=path, key=where)
    kind = known or declared
    if not kind:
        raise SceneError(f"cannot tell the kind of {base!r}: add kind = \"angle\" (or length, velocity, ...)",
                         path=path, key=where)
    label = entry.label if entry.label is not None else quantity
    out = []
    for i, printed in enumerate(hand):
        try:
            exponent = Decimal(printed).as_tuple().exponent
            finite = math.isfinite(float(printed)) and isinstance(exponent, int) and -300 < exponent < 300
        except (InvalidOperation, ValueError):
            raise SceneError(f"hand value {printed!r} is not a number", path=path, key=where) from None
        if not finite:
            raise SceneError(f"hand value {printed!r} is not a finite number as printed", path=path, key=where)
        comp = component if component is not None else (i if len(hand) > 1 else None)
        suffix = "" if len(hand) == 1 else f" {'xyz'[i]}"
        out.append(HandValue(label + suffix, base, comp, printed.strip(), entry.unit, kind, path, where))
    unit = out[0].unit
    if not unit.strip() or re.search(r"^\s*[-+.\d]|,", unit):
        raise SceneError(f"unit = {unit!r} is not a unit (e.g. \"m/s\", \"deg\")", path=path, key=f"{where}.unit")
    if known and declared and declared != known:  # a declared kind never overrides the quantity's own
        raise _misfit(out[0], known, where, declared)
    factor = _unit_factor(out[0], where)  # unknown or wrong unit fails here
    if not factor > 0:
        raise SceneError(f"unit = {out[0].unit!r} is not a unit", path=path, key=f"{where}.unit")
    return out


def _unit_factor(hv: HandValue, where: str) -> float:
    """SI value of one `hv.unit` (m/s for "mm/s": 0.001); `where` names the entry in errors.

    Raises:
        UnitError: naming the hand file, the entry and the unit as written: a unit of
            another kind than the quantity's, or one pinmech cannot read.
    """
    try:
        return to_si(f"1 {hv.unit}", hv.kind)
    except UnitError as exc:
        if _unit_kind(hv.unit) is not None:
            raise _misfit(hv, hv.kind, where) from None
        said = str(exc).replace(repr(f"1 {hv.unit}"), repr(hv.unit))  # the unit as the file writes it
        raise UnitError(said, path=hv.file or None, key=f"{where}.unit") from None


def _unit_kind(unit: str) -> str | None:
    """The kind of quantity `unit` measures ("rpm": angular_velocity), None if none."""
    for kind in SI_UNITS:
        try:
            to_si(f"1 {unit}", kind)
        except UnitError:
            continue
        return kind
    return None


def _a(kind: str) -> str:
    """"an angular velocity", "a length"."""
    name = kind.replace("_", " ")
    return f"an {name}" if name[0] in "aeiou" else f"a {name}"


def _misfit(hv: HandValue, expected: str, where: str, declared: str = "", why: str = "") -> UnitError:
    """The error for a unit (or a declared kind) that does not fit the quantity, which is
    `expected` (`why`: how pinmech knows, e.g. " (joint B is prismatic)")."""
    measures = _unit_kind(hv.unit)
    if declared and declared != expected:
        wrong = declared
        said = f"kind = {declared!r} and unit = {hv.unit!r} say" if measures == declared else f"kind = {declared!r} says"
    else:
        wrong, said = measures or hv.kind, f"unit = {hv.unit!r} says"
    if measures == expected:
        advice = f"make it kind = {expected!r}, or leave kind out"
    else:
        advice = f"give it in {format_si(1.0, expected)} (or another {expected.replace('_', ' ')} unit)"
        advice += f" with kind = {expected!r}" if why else " and leave kind out" if declared else ""
    return UnitError(f"{hv.quantity!r} is {_a(expected)}{why}, not {_a(wrong)} as {said}: {advice}",
                     path=hv.file or None, key=where)


def _split_component(quantity: str) -> tuple[str, int | str | None]:
    head, _, last = quantity.rpartition(".")
    if last in _COMPONENTS:
        return head, _COMPONENTS[last]
    return quantity, None


def _path_kind(quantity: str, result: dict[str, Any] | None = None) -> tuple[str | None, str]:
    """The kind of the number at a result path, and how it is known (" (joint B is
    prismatic)"), or None. A joint's coordinate (joints.B.q, drivers.B.v) and a driver's
    effort (forces.drivers.B.effort) are known from the joint's type in `result` only."""
    parts = quantity.split(".")
    if (parts[0], parts[-1]) in PURE_NUMBERS or (parts[0], None) in PURE_NUMBERS:
        return NUMBER, ""
    if len(parts) == 3 and parts[0] in ("joints", "drivers") and parts[2] in ("q", "v", "a"):
        joint, index = parts[1], "qva".index(parts[2])
    elif len(parts) == 3 and parts[:2] == ["route", "from"]:  # the driver's value the pose was reached from
        joint, index = parts[2], 0
    elif len(parts) == 4 and parts[:2] == ["forces", "drivers"] and parts[3] == "effort":
        joint, index = parts[2], None
    elif len(parts) == 4 and parts[:2] == ["forces", "reactions"]:
        return _REACTION_KINDS.get(parts[3]), ""
    elif quantity == "forces.gravity":
        return "acceleration", ""
    else:
        return _KINDS.get(parts[-1]), ""
    joints = result.get("joints") if isinstance(result, dict) else None
    about = joints.get(joint) if isinstance(joints, dict) else None
    joint_type = str(about.get("type")) if isinstance(about, dict) else ""
    family = _JOINT_FAMILIES.get(joint_type)
    if family is None:
        return None, ""
    kind = JOINT_KINDS[family][index] if index is not None else "torque" if family == "revolute" else "force"
    return kind, f" (joint {joint} is {joint_type})"


def lookup(result: dict[str, Any], quantity: str, component: int | str | None, *, where: str = "",
           path: str | None = None) -> float:
    """A number of a `pinmech solve --json` result, by dotted path and component
    (`where`, `path`: the entry and hand file, for errors)."""
    node: Any = result
    for part in quantity.split("."):
        if not isinstance(node, dict) or part not in node:
            known = ", ".join(node) if isinstance(node, dict) else "nothing"
            raise SceneError(f"{quantity!r}: no '{part}' in the result (has {known})", path=path, key=where)
        node = node[part]
    if component == "norm":
        numbers = node if isinstance(node, list) else [node]
        if not numbers or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in numbers):
            raise SceneError(f"{quantity!r} has no magnitude: it is not a number or a vector of the result",
                             path=path, key=where)
        return math.hypot(*numbers)
    if isinstance(node, list):
        if component is None:
            raise SceneError(f"{quantity!r} is a vector: add .x, .y, .z or .norm, or give a list of hand values",
                             path=path, key=where)
        if component >= len(node):
            raise SceneError(f"{quantity!r} has {len(node)} components, no {'xyz'[component]}", path=path, key=where)
        node = node[component]
    elif component is not None and isinstance(node, (int, float)) and not isinstance(node, bool):
        raise SceneError(f"{quantity!r} is a number, not a vector: give one hand value, without .x, .y or .z",
                         path=path, key=where)
    if isinstance(node, bool) or not isinstance(node, (int, float)):
        raise SceneError(f"{quantity!r} is not a number of the result", path=path, key=where)
    return float(node)


def compare(result: dict[str, Any], values: list[HandValue], slack: float = DEFAULT_SLACK) -> list[Verdict]:
    """Verdicts of hand values against a result, in the hand values' units. An angle is
    compared with the equivalent of pinmech's nearest it (413.794 deg is 53.794 deg).

    Raises:
        SceneError: a slack that is not a number from 0 to `MAX_SLACK`; a path not in the
            result.
        UnitError: a value whose kind (and unit) is not the quantity's: a prismatic
            joint's q in degrees.
    """
    check_slack(slack)
    for hv in values:  # the kinds first: no verdict on a value read in the wrong unit
        expected, why = _path_kind(hv.quantity, result)
        if expected is None or expected == NUMBER:  # a declared kind is never taken on trust
            lookup(result, hv.quantity, hv.component, where=hv.where, path=hv.file or None)  # a missing path first
            what = "is a pure number of the solver (without unit)" if expected else "holds no quantity pinmech can name"
            raise SceneError(f"{hv.quantity!r} {what}: it cannot be checked as {_a(hv.kind)} in {hv.unit!r}",
                             path=hv.file or None, key=hv.where)
        if expected != hv.kind:
            raise _misfit(hv, expected, hv.where, hv.kind, why)
    out = []
    for hv in values:
        factor = _unit_factor(hv, hv.where)
        computed = lookup(result, hv.quantity, hv.component, where=hv.where, path=hv.file or None) / factor
        if hv.kind == "angle" and hv.component != "norm":
            turn = 2 * math.pi / factor  # a full turn in the hand unit
            computed += turn * round((hv.value - computed) / turn)
        diff = hv.value - computed
        units = abs(diff) / hv.ulp
        verdict = "ok" if units <= 0.5 + 1e-9 else "rounding" if units <= slack else "MISMATCH"
        out.append(Verdict(hv, computed, diff, verdict))
    return out


def check_slack(slack: float, name: str = "slack") -> None:
    """Raises SceneError unless `slack` is a number from 0 to `MAX_SLACK` (units of the
    last printed digit; infinity would call any value rounding)."""
    if isinstance(slack, bool) or not isinstance(slack, (int, float)) or not 0 <= slack <= MAX_SLACK:
        raise SceneError(f"{name} must be a number from 0 to {MAX_SLACK:g} (units of the last printed digit), "
                         f"got {slack!r}")


def _difference(v: Verdict) -> str:
    """The difference, and how many units of the last printed digit it is."""
    if abs(v.difference) < 1e-9 * v.hand.ulp:
        return "0"
    return f"{v.difference:+.2g} ({abs(v.difference) / v.hand.ulp:.2g} digit)"


def format_verdicts(verdicts: list[Verdict]) -> str:
    """A table: label, hand value, pinmech value, difference (in last-digit units), verdict."""
    rows = [("quantity", "hand", "pinmech", "difference", "verdict")]
    for v in verdicts:
        digits = max(0, -math.floor(math.log10(v.hand.ulp))) + 3
        rows.append((
            v.hand.label,
            f"{v.hand.printed} {v.hand.unit}",
            f"{round(v.computed, digits) + 0.0:.{digits}f}",  # + 0.0: no "-0.00000"
            _difference(v),
            v.verdict,
        ))
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    counts = {k: sum(v.verdict == k for v in verdicts) for k in ("ok", "rounding", "MISMATCH")}
    lines.append(f"{counts['ok']} ok, {counts['rounding']} within rounding, {counts['MISMATCH']} mismatch")
    return "\n".join(lines)
