"""A drawn-linkage file as one typed, validated object: `LinkageSpec` (a frozen msgspec Struct).

The file is read once (`read_linkage_spec`) into a `LinkageSpec` holding what it writes, as
it writes it: quantities stay the user's text (`"40 mm"`, `"2*a + b"`, `"30 deg"`), names
stay names. Validation checks every entry's shape and every name it refers to (a link's
joints, a construction's bases, a slider's links...), each failure one `ModelError` naming
the file and the key (`[links] coupler`). Lengths and angles become SI numbers, and the
drawn pose is constructed, in `pinmech.model.linkage.linkage_from_spec`, the one place a
written quantity is read; nothing below reads TOML keys. `linkage_toml` writes a spec back
(`pinmech.model.linkage_write`), so a program (a study, a synthesis) can change `params` or
joints and write or load the result.
"""

from __future__ import annotations

from contextvars import ContextVar
from typing import Any, Union

import msgspec
from msgspec import structs

from pinmech.directions import unit_vector, written
from pinmech.exceptions import ModelError
from pinmech.known_keys import unknown_keys
from pinmech.model.linkage_entries import (TABLES as _TABLES, Bearing, Compass, Joint, MassSpec, Polar, Slider, Slot, Written,
                                           as_model_error as _as_model_error, joint_type)
from pinmech.model.linkage_expr import check_param_name, is_angle
from pinmech.typed_values import WrongType, typed

GROUND = "ground"
_KEYS = {"title", "ground", "balls", *_TABLES}
#: The file a spec is being read from, for its messages (`linkage_spec`; "<linkage>" in code).
_SOURCE: ContextVar[str] = ContextVar("linkage_source", default="<linkage>")


class LinkageSpec(msgspec.Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """A drawn linkage as its file writes it, validated: build one with `read_linkage_spec`
    (a file), `linkage_spec` (TOML's tables) or `LinkageSpec(...)` in code; draw it with
    `linkage_from_spec`, write it with `linkage_toml`. Frozen: `with_params` makes a changed
    copy (validated again), as does `linkage_spec(changed tables)`.

    Attributes (the file's keys; every table in the order written):
        title: the linkage's title (None: the file's stem).
        ground: the joints on the ground.
        params: parameter name -> a length as written; coordinates may use them.
        joints: joint name -> `[x, y]` / `[x, y, z]` as written, or a `Polar`, `Compass` or `Bearing`
            construction from joints above it.
        links: link name -> the joints it carries, in order.
        sliders, slots: name -> `Slider` / `Slot`.
        axes: joint -> its pin's axis (three numbers); balls: joints that are ball joints.
        masses: link -> `MassSpec`; colors: link -> a colour (kept, not read).
    """

    title: Union[str, None] = None
    ground: tuple[str, ...] = ()
    params: dict[str, Written] = {}
    joints: dict[str, Joint] = {}
    links: dict[str, tuple[str, ...]] = {}
    sliders: dict[str, Slider] = {}
    slots: dict[str, Slot] = {}
    colors: dict[str, str] = {}
    axes: dict[str, tuple[float, float, float]] = {}
    balls: tuple[str, ...] = ()
    masses: dict[str, MassSpec] = {}

    def __post_init__(self) -> None:
        """Every table's shape, every value's type (msgspec, strict), every name referred to.

        Raises:
            ModelError: the first mistake, naming the file (`_SOURCE`) and the key.
        """
        source = _SOURCE.get()
        for key in _TABLES:
            if not isinstance(getattr(self, key), dict):
                raise ModelError(f"[{key}] must be a table", path=source, element=key)
        for field in structs.fields(self):
            value = getattr(self, field.name)
            check = _CHECKS.get(field.name)
            if check is not None:
                value = check(value, field.name, source)
            try:
                value = _joints_typed(value) if field.name == "joints" else typed(value, field.type, (field.name,))
            except WrongType as exc:
                raise _as_model_error(exc, source) from None
            structs.force_setattr(self, field.name, value)
        _check_references(self, source)

    # ------------------------------------------------------------------ for programs
    @property
    def pins(self) -> tuple[str, ...]:
        """Joints on two or more links (the ground counting as one): the pins, in order."""
        count = {name: sum(name in names for names in (self.ground, *self.links.values())) for name in self.joints}
        return tuple(name for name, n in count.items() if n >= 2)

    def with_params(self, **lengths_m: float) -> LinkageSpec:
        """This linkage with parameters set to lengths [m] (written "<value> m"; an angle
        parameter's value [rad] written "<value> rad"), validated again.

        Raises:
            ModelError: a name that is not one of `params`.
        """
        for name in lengths_m:
            if name not in self.params:
                raise ModelError(f"'{name}' is not a parameter (params: {', '.join(self.params) or 'none'})",
                                 element="[params]")
        unit = {n: "rad" if is_angle(self.params[n]) else "m" for n in lengths_m}
        params = {**self.params, **{n: f"{float(v)!r} {unit[n]}" for n, v in lengths_m.items()}}
        return linkage_spec({**msgspec.to_builtins(self), "params": params})


def _param_names(value: dict[str, Any], key: str, source: str) -> dict[str, Any]:
    for name in value:
        check_param_name(name, source)
    return value


def _link_lists(value: dict[str, Any], key: str, source: str) -> dict[str, list[str]]:
    for name in value:
        if name == GROUND:
            raise ModelError("the ground is listed by ground = [...], not as a link", path=source,
                             element="[links] ground")
    return {name: _names(names, f"[links] {name}", source) for name, names in value.items()}


def _joint_shapes(value: dict[str, Any], key: str, source: str) -> dict[str, Any]:
    return {name: _joint(spec, f"[joints] {name}", source) for name, spec in value.items()}


def _joints_typed(value: dict[str, Any]) -> dict[str, Any]:
    """Each joint as its type: coordinates, a Polar or a Compass construction (`joint_type`)."""
    return {name: typed(spec, joint_type(spec), ("joints", name)) for name, spec in value.items()}


def _axis_shapes(value: dict[str, Any], key: str, source: str) -> dict[str, Any]:
    for name, axis in value.items():
        where = f"[axes] {name}"
        if (not isinstance(axis, (list, tuple)) or len(axis) != 3
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in axis)):
            raise ModelError(f"an axis is three numbers, e.g. [0, 0, 1], got {axis!r}", path=source, element=where)
        if unit_vector(axis) is None:
            raise ModelError(f"{written(axis)} is not a direction (zero or not finite)", path=source, element=where)
    return value


