"""Goals given as a tool pose: every configuration that reaches it, and the one to plan to.

The candidates are every branch of the closed form where the chain has one
(:func:`kin.ik.analytic.analytic_branches`: spherical wrists and the UR family) with *all* its
whole-turn copies inside the joint limits (a joint of ±360° gives each branch up to 2⁶ copies) —
else the solutions of the numeric IK from several starts, their flipped-wrist twins, and their
whole-turn copies.  Each candidate is refused for the first reason that applies, in this order:
outside the limits (a branch with no copy inside them), in a window, below the σ_min floor, in a
keep-out box, in collision, in another free cell than the start's (:class:`planning.certify.FreeCells`:
a path to it is proven impossible).  The goal is the remaining candidate nearest the start (joint-space
distance, SI); when every valid candidate lies in another free cell, the nearest valid one (the
planner then answers "no joint path" with the separation).  When none is valid,
:class:`GoalPoseError` names the reason of the best candidate — "out of reach", "outside the
limits", "in a window (<name>)", "below the σ_min floor", "in a keep-out box", "in collision
(<bodies>)" — and the frame the pose was given in.
"""
from __future__ import annotations

import math

import numpy as np

from kin.ik.analytic import NoClosedFormError, analytic_branches, turn_copies
from planning.certify import FreeCells
from planning.errors import PlanningError
from planning.ompl.validity import REFUSALS, JointSpaceChecker

__all__ = ["GoalPoseError", "REASONS", "goal_from_pose", "wrist_twins"]

#: the reasons a candidate is refused, in the order they are tested
REASONS = ("outside the limits", "in a window", "below the σ_min floor", "in a keep-out box", "in collision",
           "in another free cell")


class GoalPoseError(PlanningError):
    """No valid configuration reaches a goal pose; ``reason`` is the best candidate's (one of
    ``"out of reach"`` or :data:`REASONS`), ``info`` the counts (as :func:`goal_from_pose`'s)."""

    def __init__(self, message: str, reason: str, info: dict):
        super().__init__(message)
        self.reason = reason
        self.info = info


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


def _copies(robot, q: np.ndarray) -> np.ndarray:
    """``q`` and its whole-turn copies within the limits (revolute joints only)."""
    c = robot.chain
    if not c.revolute_mask.any():
        return q[None] if c.within_limits(q) else np.zeros((0, c.n))
    lo = np.where(c.revolute_mask, c.lower, q)
    hi = np.where(c.revolute_mask, c.upper, q)
    out = turn_copies(q, lo, hi)
    return out[c.within_limits(out)] if len(out) else out


def _candidates(robot, pose, start, seed) -> tuple[list[np.ndarray], int, str]:
    """(candidates inside the limits, branches with no copy inside them, source)."""
    try:
        branches = analytic_branches(robot, pose, q_ref=start)
        source = "closed form"
    except NoClosedFormError:
        branches, source = [], "numeric IK"
        for k in range(8):
            res = robot.ik(pose, seed=seed + k, q0=start if k == 0 else None)
            if res.success:
                branches.append(res.q)
                branches.extend(wrist_twins(robot, res.q, pose))
    cands, outside = [], 0
    for b in branches:
        cp = _copies(robot, np.asarray(b, dtype=float))
        outside += len(cp) == 0
        cands.extend(cp)
    uniq: list[np.ndarray] = []
    if cands:                    # duplicates (within 1e-6) dropped, the first kept; one array op per candidate
        C = np.asarray(cands, dtype=float)
        keep: list[int] = []
        for i in range(len(C)):
            if not keep or np.abs(C[keep] - C[i]).max(axis=1).min() >= 1e-6:
                keep.append(i)
        uniq = [C[i] for i in keep]
    return uniq, outside, source


