"""Joint values in words, in the robot file's units with the unit named: what every message that
shows a user a joint value uses ("joint 5 (wrist2) = 0°", "[-5°, 5°]", "12.5 mm")."""
from __future__ import annotations


def _unit(chain, j: int) -> tuple[float, str]:
    """(SI per file unit, unit) of joint ``j`` (0-based)."""
    if chain.joints[j].is_revolute:
        return chain.angle_scale, chain.angle_unit
    return chain.length_scale, chain.length_unit


def joint_value(chain, j: int, v: float, digits: int = 6) -> str:
    """A value of joint ``j`` (0-based), SI → file units with the unit: "5°", "0.1 rad", "12 mm"."""
    s, u = _unit(chain, j)
    x = float(v) / s + 0.0
    return f"{x:.{digits}g}°" if u == "deg" else f"{x:.{digits}g} {u}"


def joint_interval(chain, j: int, lo: float, hi: float, digits: int = 6) -> str:
    """An interval of joint ``j`` (0-based), SI → "[-5°, 5°]" in file units."""
    return f"[{joint_value(chain, j, lo, digits)}, {joint_value(chain, j, hi, digits)}]"


def joint_label(chain, j: int) -> str:
    """"joint 5 (wrist2)" for joint ``j`` = 4 (0-based), "joint 5" when it has no name."""
    name = chain.joints[j].name
    return f"joint {j + 1} ({name})" if name else f"joint {j + 1}"
