"""Task rows: the rows of the Jacobian a robot controls (``robot.task_rows``).  A chain whose tool
point never moves has none, and its dexterity measures, singular set and windows would be rounding
noise; every command and study that needs them refuses it first (:func:`require_task_rows`).

A module of its own, without the study engine, so that the command line imports it at start-up
for nothing more than this check."""
from __future__ import annotations

import kin

__all__ = ["require_task_rows"]


def require_task_rows(robot: kin.Robot) -> kin.Robot:
    """Refuse a chain whose tool point never moves (no task rows): its dexterity measures, singular
    set and windows would be rounding noise (σ_min ≈ 1e-310), not answers.  Returns ``robot``."""
    if not robot.task_rows:
        raise kin.ChainError(f"{robot.name}: no task rows to control: the tool point never moves (every "
                             "position row of the Jacobian is identically zero); name rows with task = [...]")
    return robot
