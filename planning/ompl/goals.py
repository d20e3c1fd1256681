"""Goals given as a tool pose: the configurations that reach it (every analytic IK branch where the
chain has a closed form, numeric IK from several starts, the flipped-wrist twins) and the one to
plan to — valid, in the start's free cell, nearest first."""
from __future__ import annotations

import math

import numpy as np

from kin.ik.analytic import NoClosedFormError, analytic_ik
from planning.certify import FreeCells
from planning.errors import PlanningError
from planning.ompl.validity import JointSpaceChecker

__all__ = ["goal_from_pose", "wrist_twins"]


def wrist_twins(robot, q: np.ndarray, pose: np.ndarray) -> list[np.ndarray]:
    """The flipped-wrist twins of ``q`` (q4 ± π, −q5, q6 ± π) that reach the same pose — a spherical
    wrist has them; the FK check keeps only true twins, whatever the chain."""
    n = robot.n
    if n < 6 or not all(robot.chain.joints[k].is_revolute for k in (n - 3, n - 2, n - 1)):
        return []
    out = []
    for s4 in (math.pi, -math.pi):
        for s6 in (math.pi, -math.pi):
            f = q.copy()
            f[n - 3] += s4
            f[n - 2] = -f[n - 2]
            f[n - 1] += s6
            T = robot.fk(f)
            if np.abs(T - pose).max() < 1e-9 and robot.within_limits(f):
                out.append(f)
    return out


def goal_from_pose(robot, pose: np.ndarray, start: np.ndarray, checker: JointSpaceChecker,
                    cells: FreeCells, seed: int) -> tuple[np.ndarray, dict]:
    """The goal configuration of a tool pose: among its IK branches (every branch of the closed form
    where the chain has one, :func:`kin.ik.analytic.analytic_ik`), the solutions of the numeric IK
    from several starts and their wrist twins, the valid ones in the start's free cell, nearest the
    start first (else the nearest valid one; the caller then reports the separation).  Returns it and a description."""
    cands: list[np.ndarray] = []
    try:                                 # every branch in closed form where the chain has one
        cands.extend(analytic_ik(robot, pose, q_ref=start))
    except NoClosedFormError:
        pass
    for k in range(8):
        res = robot.ik(pose, seed=seed + k, q0=start if k == 0 else None)
        if res.success:
            cands.append(res.q)
            cands.extend(wrist_twins(robot, res.q, pose))
    uniq: list[np.ndarray] = []
    for c in cands:
        if checker.state_valid(list(c)) and not any(np.abs(c - u).max() < 1e-6 for u in uniq):
            uniq.append(c)
    if not uniq:
        raise PlanningError("goal pose: no valid IK solution (inside the limits, outside every window"
                            + (", above the σ_min floor" if checker.sigma_floor else "") + ")")
    dist = [float(np.linalg.norm(c - start)) for c in uniq]
    same = [cells.same_cell(start, c) for c in uniq]
    order = sorted(range(len(uniq)), key=lambda i: (not same[i], dist[i]))
    best = order[0]
    nearest = int(np.argmin(dist))
    info = {"candidates": len(uniq), "in_start_cell": int(sum(same)), "chosen_distance": dist[best],
            "nearest_distance": dist[nearest], "nearest_in_start_cell": bool(same[nearest]),
            "q": uniq[best].tolist()}
    return uniq[best], info
