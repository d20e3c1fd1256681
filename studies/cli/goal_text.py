"""The lines ``rmt plan`` prints about a goal given as a tool pose: the configuration chosen (robot file
units), why, and which candidates were refused (:func:`planning.ompl.goals.goal_from_pose`)."""
from __future__ import annotations

import numpy as np

from studies.units import joint_units

__all__ = ["goal_lines"]


def goal_lines(chain, res) -> str:
    """The goal of ``res`` (a PlanResult of a pose goal) in words; empty when no goal was chosen (the
    status then says why)."""
    b = res.goal_branch
    if b is None or res.goal is None:
        return ""
    units = joint_units(chain)
    q = chain.from_si(np.asarray(res.goal))
    vals = ", ".join(f"{x + 0.0:.5g}" for x in np.where(np.abs(q) < 1e-9, 0.0, q))
    unit = units[0] if len(set(units)) == 1 else "file units"
    lines = [f"goal pose ({b['frame']}): goal q = ({vals}) {unit}, by {b['source']}", f"  {b['why']}"]
    if b.get("start_cell_reason") and res.separation is None:       # else the status says it
        lines.append(f"  none lies on the start's side of every window: {b['start_cell_reason']}")
    return "\n".join(lines)
