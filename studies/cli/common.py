"""Helpers shared by the ``rmt`` commands: number parsing, windows from the command line, JSON."""
from __future__ import annotations

import json
import math
from typing import Sequence

import numpy as np

import kin


EXIT_OK, EXIT_FAIL, EXIT_USAGE = 0, 1, 2


class CliInputError(kin.RmtError):
    """Bad command-line input (the CLI exits with code 2)."""


def numbers(values: Sequence[str], what: str) -> list[float]:
    """Parse finite numbers; ``what`` names the argument in the error."""
    out = []
    for v in values:
        try:
            x = float(v)
        except ValueError:
            raise CliInputError(f"{what}: {v!r} is not a number") from None
        if not math.isfinite(x):
            raise CliInputError(f"{what}: {v!r} is not a finite number")
        out.append(x)
    return out


def joint_values(robot: kin.Robot, values: Sequence[str], what: str = "joint values") -> np.ndarray:
    """A configuration given in the robot file's units → SI, checked for count and finiteness."""
    q = numbers(values, what)
    if len(q) != robot.n:
        units = ", ".join(c.angle_unit if j.is_revolute else c.length_unit
                          for c in [robot.chain] for j in c.joints)
        raise CliInputError(f"{what}: got {len(q)} values; {robot.name} has {robot.n} joints ({units})")
    return robot.chain.to_si(q)


def factor_margins(chain: kin.Chain, analysis, margin: float) -> list[float]:
    """One margin in file units → SI per factor: an angle for factors with a revolute joint, a length
    for purely prismatic ones."""
    if not (math.isfinite(margin) and margin >= 0):
        raise CliInputError(f"--margin {margin} must be a finite number ≥ 0 (robot file units)")
    return [margin * (chain.angle_scale if any(chain.joints[j - 1].is_revolute for j in f.joints)
                      else chain.length_scale) for f in analysis.factors]


def windows_from_args(robot: kin.Robot, margin: float | None, sigma_min: float | None, seed: int = 0):
    """Windows from ``--margin`` (file units) or ``--sigma-min`` (SI threshold); None when neither."""
    if margin is None and sigma_min is None:
        return None
    from kin.singular import analyse_singularities
    from planning.windows import build_windows
    from studies.cli.progress import TerminalProgress
    with TerminalProgress() as progress:
        analysis = analyse_singularities(robot, seed=seed, progress=progress)
    if margin is not None:
        return build_windows(robot, margin=factor_margins(robot.chain, analysis, margin), analysis=analysis)
    return build_windows(robot, sigma_min=sigma_min, analysis=analysis, seed=seed)


def jsonable(obj):
    """numpy values → plain Python; NaN and infinities → None (strict JSON)."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (np.floating, float)):
        x = float(obj)
        return x if math.isfinite(x) else None
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def dump(obj) -> str:
    """One line of strict JSON."""
    return json.dumps(jsonable(obj), allow_nan=False)
