"""A task file's ``[cycle]`` table → :class:`design.cycle.CycleSpec` (SI).  Every bad field raises
:class:`design.task.TaskError` naming the file, the field and its allowed range.  Schema:
docs/design.md, "Cycle time and motor torque".

Lengths (``lift``) in the file's ``length_unit``; speeds and accelerations per joint in the file's
angle unit (revolute) or length unit (prismatic) per s and s²; ``tau_max`` in N·m (revolute) and N
(prismatic); masses SI (kg, kg/m, kg·m²); ``blend`` SI (rad or m of joint-space distance, as
:func:`planning.timing.time_parameterize`'s)."""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from design.cycle.masses import MAX_MASS_PER_LENGTH, MAX_PART_MASS, LinkMasses
from design.cycle.model import MAX_STOPS, TORQUE_MODES, CycleSpec
from design.task.model import TaskError
from planning.timing.limits import LIMIT_RANGE

__all__ = ["read_cycle", "CYCLE_KEYS", "MASS_KEYS", "MIN_LIMIT", "MAX_LIMIT"]

CYCLE_KEYS = ("sequence", "v_max", "a_max", "tau_max", "torque", "lift", "dwell", "blend", "ik_starts", "masses")
MASS_KEYS = ("mass_per_length", "motor_mass", "rotor_inertia", "payload")
#: the smallest and largest speed, acceleration (file units) or torque a cycle limit may have: the range
#: ``rmt time`` checks too (planning.timing.limits.LIMIT_RANGE)
MIN_LIMIT, MAX_LIMIT = LIMIT_RANGE


def _per_joint(r, raw: Any, field: str, n: int, scale: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """A number (every joint) or a list of n numbers in [lo, hi], times ``scale``."""
    vals = [raw] * n if not isinstance(raw, list) else raw
    if len(vals) != n:
        raise r.fail(field, f"must be a number or a list of {n} numbers (one per joint), got {len(vals)}")
    out = []
    for k, v in enumerate(vals):
        f = field if not isinstance(raw, list) else f"{field}[{k}]"
        x = r.number(v, f)
        if x < lo or x > hi:
            raise r.fail(f, f"must be in [{lo:g}, {hi:g}], got {v}")
        out.append(x * scale[k])
    return np.array(out, float)


def _from_robot(chain, attr: str) -> np.ndarray | None:
    vals = [getattr(j, attr, None) for j in chain.joints]
    return None if any(v is None for v in vals) else np.array(vals, float)


def read_cycle(r, raw: Any, robot, targets, ls: float, as_: float) -> CycleSpec:
    """The ``[cycle]`` table ``raw`` of a task file read by ``r`` (the task file's reader), for
    ``robot`` and the task's ``targets``; ``ls``, ``as_`` the file's length and angle scales (SI per unit)."""
    r.table(raw, "cycle", CYCLE_KEYS)
    chain = robot.chain
    n = chain.n
    unit = np.where(chain.revolute_mask, as_, ls)            # file unit → SI, per joint
    if "sequence" not in raw:
        raise r.fail("cycle.sequence", "missing (required): the target indices (0-based) the cycle visits in order")
    seq = raw["sequence"]
    if not isinstance(seq, list) or not 2 <= len(seq) <= MAX_STOPS:
        raise r.fail("cycle.sequence", f"must be a list of 2 to {MAX_STOPS} target indices (0-based)")
    seq = [r.integer(x, f"cycle.sequence[{i}]", 0, len(targets) - 1) for i, x in enumerate(seq)]
    lims = {}
    for key, attr, word in (("v_max", "max_velocity", "speed"), ("a_max", "max_acceleration", "acceleration")):
        if key in raw:
            lims[key] = _per_joint(r, raw[key], f"cycle.{key}", n, unit, MIN_LIMIT, MAX_LIMIT)
        else:
            got = _from_robot(chain, attr)
            if got is None:
                raise r.fail(f"cycle.{key}", f"missing: {chain.name} does not give every joint's {attr}, so the "
                                             f"cycle needs its joint {word} limits")
            lims[key] = got
    if "tau_max" in raw:
        tau = _per_joint(r, raw["tau_max"], "cycle.tau_max", n, np.ones(n), MIN_LIMIT, MAX_LIMIT)
    else:
        got = [j.max_torque for j in chain.joints]
        tau = np.array([math.nan if v is None else float(v) for v in got])
    torque = r.string(raw.get("torque", "check"), "cycle.torque", TORQUE_MODES)
    if torque == "limit" and np.isnan(tau).any():
        raise r.fail("cycle.torque", "\"limit\" needs tau_max for every joint (give cycle.tau_max)")
    lift = r.number(raw.get("lift", 0.0), "cycle.lift")
    if not 0 <= lift * ls <= 1e3:
        raise r.fail("cycle.lift", f"must be in [0, {1e3 / ls:g}] (length unit), got {raw.get('lift')}")
    dwell = r.number(raw.get("dwell", 0.0), "cycle.dwell")
    if not 0 <= dwell <= 3600:
        raise r.fail("cycle.dwell", f"must be in [0, 3600] s, got {dwell:g}")
    blend = r.number(raw.get("blend", 0.05), "cycle.blend")
    if not 0 <= blend <= 10:
        raise r.fail("cycle.blend", f"must be in [0, 10] (rad or m of joint-space distance), got {blend:g}")
    starts = r.integer(raw.get("ik_starts", 8), "cycle.ik_starts", 1, 64)
    if "masses" not in raw:
        raise r.fail("cycle.masses", "missing (required): the link mass model (mass_per_length, motor_mass, "
                                     "rotor_inertia, payload)")
    m = r.table(raw["masses"], "cycle.masses", MASS_KEYS)
    one = np.ones(n)
    mpl = _per_joint(r, m.get("mass_per_length", 0.0), "cycle.masses.mass_per_length", n, one, 0.0,
                     MAX_MASS_PER_LENGTH)
    mm = _per_joint(r, m.get("motor_mass", 0.0), "cycle.masses.motor_mass", n, one, 0.0, MAX_PART_MASS)
    ri = _per_joint(r, m.get("rotor_inertia", 0.0), "cycle.masses.rotor_inertia", n, one, 0.0, MAX_PART_MASS)
    pay = r.number(m.get("payload", 0.0), "cycle.masses.payload")
    if not 0 <= pay <= MAX_PART_MASS:
        raise r.fail("cycle.masses.payload", f"must be in [0, {MAX_PART_MASS:g}] kg, got {pay:g}")
    try:
        masses = LinkMasses.make(n, mpl, mm, ri, pay)
        return CycleSpec(tuple(seq), lims["v_max"], lims["a_max"], tau, masses, torque, lift * ls, dwell, blend,
                         starts)
    except TaskError as e:
        raise r.fail("cycle", str(e)) from None