def _entry_keys(value: dict[str, Any], key: str, source: str) -> dict[str, Any]:
    shape = _SHAPES[key]
    for name, spec in value.items():
        if isinstance(spec, msgspec.Struct):  # an entry built in code, typed already
            continue
        if not isinstance(spec, dict) or not set(spec) <= set(shape[0]):
            raise ModelError(shape[1], path=source, element=f"[{key}] {name}")
    return value


_SHAPES = {
    "sliders": (("block", "on", "at", "along"), "a slider is {block = LINK, on = LINK, at = JOINT, along = ANGLE or [P, Q]}"),
    "slots": (("pin", "slot", "along"), "a pin-in-slot joint is {pin = LINK, slot = LINK, along = ANGLE or [P, Q]}"),
    "masses": (("mass", "at", "izz", "inertia"), "give mass, at and izz (planar) or inertia (spatial): "
               '{ mass = "0.4 kg", at = "G", izz = "2e-4 kg*m^2" }'),
}


def _names(value: Any, where: str, source: str) -> list[str]:
    """A list of joint names, none twice."""
    if not isinstance(value, (list, tuple)) or not all(isinstance(n, str) for n in value):
        raise ModelError(f"must be a list of joint names, e.g. [\"A\", \"B\"], got {value!r}", path=source,
                         element=where)
    if len(set(value)) != len(value):
        raise ModelError(f"lists a joint twice: {value}", path=source, element=where)
    return list(value)


_SAY = {"polar": 'a polar construction has from = "JOINT", length, angle (from the x axis)',
        "compass": 'a compass construction has from = ["A", "B"], lengths = [|A..|, |B..|], side = "left" or '
                   '"right" (of the line A -> B)',
        "bearing": 'a bearing construction has from = ["A", "B"], length (from A), angle (from the line A -> B)'}
_KEYS_OF = {"polar": ("from", "length", "angle"), "compass": ("from", "lengths", "side"),
            "bearing": ("from", "length", "angle")}