def goal_from_pose(robot, pose: np.ndarray, start: np.ndarray, checker: JointSpaceChecker,
                   cells: FreeCells, seed: int, frame: str = "base frame") -> tuple[np.ndarray, dict]:
    """The goal configuration of a tool pose ``pose`` (4×4, the robot's base frame, SI; ``frame`` names
    the frame it was given in, for the messages): the valid candidate in the start's free cell nearest
    ``start`` (see the module docstring).  Returns it and a description: ``frame``, ``source`` ("closed
    form" or "numeric IK"), ``candidates`` (configurations considered inside the limits), ``valid``,
    ``in_start_cell``, ``refused`` (count per reason of :data:`REASONS`), ``chosen_distance``,
    ``nearest_distance`` (of the nearest valid one), ``nearest_in_start_cell``, ``q`` and ``why`` (one
    sentence).  Raises :class:`GoalPoseError` when no candidate is valid."""
    start = np.asarray(start, dtype=float)
    cands, outside, source = _candidates(robot, pose, start, seed)
    refused = dict.fromkeys(REASONS, 0)
    refused[REASONS[0]] = outside
    valid: list[np.ndarray] = []
    bad: list[tuple[np.ndarray, str, str]] = []          # refused candidates, nearest first
    dist: list[float] = []                                # of the valid ones, ascending
    for d, q in sorted(((float(np.linalg.norm(q - start)), q) for q in cands), key=lambda dq: dq[0]):
        refusal = checker.refusal([float(x) for x in q])
        if refusal is None:
            valid.append(q)
            dist.append(d)
            continue
        cat, detail = REASONS[REFUSALS.index(refusal[0])], refusal[1]
        refused[cat] += 1
        bad.append((q, cat, detail))
    info = {"frame": frame, "source": source, "candidates": len(cands), "valid": len(valid), "refused": refused}
    if not valid:
        if not cands and not outside:
            reason, text = "out of reach", "out of reach (no IK solution)"
        elif not cands:
            reason, text = REASONS[0], f"outside the limits (all {outside} IK branch(es))"
        else:
            reason, text = bad[0][1], _words(bad[0][1], bad[0][2])
        raise GoalPoseError(f"goal pose ({frame}): no valid configuration — the nearest candidate is {text}"
                            + _counts(refused), reason, {**info, "reason": reason})
    same = [cells.same_cell(start, q) for q in valid]
    refused[REASONS[5]] = len(valid) - sum(same)
    order = sorted(range(len(valid)), key=lambda i: (not same[i], dist[i]))
    best, nearest = order[0], 0                           # valid is sorted by distance
    why = (f"{len(valid)} of {len(cands)} candidate(s) valid, {sum(same)} in the start's free cell; the nearest "
           + ("such one" if same[best] else "valid one (none shares the start's free cell)")
           + f" chosen, {dist[best]:.4g} from the start" + _counts(refused))
    info.update({"in_start_cell": int(sum(same)), "chosen_distance": dist[best], "nearest_distance": dist[nearest],
                 "nearest_in_start_cell": bool(same[nearest]), "q": valid[best].tolist(), "why": why})
    if not same[best]:
        # why no goal on the start's side: the nearest refused candidate that shares the start's free cell
        # (collisions, σ_min floor, keep-out boxes leave the windows' cells as they are)
        for q, cat, detail in bad:
            if cat not in REASONS[:2] and cells.same_cell(start, q):
                info["start_cell_reason"] = (f"the nearest candidate in the start's free cell, "
                                             f"{_deg(robot, q)}, is {_words(cat, detail)}")
                break
        else:
            info["start_cell_reason"] = "no candidate lies in the start's free cell"
    return valid[best], info


def _words(cat: str, detail: str) -> str:
    return {REASONS[1]: f"in a window ({detail})", REASONS[4]: f"in collision ({detail})"}.get(cat, f"{cat} ({detail})")


def _counts(refused: dict) -> str:
    """The invalid candidates by reason (the valid ones in another free cell are counted apart, as the
    complement of those in the start's: they are valid, not refused)."""
    counts = ", ".join(f"{v} {k}" for k, v in refused.items() if v and k != REASONS[5])
    return f"; invalid: {counts}" if counts else ""


def _deg(robot, q) -> str:
    """A configuration in the robot file's units, e.g. ``(46.7, -76.3, …) deg``."""
    c = robot.chain
    units = sorted({c.angle_unit if j.is_revolute else c.length_unit for j in c.joints})
    v = c.from_si(np.asarray(q, dtype=float))
    return "(" + ", ".join(f"{x + 0.0:.4g}" for x in np.where(np.abs(v) < 1e-9, 0.0, v)) + ") " + "/".join(units)
