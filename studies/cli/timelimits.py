"""The joint limits ``rmt time`` and ``rmt plan --time`` time a path under: ``--v-max``, ``--a-max``,
``--j-max`` and ``--tau-max`` from the command line (robot file units → SI), or the robot file's
``max_velocity`` and ``max_acceleration``."""
from __future__ import annotations

import numpy as np

from studies.cli.common import CliInputError, numbers
from studies.units import joint_units

#: the unit of each limit option (its values must lie in planning.timing.limits.LIMIT_RANGE, as a task's
#: ``[cycle]`` limits)
LIMIT_UNITS = {"--v-max": "robot file units/s", "--a-max": "robot file units/s²", "--j-max": "robot file units/s³",
               "--tau-max": "N·m or N"}


def per_joint(robot, raw, what: str, unit_power: int, default_attr: str | None) -> np.ndarray | None:
    """A limit per joint from the command line (one value for all, or one per joint; robot file units
    per s^unit_power → SI), or from the joints' ``default_attr`` (SI) when all are known; None else."""
    c = robot.chain
    if raw is None:
        if default_attr is None:
            return None
        known = [getattr(j, default_attr, None) for j in c.joints]
        return None if any(v is None for v in known) else np.array(known, float)
    v = numbers(raw, what)
    if len(v) not in (1, robot.n):
        raise CliInputError(f"{what}: got {len(v)} values; give one for every joint or {robot.n} "
                            f"(one per joint of {robot.name})")
    arr = np.full(robot.n, v[0]) if len(v) == 1 else np.array(v)
    from planning.timing.limits import LIMIT_RANGE, limit_out_of_range
    k = limit_out_of_range(arr)
    if k is not None:
        unit = LIMIT_UNITS[what]
        which = "" if len(v) == 1 else f" (joint {c.joint_names()[k]})"
        raise CliInputError(f"{what}: {v[0 if len(v) == 1 else k]:g}{which} is outside the allowed range "
                            f"[{LIMIT_RANGE[0]:g}, {LIMIT_RANGE[1]:g}] ({unit})")
    return arr if unit_power == 0 else c.to_si(arr)


def limits_or_defaults(robot, v_raw, a_raw) -> tuple[np.ndarray, np.ndarray]:
    """``--v-max`` and ``--a-max`` (robot file units) → SI, each defaulting to the robot file's
    ``max_velocity``/``max_acceleration``; one line naming the option (and its unit) when neither is there."""
    units = sorted(set(f"{u}/s" for u in joint_units(robot.chain)))
    out = []
    for raw, name, attr, word, power in ((v_raw, "--v-max", "max_velocity", "speeds", ""),
                                         (a_raw, "--a-max", "max_acceleration", "accelerations", "²")):
        v = per_joint(robot, raw, name, 1, attr)
        if v is None:
            missing = [robot.chain.joint_names()[j] for j, jt in enumerate(robot.chain.joints)
                       if getattr(jt, attr) is None]
            which = "" if len(missing) == robot.n else f" for joint(s) {', '.join(missing)}"
            raise CliInputError(f"{robot.name} has no published {word}{which} (its robot file gives no {attr}): "
                                f"give {name} {name[2].upper()} ({', '.join(u + power for u in units)}; one value "
                                f"for every joint or one per joint)")
        out.append(v)
    return out[0], out[1]