def _joint(spec: Any, where: str, source: str) -> Any:
    """A joint's entry checked for shape: coordinates, or a polar, compass or bearing construction."""
    if isinstance(spec, (Polar, Compass, Bearing)):  # built in code, typed already
        return spec
    if isinstance(spec, (list, tuple)):
        if len(spec) not in (2, 3):
            raise ModelError(f"give coordinates [x, y] (or [x, y, z]) with units, got {spec!r}", path=source,
                             element=where)
        return spec
    if not isinstance(spec, dict):
        raise ModelError(f"give [x, y] with units or a construction table, got {spec!r}", path=source, element=where)
    origin = spec.get("from")
    bases = [origin] if isinstance(origin, str) else origin
    if not isinstance(bases, (list, tuple)) or not all(isinstance(b, str) for b in bases):
        raise ModelError("a construction needs from = \"JOINT\" (with length, angle) or from = [\"A\", \"B\"] "
                         "(with lengths, side; or with length, angle from the line A -> B)", path=source, element=where)
    kind = _construction(spec)
    message = unknown_keys(spec, _KEYS_OF[kind], hint=_SAY[kind])
    missing = [k for k in _KEYS_OF[kind] if k not in spec]
    if message or missing:
        raise ModelError(message or f"missing {', '.join(missing)}: {_SAY[kind]}", path=source, element=where)
    if kind != "polar" and len(bases) != 2:
        raise ModelError(f"from names {len(bases)} joints: {_SAY[kind]}", path=source, element=where)
    if kind == "compass":
        if not isinstance(spec["lengths"], (list, tuple)) or len(spec["lengths"]) != 2:
            raise ModelError(f"lengths must be two lengths, got {spec['lengths']!r}", path=source, element=where)
        if spec["side"] not in ("left", "right"):
            raise ModelError(f"side must be \"left\" or \"right\", got {spec['side']!r}", path=source, element=where)
    return spec


def _construction(spec: dict) -> str:
    """Which construction a table is: polar (from one joint), else compass or bearing (from
    two), whichever of their keys it writes more of (a misspelt key then named as unknown)."""
    if isinstance(spec.get("from"), str):
        return "polar"
    score = {k: len(set(spec) & set(_KEYS_OF[k])) for k in ("compass", "bearing")}
    return "bearing" if score["bearing"] > score["compass"] else "compass"


def read_linkage_spec(path: Any) -> tuple[LinkageSpec, str]:
    """Read and validate a linkage file: (its LinkageSpec, the file's name for messages).

    Raises:
        ModelError: a missing file, malformed TOML, or anything the spec refuses (one line
            naming the file and the key).
    """
    from pinmech.arguments import file_path
    from pinmech.toml_file import read_toml

    path = file_path(path, "the linkage file")
    source = str(path)
    return linkage_spec(read_toml(path, "linkage", ModelError), source), source


def linkage_spec(raw: dict[str, Any], source: str = "<linkage>") -> LinkageSpec:
    """Validate the tables of a linkage file (as TOML reads them) into a LinkageSpec.

    Raises:
        ModelError: one line naming `source` and the first key in error.
    """
    if not isinstance(raw, dict):
        raise ModelError("a linkage file is a table of keys", path=source)
    message = unknown_keys(raw, sorted(_KEYS))
    if message:
        raise ModelError(message, path=source)
    token = _SOURCE.set(source)
    try:
        return LinkageSpec(**raw)
    finally:
        _SOURCE.reset(token)


def _check_references(spec: LinkageSpec, source: str) -> None:
    """Every name an entry uses is given where it must be (joints, links, earlier joints)."""
    joints = list(spec.joints)
    for name, entry in spec.joints.items():
        bases = [entry.base] if isinstance(entry, Polar) else list(entry.bases) if isinstance(entry, (Compass, Bearing)) else []
        for base in bases:
            if base not in joints[: joints.index(name)]:
                above = ", ".join(joints[: joints.index(name)]) or "none"
                later = " (it is given below: a construction uses joints above it)" if base in joints else ""
                raise ModelError(f"from names '{base}', which is not given above it{later}; joints above: {above}",
                                 path=source, element=f"[joints] {name}")
    for link, names in {GROUND: spec.ground, **spec.links}.items():
        for name in names:
            if name not in spec.joints:
                raise ModelError(f"names joint '{name}', which [joints] does not give (joints: {', '.join(joints)})",
                                 path=source, element=f"[links] {link}" if link != GROUND else "ground")
    if not spec.links:
        raise ModelError("no link: list the moving links under [links]", path=source)
    for where, names in ((f"[axes] {n}", [n]) for n in spec.axes):
        _joints_given(names, spec, source, where)
    _joints_given(list(spec.balls), spec, source, "balls")
    links = [GROUND, *spec.links]
    for name, slider in spec.sliders.items():
        _check_slider(name, slider, spec, links, source)
    for name, slot in spec.slots.items():
        _check_slot(name, slot, spec, links, source)
        links.append(f"{name}_block")
    for link, mass in spec.masses.items():
        _check_mass(link, mass, spec, source)


