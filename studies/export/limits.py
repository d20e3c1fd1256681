"""Does a trajectory keep to the robot's limits?  Joint positions within the robot file's limits,
speeds within ``max_velocity`` and accelerations within ``max_acceleration`` of every joint that has
them — at the samples, at the resampled stream's samples when there is one, and the mean speed
between consecutive samples (a jump in q that the q̇ column hides is a breach too)."""
from __future__ import annotations

import numpy as np

from studies.units import joint_units

__all__ = ["first_breach", "POSITION_SLACK", "RATE_SLACK"]

#: slack of the position limits, SI (rad or m): rounding of a file in degrees or mm
POSITION_SLACK = 1e-9
#: relative slack of the speed and acceleration limits (a timing's own rounding)
RATE_SLACK = 1e-6


def _limits(robot) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """kind → (lower, upper) (n,) SI; ±inf where the robot file gives no limit."""
    c = robot.chain
    out = {"position": (c.lower - POSITION_SLACK, c.upper + POSITION_SLACK)}
    for kind, attr in (("velocity", "max_velocity"), ("acceleration", "max_acceleration")):
        m = np.array([np.inf if getattr(j, attr) is None else getattr(j, attr) for j in c.joints], float)
        m = m * (1 + RATE_SLACK)
        out[kind] = (-m, m)
    return out


def first_breach(robot, checks: list[tuple[str, np.ndarray, np.ndarray]]) -> str | None:
    """The earliest sample that breaks a limit, as one sentence naming the joint, the time, the value and
    the limit in robot file units; None when every value keeps to them.  ``checks``: (kind, times (T,),
    values (T, n) SI) with kind one of ``position``, ``velocity``, ``acceleration`` or ``mean velocity``
    (checked against the velocity limits)."""
    lim = _limits(robot)
    c = robot.chain
    names, units = c.joint_names(), joint_units(c)
    found = None
    for kind, times, X in checks:
        lo, hi = lim["velocity" if kind == "mean velocity" else kind]
        bad = (X < lo) | (X > hi)
        if not bad.any():
            continue
        i, j = (int(x) for x in np.argwhere(bad)[0])
        if found is None or times[i] < found[0]:
            found = (float(times[i]), kind, j, float(X[i, j]))
    if found is None:
        return None
    t, kind, j, x = found
    power = {"position": "", "velocity": "/s", "mean velocity": "/s", "acceleration": "/s²"}[kind]
    u = units[j] + power
    scale = c.variable_scale[j]
    if kind == "position":
        lim_text = f"its limits [{c.lower[j] / scale:.10g}, {c.upper[j] / scale:.10g}] {u}"
    else:
        attr = "max_velocity" if "velocity" in kind else "max_acceleration"
        lim_text = f"its {attr} {getattr(c.joints[j], attr) / scale:.10g} {u}"
    where = f"between t = {t:.6g} s and the next sample" if kind == "mean velocity" else f"at t = {t:.6g} s"
    return (f"joint {names[j]} {kind} {x / scale:.10g} {u} {where} is beyond {lim_text} ({robot.name}); "
            f"the trajectory breaks the robot's limits")
