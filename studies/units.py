"""Conversions between SI results and a robot file's units, for everything the CLI and reports show."""
from __future__ import annotations

import numpy as np

from kin import Chain


def pose_to_file(chain: Chain, T: np.ndarray) -> np.ndarray:
    """A pose (…, 4, 4) with its translation in the file's length unit."""
    out = np.array(T, dtype=float, copy=True)
    out[..., :3, 3] /= chain.length_scale
    return out


def jacobian_to_file(chain: Chain, J: np.ndarray) -> np.ndarray:
    """Jacobian (…, 6, n) mapping joint rates in file units to [v in length/s; ω in angle/s]."""
    out = np.array(J, dtype=float, copy=True)
    var = chain.variable_scale                      # SI per file unit of each joint
    out[..., :3, :] *= var / chain.length_scale     # v rows: length_unit per joint unit
    out[..., 3:, :] *= var / chain.angle_scale      # ω rows: angle_unit per joint unit
    return out


def joint_value_to_file(chain: Chain, joint: int, v: float) -> float:
    """A value of joint ``joint`` (1-based) in SI → the file's unit of that joint."""
    return v / chain.variable_scale[joint - 1]


def unit_names(chain: Chain) -> dict[str, str]:
    return {"length": chain.length_unit, "angle": chain.angle_unit}


def joint_units(chain: Chain) -> list[str]:
    return [chain.angle_unit if j.is_revolute else chain.length_unit for j in chain.joints]
