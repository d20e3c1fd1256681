"""Joint-space planning with OMPL around singular windows.

The roles are OMPL's: a :class:`ompl.base.RealVectorStateSpace` bounded by the joint limits, a
state validity checker (limits, outside every window, an optional σ_min floor, optional keep-out
boxes), a motion validator that checks a whole motion as one batch at a step finer than the
narrowest window (so no window can be jumped), a problem definition with an optional objective
(path length, or path length plus a singularity cost ∫ 1/σ_min), and a planner chosen by name.

Every returned path is re-checked by :func:`planning.validate.check_path`, independently of the
planner (and, with keep-out boxes, its densely interpolated tool points against the boxes); a path that fails is repaired (the unsimplified path, then re-planning with a finer
motion step) or reported as a failure — :func:`plan` never returns an invalid path as a success.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from kin.errors import ConfigurationError

from planning.errors import PlanningError
from planning.ompl.bindings import ob, og, quiet_rng_seed
from planning.validate import (
    DEFAULT_STEP_ANGLE,
    DEFAULT_STEP_LENGTH,
    PathCheck,
    check_path,
    densify,
)
from planning.ompl.validity import JointSpaceChecker, KeepOutBox

PLANNERS = {
    "rrtconnect": "RRTConnect", "rrt": "RRT", "rrtstar": "RRTstar", "informedrrtstar": "InformedRRTstar",
    "sorrtstar": "SORRTstar", "prm": "PRM", "prmstar": "PRMstar", "bitstar": "BITstar", "fmt": "FMT",
    "bfmt": "BFMT", "kpiece": "KPIECE1", "kpiece1": "KPIECE1", "bkpiece": "BKPIECE1", "bkpiece1": "BKPIECE1",
    "lbkpiece": "LBKPIECE1", "lbkpiece1": "LBKPIECE1", "aorrtc": "AORRTC",
}
OBJECTIVES = ("none", "length", "singularity")


def planner_class(name: str):
    """The OMPL geometric planner class for a name such as ``RRTConnect``, ``rrt*``, ``PRM*``, ``BIT*``."""
    key = name.lower().replace("*", "star").replace("-", "").replace("_", "")
    if key not in PLANNERS or not hasattr(og, PLANNERS[key]):
        allowed = sorted({v for k, v in PLANNERS.items() if hasattr(og, v)})
        raise PlanningError(f"planner {name!r} unknown; allowed: {', '.join(allowed)} (also RRT*, PRM*, BIT*)")
    return getattr(og, PLANNERS[key])


@dataclass
class PlanResult:
    """Outcome of :func:`plan` (SI units)."""

    success: bool
    path: np.ndarray            # (M, n), empty when no path
    planner: str
    time_s: float
    length: float               # Σ ‖Δq‖ along the path (joint-space length)
    min_sigma: float
    check: PathCheck | None
    status: str
    straight_line_valid: bool
    goal: np.ndarray | None = None
    attempts: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"success": self.success, "path": self.path.tolist(), "planner": self.planner,
                "time_s": self.time_s, "length": self.length,
                "min_sigma": None if not math.isfinite(self.min_sigma) else self.min_sigma,
                "status": self.status, "straight_line_valid": self.straight_line_valid,
                "check": None if self.check is None else self.check.to_dict(), "attempts": self.attempts}


def path_length(path: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()) if len(path) > 1 else 0.0


class _MotionValidator(ob.MotionValidator):
    """Checks a whole motion in one call (see :meth:`JointSpaceChecker.motion_valid`)."""

    def __init__(self, si, checker: JointSpaceChecker):
        super().__init__(si)
        self.checker = checker
        self.n = checker.n

    def checkMotion(self, s1, s2):  # noqa: N802 - OMPL's name
        n = self.n
        a = [s1[i] for i in range(n)]
        b = [s2[i] for i in range(n)]
        return self.checker.motion_valid(a, b)


class _SingularityCost(ob.StateCostIntegralObjective):
    """State cost 1/σ_min (large near singularities), integrated along the path."""

    def __init__(self, si, checker: JointSpaceChecker, scale: float):
        super().__init__(si, True)
        self.checker = checker
        self.scale = scale

    def stateCost(self, s):  # noqa: N802 - OMPL's name
        q = [s[i] for i in range(self.checker.n)]
        return ob.Cost(self.scale / max(self.checker.sigma(q), 1e-9))


def _goal_from_pose(robot, pose: np.ndarray, start: np.ndarray, checker: JointSpaceChecker,
                    seed: int) -> np.ndarray:
    """IK solutions of a tool pose; the valid one nearest the start."""
    cands = []
    for k in range(8):
        res = robot.ik(pose, seed=seed + k, q0=start if k == 0 else None)
        if res.success and checker.state_valid(res.q):
            cands.append(res.q)
    if not cands:
        raise PlanningError("goal pose: no valid IK solution (inside the limits, outside every window"
                            + (", above the σ_min floor" if checker.sigma_floor else "") + ")")
    cands = np.array(cands)
    return cands[np.argmin(np.linalg.norm(cands - start, axis=1))]


def plan(robot, start, goal=None, windows=None, *, goal_pose=None, planner: str = "RRTConnect",
         time_limit: float = 2.0, seed: int = 0, sigma_min: float | None = None,
         boxes: Sequence[KeepOutBox] = (), objective: str = "none", simplify: bool = True,
         check_step_angle: float = DEFAULT_STEP_ANGLE, check_step_length: float = DEFAULT_STEP_LENGTH,
         motion_step: float | None = None) -> PlanResult:
    """Plan a joint path from ``start`` to ``goal`` (configurations, SI) — or to ``goal_pose`` (4×4) —
    that stays inside the limits, outside every window of ``windows`` (a WindowSet), above the
    σ_min floor and out of the keep-out boxes.

    ``planner``: any OMPL geometric planner by name (RRTConnect default, RRT*, PRM*, BIT*, …);
    ``time_limit``: seconds for the planner; ``seed``: OMPL's RNG seed (same seed, same plan);
    ``objective``: ``"none"``, ``"length"`` or ``"singularity"`` (length + ∫ 1/σ_min; used by the
    optimising planners); ``motion_step``: joint step of the motion validator (default: a fifth
    of the narrowest window width, at most 1°).
    """
    t0 = time.perf_counter()
    if objective not in OBJECTIVES:
        raise PlanningError(f"objective {objective!r} unknown; allowed: {', '.join(OBJECTIVES)}")
    if not (time_limit > 0 and math.isfinite(time_limit)):
        raise PlanningError(f"time limit {time_limit} must be a positive number of seconds")
    cls = planner_class(planner)
    chain = robot.chain
    start_q, _ = chain.as_batch(start, "start")
    start_q = start_q[0]
    checker = JointSpaceChecker(robot, windows, sigma_min, boxes, motion_step)
    checker.require_valid(start_q, "start")
    if (goal is None) == (goal_pose is None):
        raise PlanningError("give exactly one of goal (a configuration) or goal_pose (a 4×4 tool pose)")
    if goal_pose is not None:
        pose = np.asarray(goal_pose, dtype=float)
        if pose.shape != (4, 4) or not np.isfinite(pose).all():
            raise ConfigurationError(f"goal pose has shape {pose.shape}; expected a finite 4×4 transform")
        goal_q = _goal_from_pose(robot, pose, start_q, checker, seed)
    else:
        goal_q, _ = chain.as_batch(goal, "goal")
        goal_q = goal_q[0]
    checker.require_valid(goal_q, "goal")

    straight = np.array([start_q, goal_q])
    # the cheap motion check first: the dense check (σ_min at every 0.1°) only when it passes
    straight_ok = checker.motion_valid(start_q, goal_q) \
        and check_path(robot, straight, windows, sigma_min, check_step_angle, check_step_length).valid
    attempts: list[str] = []
    step = checker.motion_step
    for attempt in range(3):
        path, raw, status = _solve(robot, cls, checker, start_q, goal_q, time_limit, seed, objective, simplify)
        if path is None:
            attempts.append(f"{status}")
            break
        for cand in ([path, raw] if simplify else [raw]):
            chk = check_path(robot, cand, windows, sigma_min, check_step_angle, check_step_length)
            box_row = _box_violation(robot, checker, cand, check_step_angle, check_step_length) \
                if chk.valid and checker.boxes else None
            if chk.valid and box_row is None:
                attempts.append(f"{status}; dense check passed")
                return PlanResult(True, cand, cls.__name__, time.perf_counter() - t0, path_length(cand),
                                  chk.min_sigma, chk, status, straight_ok, goal_q, attempts)
            if not chk.valid:
                attempts.append(f"{status}; dense check failed: {chk.first_violation.kind} at row "
                                f"{chk.first_violation.index}")
            else:
                attempts.append(f"{status}; dense check failed: keep-out box at row {box_row}")
        step /= 4.0          # repair: a finer motion validator, then plan again
        checker.motion_step = step
    return PlanResult(False, np.zeros((0, chain.n)), cls.__name__, time.perf_counter() - t0, math.nan, math.nan,
                      None, attempts[-1] if attempts else "failed", straight_ok, goal_q, attempts)


def _box_violation(robot, checker: JointSpaceChecker, path: np.ndarray, step_angle: float,
                   step_length: float) -> int | None:
    """Row of the first segment whose densely interpolated states put a checked point in a keep-out
    box (None when none does): :func:`check_path` knows nothing of boxes."""
    Q, seg, _ = densify(path, robot.chain.revolute_mask, step_angle, step_length)
    hit = checker._in_box(Q)
    return int(seg[int(np.argmax(hit))]) if hit.any() else None


def _solve(robot, cls, checker: JointSpaceChecker, start_q, goal_q, time_limit, seed, objective, simplify):
    """One OMPL run → (simplified path (M, n) or None, unsimplified path or None, status text)."""
    n = robot.n
    quiet_rng_seed(seed)
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    for i in range(n):
        bounds.setLow(i, float(robot.chain.lower[i]))
        bounds.setHigh(i, float(robot.chain.upper[i]))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda s: checker.state_valid([s[i] for i in range(n)]))
    mv = _MotionValidator(si, checker)
    si.setMotionValidator(mv)
    si.setup()
    s0, s1 = space.allocState(), space.allocState()
    for i in range(n):
        s0[i] = float(start_q[i])
        s1[i] = float(goal_q[i])
    pdef = ob.ProblemDefinition(si)
    pdef.setStartAndGoalStates(s0, s1)
    keep = [space, si, mv, pdef, s0, s1]
    if objective != "none":
        length = ob.PathLengthOptimizationObjective(si)
        if objective == "singularity":
            multi = ob.MultiOptimizationObjective(si)
            sing = _SingularityCost(si, checker, scale=0.01)
            multi.addObjective(length, 1.0)
            multi.addObjective(sing, 1.0)
            keep += [length, sing]
            pdef.setOptimizationObjective(multi)
            keep.append(multi)
        else:
            pdef.setOptimizationObjective(length)
            keep.append(length)
    pl = cls(si)
    pl.setProblemDefinition(pdef)
    pl.setup()
    status = pl.solve(float(time_limit))
    text = str(status)
    if not bool(status) or not pdef.hasExactSolution():
        return None, None, f"no exact solution ({text})"
    path = pdef.getSolutionPath()
    raw = np.array([[path.getState(k)[i] for i in range(n)] for k in range(path.getStateCount())])
    out = raw
    if simplify:
        og.PathSimplifier(si).simplifyMax(path)
        out = np.array([[path.getState(k)[i] for i in range(n)] for k in range(path.getStateCount())])
    del keep
    return out, raw, text