def _joints_given(names: list[str], spec: LinkageSpec, source: str, where: str) -> None:
    for name in names:
        if name not in spec.joints:
            raise ModelError(f"'{name}' is not a joint of [joints] (joints: {', '.join(spec.joints)})", path=source,
                             element=where)


def _link(value: Any, links: list[str], key: str, source: str, where: str) -> str:
    if not isinstance(value, str) or value not in links:
        raise ModelError(f"{key} = {value!r} names no link (links: {', '.join(links)})", path=source, element=where)
    return value


def _check_along(along: Any, spec: LinkageSpec, source: str, where: str) -> None:
    if along is None:
        raise ModelError("has no line: give along = \"ANGLE\" or along = [\"P\", \"Q\"]", path=source, element=where)
    if isinstance(along, tuple) and (len(along) != 2 or not all(n in spec.joints for n in along)):
        raise ModelError(f"along = {list(along)!r} must name two joints of [joints] (joints: {', '.join(spec.joints)})",
                         path=source, element=where)


def _check_slider(name: str, slider: Slider, spec: LinkageSpec, links: list[str], source: str) -> None:
    where = f"[sliders] {name}"
    block = _link(slider.block, links, "block", source, where)
    on = _link(slider.on, links, "on", source, where)
    if block == on:
        raise ModelError(f"block and on are the same link '{block}'", path=source, element=where)
    if slider.at not in ({GROUND: spec.ground, **spec.links}.get(block) or ()):
        listed = ", ".join({GROUND: spec.ground, **spec.links}.get(block) or ()) or "none"
        raise ModelError(f"at = {slider.at!r} must be a joint the block '{block}' lists ({listed})", path=source,
                         element=where)
    _check_along(slider.along, spec, source, where)


def _check_slot(name: str, slot: Slot, spec: LinkageSpec, links: list[str], source: str) -> None:
    where = f"[slots] {name}"
    pin_link = _link(slot.pin, links, "pin", source, where)
    _link(slot.slot, links, "slot", source, where)
    if name not in spec.joints:
        raise ModelError(f"the slot's pin '{name}' is not given in [joints] (joints: {', '.join(spec.joints)})",
                         path=source, element=where)
    if name not in ({GROUND: spec.ground, **spec.links}.get(pin_link) or ()):
        raise ModelError(f"the pin '{name}' must be listed by its link '{pin_link}'", path=source, element=where)
    if f"{name}_block" in spec.links:  # it would be replaced by the block, in silence
        raise ModelError(f"link '{name}_block' has the name pinmech gives slot {name}'s block (a hidden link): "
                         "rename the link", path=source, element=f"[links] {name}_block")
    _check_along(slot.along, spec, source, where)


def _check_mass(link: str, mass: MassSpec, spec: LinkageSpec, source: str) -> None:
    where = f"[masses] {link}"
    if link not in spec.links:
        raise ModelError(f"names no moving link (links: {', '.join(spec.links)})", path=source, element=where)
    if isinstance(mass.at, str) and mass.at not in spec.joints:
        raise ModelError(f"at = {mass.at!r} is not a joint of [joints] (give its name or coordinates; joints: "
                         f"{', '.join(spec.joints)})", path=source, element=where)
    if not isinstance(mass.at, (str, tuple)) or (isinstance(mass.at, tuple) and len(mass.at) not in (2, 3)):
        raise ModelError(f"at = {mass.at!r}: the centre of mass is a joint's name or [x, y] (or [x, y, z]) "
                         "with units", path=source, element=where)


#: The shape checks of the tables that have one, before their types are checked.
_CHECKS = {"params": _param_names, "ground": _names, "balls": _names, "links": _link_lists, "joints": _joint_shapes,
           "axes": _axis_shapes, "sliders": _entry_keys, "slots": _entry_keys, "masses": _entry_keys}
