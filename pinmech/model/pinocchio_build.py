"""Pinocchio's model builders called safely: urdfdom's chatter folded into one-line errors,
joints locked out of the model, and models too large for Pinocchio's working data refused."""

from __future__ import annotations

import math
import os
import sys
import tempfile

import numpy as np
import pinocchio as pin

from pinmech.exceptions import FrameNotFound, ModelError
from pinmech.model.frame_names import reduced_model

_ROOT_JOINTS = {"free_flyer": pin.JointModelFreeFlyer}


def _build_model(source: str, root_joint: str | None = None, *, mimic: bool = False) -> pin.Model:
    """pin.buildModelFromUrdf (honouring `<mimic>` when asked), with urdfdom's own stderr
    chatter folded into the error."""
    if root_joint is not None and root_joint not in _ROOT_JOINTS:
        raise ModelError(f"root_joint must be None or one of {', '.join(_ROOT_JOINTS)}, got {root_joint!r}",
                         path=source)
    args = (_ROOT_JOINTS[root_joint](),) if root_joint else ()
    return pinocchio_build(lambda: pin.buildModelFromUrdf(source, *args, mimic=mimic), source)


def pinocchio_build(build, source: str):
    """Call one of Pinocchio's model builders with the C++ parsers' stderr chatter caught,
    and fold that chatter into a one-line ModelError when the builder fails."""
    with tempfile.TemporaryFile(mode="w+b") as sink:
        saved = os.dup(2)
        try:
            sys.stderr.flush()
            os.dup2(sink.fileno(), 2)
            try:
                return build()
            except (ValueError, RuntimeError) as exc:
                error = exc
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        sink.seek(0)
        said = " ".join(sink.read().decode(errors="replace").split())
    detail = f" ({said})" if said else ""
    message = " ".join(f"{error}{detail}".split())  # Pinocchio's messages run over several lines
    raise ModelError(f"Pinocchio cannot build the model: {message}", path=source) from error


def _check_locked(locked: dict[str, float], source: str) -> None:
    """Every locked value is a finite number (SI), else a ModelError naming the joint."""
    if not isinstance(locked, dict):
        raise ModelError(f"locked must be a dict of joint name -> value (rad or m), got {locked!r:.60}", path=source)
    for name, value in locked.items():
        if not isinstance(name, str):
            raise ModelError(f"locked must name joints (str), got the key {name!r:.40}", path=source)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(_as_float(value)):
            raise ModelError(f"locked joint '{name}' must be held at a finite number (rad or m), got {value!r:.40}",
                             path=source)


def _as_float(value: int | float) -> float:
    """value as a float; an int beyond float64 as infinity (refused as not finite)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf


def _lock_joints(model: pin.Model, locked: dict[str, float], source: str) -> pin.Model:
    if not locked:
        return model
    q_ref = pin.neutral(model)
    ids = []
    for name, value in locked.items():
        if not model.existJointName(name):
            raise FrameNotFound("joint to lock", name, [n for n in model.names[1:]], path=source)
        jid = model.getJointId(name)
        joint = model.joints[jid]
        if joint.nq == 0 and "Mimic" in joint.shortname():
            pass  # a follower: its leader, locked with it, sets where it is held
        elif joint.nq == 2 and joint.nv == 1:
            q_ref[joint.idx_q : joint.idx_q + 2] = (np.cos(value), np.sin(value))
        elif joint.nq == 1:
            q_ref[joint.idx_q] = value
        else:
            raise ModelError(f"joint '{name}' has {joint.nq} coordinates and cannot be locked by one value", path=source)
        ids.append(jid)
    return reduced_model(model, ids, q_ref)


#: Most degrees of freedom a model may keep. Pinocchio's `Data` allocates, whatever it is
#: used for, four nv x nv x nv tensors (second derivatives of the inverse dynamics:
#: d2tau_dqdq, d2tau_dvdv, d2tau_dqdv, d2tau_dadq; data.hxx) and a 6 x nv x nv one, so its
#: size grows as nv^3: measured with Pinocchio 4.1, 69 MB at nv = 100, 0.5 GB at 200, 4 GB at
#: 400 (62.5 bytes per nv^3, chains and stars alike). pinmech makes several Data; past this
#: a model would exhaust memory (a 1,000-link chain: 62 GB) before anything is solved.
MAX_DOF = 256
_DATA_BYTES_PER_DOF_CUBED = 62.5


def _check_size(model: pin.Model, source: str) -> None:
    """Raises ModelError (one line, with the memory it would take) for a model with more
    degrees of freedom than `MAX_DOF`, before Pinocchio tries to allocate its Data."""
    if model.nv > MAX_DOF:
        gigabytes = _DATA_BYTES_PER_DOF_CUBED * model.nv**3 / 1e9
        raise ModelError(f"the model keeps {model.nv} degrees of freedom ({model.njoints - 1} joints); Pinocchio's "
                         f"working data for it would take about {gigabytes:.3g} GB (it holds nv x nv x nv tensors of "
                         f"second derivatives), so pinmech takes at most {MAX_DOF}: lock the joints the scene holds "
                         "still ([lock], or move = [...])", path=source)

