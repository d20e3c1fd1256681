"""The tool handle of ``rmt view``: a tool pose dragged in the browser → the configuration that reaches
it on the nearest valid branch to the current one.

The candidates are every branch of the closed form where the chain has one
(:func:`kin.ik.analytic.analytic_branches`: spherical wrists, the UR family) with its whole-turn copies
inside the limits (:func:`kin.ik.analytic.turn_copies`); else the warm-started IK from the current
configuration (:func:`kin.ik.local_ik`: the continuation a drag is) and, when that does not converge,
the full IK.  The nearest candidate (joint-space distance, SI) that the view's checker accepts (limits,
windows, σ_min floor, collisions: :class:`planning.ompl.validity.JointSpaceChecker`) is chosen; when
none is valid, the nearest inside the limits with the reason it is refused — the viewer shows the pose
as it is, red; when none reaches the pose, None with "out of reach"."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["HandleAnswer", "solve_handle"]


@dataclass(frozen=True)
class HandleAnswer:
    """``q`` (SI) or None (out of reach); ``valid``: the checker accepts it; ``text``: one line;
    ``candidates``: how many configurations reach the pose within the limits."""

    q: np.ndarray | None
    valid: bool
    text: str
    candidates: int


def _within(chain, Q: np.ndarray) -> np.ndarray:
    return Q[chain.within_limits(Q)] if len(Q) else Q


def candidates(robot, pose_base: np.ndarray, q_now: np.ndarray) -> tuple[np.ndarray, str]:
    """Configurations (k, n; SI) reaching ``pose_base`` (4×4, the robot's base placement frame, m)
    within the limits, and where they came from ("closed form" or "numeric IK")."""
    from kin.ik.analytic import NoClosedFormError, analytic_branches, turn_copies
    c = robot.chain
    try:
        branches = np.atleast_2d(np.asarray(analytic_branches(robot, pose_base, q_ref=q_now), float))
        out = []
        for b in branches:
            if len(b) != c.n:
                continue
            # whole turns of the revolute joints only: a prismatic joint's bounds are its value
            cp = np.atleast_2d(turn_copies(b, np.where(c.revolute_mask, c.lower, b), np.where(c.revolute_mask,
                                                                                             c.upper, b)))
            out.extend(_within(c, cp) if cp.size else [])
        return (np.array(out, float).reshape(-1, c.n), "closed form")
    except NoClosedFormError:
        pass
    from kin.ik import local_ik
    res = local_ik(robot, pose_base, q_now)
    if not res.success:
        res = robot.ik(pose_base, seed=0, q0=q_now)
    Q = np.atleast_2d(np.asarray(res.q, float)) if res.success else np.zeros((0, c.n))
    return _within(c, Q), "numeric IK"


def solve_handle(model, pose_world: np.ndarray, q_now) -> HandleAnswer:
    """The configuration for the tool pose ``pose_world`` (4×4 in the world/cell frame, m) nearest
    ``q_now`` (SI) among the valid ones of ``model`` (:class:`studies.view.readouts.LiveModel`)."""
    q_now = np.asarray(q_now, float)
    pose_base = np.linalg.solve(model.base, np.asarray(pose_world, float))
    Q, source = candidates(model.robot, pose_base, q_now)
    if not len(Q):
        return HandleAnswer(None, False, f"out of reach ({source}: no configuration within the limits)", 0)
    order = np.argsort(np.linalg.norm(Q - q_now, axis=1), kind="stable")
    checker = model.checker()
    first_bad = None
    for i in order:
        refusal = checker.refusal([float(x) for x in Q[i]])
        if refusal is None:
            return HandleAnswer(Q[i], True, f"IK ({source}): the nearest valid of {len(Q)} configuration(s)", len(Q))
        if first_bad is None:
            first_bad = (i, refusal[2])
    i, why = first_bad
    return HandleAnswer(Q[i], False, f"IK ({source}): none of {len(Q)} configuration(s) is valid; the nearest is "
                                     f"{why}", len(Q))
