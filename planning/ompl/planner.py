"""Joint-space planning with OMPL around singular windows.

The roles are OMPL's: a :class:`ompl.base.RealVectorStateSpace` bounded by the joint limits, a
state validity checker (limits, outside every window, an optional σ_min floor, optional keep-out
boxes, clear of a work cell and of the robot itself — :class:`planning.collision.CollisionWorld`,
one call of the compiled clearance kernel), a motion validator that checks a whole motion as one
batch at a step finer than the narrowest window (so no window can be jumped) and proves it clear of
the cell (:mod:`planning.certify.collision`), a problem definition with an optional objective
(path length, or path length plus a singularity cost ∫ 1/σ_min), and a planner chosen by name.

Before planning, :class:`planning.certify.FreeCells` decides whether start and goal lie in different
free cells (a slab window such as the wrist window q5 ∈ [−m, m] between them, or proven-blocked
cells of a 2- or 3-joint group): such a query is answered at once, "no joint path exists", with the
reason.  A goal given as a tool pose is chosen among its IK branches (and, for a spherical wrist, the
flipped wrist q4 ± π, −q5, q6 ± π) that are valid and in the start's free cell, nearest first.

Every returned path is re-checked by :func:`planning.validate.check_path`, independently of the
planner (and, with keep-out boxes, its densely interpolated tool points against the boxes), and
proven clear of every window segment by segment (:func:`planning.certify.certify_path`); a path that
fails is repaired (the unsimplified path, then re-planning with a finer motion step) or reported as
a failure — :func:`plan` never returns an invalid path as a success.  With the native motion checker
(a C compiler: almost always) that re-check is by the proofs alone (``check_path(..., dense=False)``:
windows, σ_min floor and collisions proven segment by segment, the dense states evaluated only where
a proof stays open), so the figures of :attr:`PlanResult.check` and :attr:`PlanResult.min_sigma` are
then those at the waypoints; ``check_path(robot, res.path, ...)`` gives the dense ones (what
``rmt plan`` prints).
"""
from __future__ import annotations

import gc
import math
import time
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from kin.errors import ConfigurationError
from planning.certify import PathProof, Separation, free_cells
from planning.certify.signs import Separator, sign_separation
from planning.errors import PlanningError
from planning.ompl.bindings import ob, og, quiet_rng_seed
from planning.ompl.goals import GoalPoseError, goal_from_pose
from planning.ompl.validity import JointSpaceChecker, KeepOutBox
from planning.validate import (
    DEFAULT_STEP_ANGLE,
    DEFAULT_STEP_LENGTH,
    PathCheck,
    check_path,
    densify,
)

PLANNERS = {
    "rrtconnect": "RRTConnect", "rrt": "RRT", "rrtstar": "RRTstar", "informedrrtstar": "InformedRRTstar",
    "sorrtstar": "SORRTstar", "prm": "PRM", "prmstar": "PRMstar", "bitstar": "BITstar", "fmt": "FMT",
    "bfmt": "BFMT", "kpiece": "KPIECE1", "kpiece1": "KPIECE1", "bkpiece": "BKPIECE1", "bkpiece1": "BKPIECE1",
    "lbkpiece": "LBKPIECE1", "lbkpiece1": "LBKPIECE1", "aorrtc": "AORRTC",
}
OBJECTIVES = ("none", "length", "singularity")
#: planners whose solve() searches the roadmap in a second C++ thread: a Python objective there
#: waits for the GIL that the planning thread holds, and solve() never returns (OMPL's PRM family)
THREADED_SEARCH = ("PRM", "PRMstar")
#: weight of the singularity state cost 1/σ_min beside the path length
SINGULARITY_SCALE = 0.01
#: the most sub-states at which the roadmap search evaluates σ_min (about 0.05 s unloaded)
MAX_COST_STATES = 50_000
#: tree planners restarted from a new seed when a run checks more motions than its budget (the first
#: run's, doubled for each next one), and the seed step between runs
RESTARTABLE = ("RRTConnect", "RRT", "BiTRRT", "TRRT", "LazyRRT", "KPIECE1", "BKPIECE1", "LBKPIECE1", "EST", "BiEST",
               "SBL", "STRIDE", "PDST")
RESTART_CHECKS = 4000
RESTART_SEED_STEP = 7919
#: default_range: how far (in chain lengths) one edge may move a point of the robot (1.5: the shortest
#: median and p95 planning times on MotionBenchMaker's Panda problems of 1.5, 2 and 3)
RANGE_REACH = 1.5
_RANGES: dict = {}          # default_range per robot (chain, geometry, value), by identity


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
    min_sigma: float            # at the states the final check evaluated (the waypoints with the native checker)
    check: PathCheck | None     # the final check (by proofs alone with the native checker: see the module)
    status: str
    straight_line_valid: bool
    goal: np.ndarray | None = None
    attempts: list[str] = field(default_factory=list)
    proof: PathProof | None = None           # windows proven clear segment by segment (None: no path)
    separation: Separation | None = None     # why no joint path exists (decided before planning)
    goal_branch: dict | None = None          # for a pose goal: the branch chosen among the candidates, or why none

    @property
    def proven(self) -> bool:
        """True when the returned path is proven clear of every window — and, in a work cell, of every
        collision, and with a σ_min floor above it — not only sampled."""
        return (self.success and self.proof is not None and self.proof.proven
                and (self.check is None or (self.check.collision_check in (None, "proven")
                                            and self.check.sigma_check in (None, "proven"))))

    @property
    def min_clearance(self) -> float | None:
        """The smallest clearance along the returned path (m; None without a work cell)."""
        return None if self.check is None else self.check.min_clearance

    def to_dict(self) -> dict:
        return {"success": self.success, "path": self.path.tolist(), "planner": self.planner,
                "time_s": self.time_s, "length": self.length,
                "min_sigma": None if not math.isfinite(self.min_sigma) else self.min_sigma,
                "status": self.status, "straight_line_valid": self.straight_line_valid,
                "check": None if self.check is None else self.check.to_dict(), "attempts": self.attempts,
                "proven": self.proven, "min_clearance": self.min_clearance,
                "proof": None if self.proof is None else
                {"methods": self.proof.methods, "unproven_segments": len(self.proof.unproven),
                 "collisions": None if self.check is None else self.check.collision_check},
                "separation": None if self.separation is None else
                {"joints": list(self.separation.joints), "windows": list(self.separation.windows),
                 "kind": self.separation.kind, "reason": self.separation.reason},
                "goal_branch": self.goal_branch}


def path_length(path: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()) if len(path) > 1 else 0.0


class _MotionValidator(ob.MotionValidator):
    """Checks a whole motion in one call (see :meth:`JointSpaceChecker.motion_valid`)."""

    def __init__(self, si, checker: JointSpaceChecker):
        super().__init__(si)
        self.checker = checker
        self.n = checker.n

    def checkMotion(self, s1, s2):  # OMPL's name
        n = self.n
        a = [s1[i] for i in range(n)]
        b = [s2[i] for i in range(n)]
        return self.checker.motion_valid(a, b)


def _edge_costs(robot, A: np.ndarray, B: np.ndarray, step: float, scale: float) -> np.ndarray:
    """Length + ∫ scale/σ_min ds of every straight motion A[k] → B[k] (K, n) → (K,); the sub-state
    spacing is ``step``, widened when the motions would need more than :data:`MAX_COST_STATES`."""
    length = np.linalg.norm(B - A, axis=1)
    step = max(step, float(length.sum()) / MAX_COST_STATES)    # a bounded number of σ_min evaluations
    k = np.maximum(np.ceil(length / step), 1).astype(int)
    seg = np.repeat(np.arange(len(A)), k + 1)
    first = np.concatenate([[0], np.cumsum(k + 1)[:-1]])
    t = (np.arange(len(seg)) - first[seg]) / k[seg]
    Q = A[seg] + t[:, None] * (B[seg] - A[seg])
    c = scale / np.maximum(robot.sigma_min(Q), 1e-9) if len(Q) else np.zeros(0)
    # trapezoid per edge: Σ over its k sub-segments of (c_i + c_{i+1}) / 2 · length / k
    mid = 0.5 * (c[:-1] + c[1:]) if len(c) else np.zeros(0)
    inner = np.ones(len(mid), bool)
    inner[first[1:] - 1] = False                       # pairs that straddle two edges
    sums = np.bincount(seg[:-1][inner], weights=mid[inner], minlength=len(A)) if len(A) else np.zeros(0)
    return length + sums * length / k


def _roadmap_search(robot, pdef, planner, n: int, step: float) -> np.ndarray | None:
    """The path of least ``singularity`` cost through a PRM roadmap (start and goal included), or
    None when they are not connected.  Edges of a PRM roadmap are valid motions (checked when added)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    pd = ob.PlannerData(planner.getSpaceInformation())
    planner.getPlannerData(pd)
    nv = pd.numVertices()
    if nv == 0 or pd.numStartVertices() == 0 or pd.numGoalVertices() == 0:
        return None
    X = np.array([[pd.getVertex(i).getState()[j] for j in range(n)] for i in range(nv)])
    edges = np.array([(i, j) for i in range(nv) for j in pd.getEdges(i) if i < j], dtype=int).reshape(-1, 2)
    if len(edges) == 0:
        return None
    w = _edge_costs(robot, X[edges[:, 0]], X[edges[:, 1]], step, SINGULARITY_SCALE)
    G = coo_matrix((w, (edges[:, 0], edges[:, 1])), shape=(nv, nv)).tocsr()
    start, goal = pd.getStartIndex(0), pd.getGoalIndex(0)
    dist, pred = dijkstra(G, directed=False, indices=start, return_predecessors=True)
    if not np.isfinite(dist[goal]):
        return None
    order = [goal]
    while order[-1] != start:
        order.append(int(pred[order[-1]]))
    return X[order[::-1]]


class _SingularityCost(ob.StateCostIntegralObjective):
    """State cost 1/σ_min (large near singularities), integrated along the path."""

    def __init__(self, si, checker: JointSpaceChecker, scale: float):
        super().__init__(si, True)
        self.checker = checker
        self.scale = scale

    def stateCost(self, s):  # OMPL's name
        q = [s[i] for i in range(self.checker.n)]
        return ob.Cost(self.scale / max(self.checker.sigma(q), 1e-9))


def plan(robot, start, goal=None, windows=None, *, goal_pose=None, planner: str = "RRTConnect",
         time_limit: float = 2.0, seed: int = 0, sigma_min: float | None = None,
         boxes: Sequence[KeepOutBox] = (), objective: str = "none", simplify: bool = True,
         check_step_angle: float = DEFAULT_STEP_ANGLE, check_step_length: float = DEFAULT_STEP_LENGTH,
         motion_step: float | None = None, world=None, planner_range: float | None = None,
         goal_frame: str = "base") -> PlanResult:
    """Plan a joint path from ``start`` to ``goal`` (configurations, SI) — or to ``goal_pose`` (4×4) —
    that stays inside the limits, outside every window of ``windows`` (a WindowSet), above the
    σ_min floor and out of the keep-out boxes.

    ``planner``: any OMPL geometric planner by name (RRTConnect default, RRT*, PRM*, BIT*, …);
    ``time_limit``: seconds for the planner; ``seed``: OMPL's RNG seed (same seed, same plan);
    ``objective``: ``"none"``, ``"length"`` or ``"singularity"`` (length + ∫ 1/σ_min; used by the
    optimising planners); ``motion_step``: joint step of the motion validator (default: a fifth
    of the narrowest window width, at most 1°); ``world``: a
    :class:`planning.collision.CollisionWorld` (the robot in its work cell) whose obstacles and
    self-collisions the path must be proven clear of — every motion the planner keeps is proven
    (:func:`planning.certify.collision.certify_collision`) and the returned path is proven again;
    ``planner_range``: the longest edge of a tree planner (joint-space distance; default
    :func:`default_range`, from the robot's geometry); ``goal_frame``: the frame of ``goal_pose``,
    ``"base"`` (the robot's base frame) or ``"cell"`` (the frame of ``world``'s cell, where it places
    the robot).  The goal of a pose is chosen by :func:`planning.ompl.goals.goal_from_pose` (every IK
    branch and its whole-turn copies; the valid one in the start's free cell nearest the start), or
    :class:`planning.ompl.goals.GoalPoseError` says why none is valid.
    """
    t0 = time.perf_counter()
    if objective not in OBJECTIVES:
        raise PlanningError(f"objective {objective!r} unknown; allowed: {', '.join(OBJECTIVES)}")
    if not (time_limit > 0 and math.isfinite(time_limit)):
        raise PlanningError(f"time limit {time_limit} must be a positive number of seconds")
    if planner_range is not None and not (isinstance(planner_range, (int, float)) and math.isfinite(planner_range)
                                          and planner_range > 0):
        raise PlanningError(f"planner range {planner_range!r} must be a positive joint-space distance")
    cls = planner_class(planner)
    chain = robot.chain
    start_q, _ = chain.as_batch(start, "start")
    start_q = start_q[0]
    checker = JointSpaceChecker(robot, windows, sigma_min, boxes, motion_step, world)
    checker.require_valid(start_q, "start")
    # the windows' free cells and, under a σ_min floor, the signs of the exact singular factors
    cells = Separator(free_cells(chain.lower, chain.upper, windows), robot, sigma_min)
    goal_branch = None
    if (goal is None) == (goal_pose is None):
        raise PlanningError("give exactly one of goal (a configuration) or goal_pose (a 4×4 tool pose)")
    if goal_pose is not None:
        pose = np.asarray(goal_pose, dtype=float)
        if pose.shape != (4, 4) or not np.isfinite(pose).all():
            raise ConfigurationError(f"goal pose has shape {pose.shape}; expected a finite 4×4 transform")
        if goal_frame not in ("base", "cell"):
            raise PlanningError(f"goal frame {goal_frame!r} unknown; allowed: base, cell")
        frame = "base frame"
        if goal_frame == "cell":
            if world is None:
                raise PlanningError("a goal pose in the cell frame needs a world (the cell that places the robot)")
            pose = np.linalg.inv(world.base) @ pose
            frame = f"cell frame{f' of {world.name!r}' if world.name else ''}"
        try:
            goal_q, goal_branch = goal_from_pose(robot, pose, start_q, checker, cells, seed, frame=frame)
        except GoalPoseError as e:           # no valid configuration reaches the pose: a negative answer
            return PlanResult(False, np.zeros((0, chain.n)), cls.__name__, time.perf_counter() - t0, math.nan,
                              math.nan, None, str(e), False, None, [str(e)], goal_branch=e.info)
    else:
        goal_q, _ = chain.as_batch(goal, "goal")
        goal_q = goal_q[0]
    checker.require_valid(goal_q, "goal")

    def separated(sep: Separation) -> PlanResult:
        status = f"no joint path exists: {sep.reason}"
        if goal_branch is not None and goal_branch.get("start_cell_reason"):
            status += f" (the goal pose's valid configurations all lie across it; {goal_branch['start_cell_reason']})"
        return PlanResult(False, np.zeros((0, chain.n)), cls.__name__, time.perf_counter() - t0, math.nan, math.nan,
                          None, status, False, goal_q, [status], separation=sep, goal_branch=goal_branch)
    sep = cells.cells.separation(start_q, goal_q, chain=chain)
    if sep is not None:
        return separated(sep)

    straight = np.array([start_q, goal_q])
    # with the native checker every motion the planner keeps is proven and the returned path is checked
    # by the proofs alone (dense=False: the dense states are evaluated only where a proof stays open)
    dense = checker.native is None
    # the cheap motion check first: the dense check (σ_min at every 0.1°) only when it passes
    straight_ok = checker.motion_valid(start_q, goal_q) \
        and check_path(robot, straight, windows, sigma_min, check_step_angle, check_step_length, world=world,
                       dense=dense).valid
    # before searching: a singular factor whose sign differs at the two ends proves no path exists under
    # the floor — when the factors are at hand (a goal pose looked them up); else only if the search fails
    # (the analysis costs about a second in a fresh process, more than most searches)
    sep = None if straight_ok or not cells.factors_ready else sign_separation(cells.factors, start_q, goal_q)
    if sep is not None:
        return separated(sep)
    attempts: list[str] = []
    step = checker.motion_step
    for attempt in range(3):
        if straight_ok and objective == "none" and attempt == 0:
            path = raw = straight
            status = "Exact solution (the straight line)"
        else:
            path, raw, status = _solve(robot, cls, checker, start_q, goal_q, time_limit, seed, objective, simplify,
                                       planner_range)
        if path is None:
            sep = sign_separation(cells.factors, start_q, goal_q)
            if sep is not None:                  # the search failed because no path exists: say why
                return separated(sep)
            attempts.append(f"{status}")
            break
        for cand in ([path, raw] if simplify else [raw]):
            chk = check_path(robot, cand, windows, sigma_min, check_step_angle, check_step_length, world=world,
                             dense=dense)
            box_row = _box_violation(robot, checker, cand, check_step_angle, check_step_length) \
                if chk.valid and checker.boxes else None
            if chk.valid and box_row is None:       # check_path proved the windows (chk.proof)
                proof = chk.proof
                attempts.append(f"{status}; dense check passed; windows "
                                + ("proven clear" if proof.proven else f"sampled on {len(proof.unproven)} segment(s)")
                                + ("" if world is None else f"; collisions {chk.collision_check}"))
                return PlanResult(True, cand, cls.__name__, time.perf_counter() - t0, path_length(cand),
                                  chk.min_sigma, chk, status, straight_ok, goal_q, attempts, proof=proof,
                                  goal_branch=goal_branch)
            if not chk.valid:
                attempts.append(f"{status}; dense check failed: {chk.first_violation.kind} at row "
                                f"{chk.first_violation.index}")
            else:
                attempts.append(f"{status}; dense check failed: keep-out box at row {box_row}")
        step /= 4.0          # repair: a finer motion validator, then plan again
        checker.motion_step = step
    return PlanResult(False, np.zeros((0, chain.n)), cls.__name__, time.perf_counter() - t0, math.nan, math.nan,
                      None, attempts[-1] if attempts else "failed", straight_ok, goal_q, attempts,
                      goal_branch=goal_branch)


def _box_violation(robot, checker: JointSpaceChecker, path: np.ndarray, step_angle: float,
                   step_length: float) -> int | None:
    """Row of the first segment whose densely interpolated states put a checked point in a keep-out
    box (None when none does): :func:`check_path` knows nothing of boxes."""
    Q, seg, _ = densify(path, robot.chain.revolute_mask, step_angle, step_length)
    hit = checker._in_box(Q)
    return int(seg[int(np.argmax(hit))]) if hit.any() else None


def joint_space(robot):
    """OMPL's state space of the joints (a RealVectorStateSpace bounded by the limits) and its
    SpaceInformation, not yet set up."""
    n = robot.n
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    for i in range(n):
        bounds.setLow(i, float(robot.chain.lower[i]))
        bounds.setHigh(i, float(robot.chain.upper[i]))
    space.setBounds(bounds)
    return space, ob.SpaceInformation(space)


def start_goal(space, si, start_q, goal_q):
    """A ProblemDefinition from ``start_q`` to ``goal_q`` and its two states (keep them alive)."""
    s0, s1 = space.allocState(), space.allocState()
    for i in range(len(start_q)):
        s0[i] = float(start_q[i])
        s1[i] = float(goal_q[i])
    pdef = ob.ProblemDefinition(si)
    pdef.setStartAndGoalStates(s0, s1)
    return pdef, (s0, s1)


def default_range(robot) -> float:
    """The longest edge of the tree planners (OMPL's ``range``, joint-space distance) from the robot's
    geometry: along an edge of this length no point of the robot moves, by the first-order bound of
    :func:`kin.geometry.motion.capsule_radii`, more than :data:`RANGE_REACH` times the chain's length
    (:func:`kin.geometry.chain_length`).  OMPL's own default, a fifth of the joint space's diagonal, makes
    edges of several radians that mostly end in collision; this gives 0.83 for the Panda and 1.1 for the UR5
    of MotionBenchMaker (VAMP tuned 1.0 and 1.5 by hand for its own, cheaper, sampled checks)."""
    key = (id(robot.chain), id(robot.geometry))
    hit = _RANGES.get(key)
    if hit is not None and hit[0] is robot.chain and hit[1] is robot.geometry:
        return hit[2]
    from kin.geometry import chain_length
    from kin.geometry.motion import capsule_radii
    R = capsule_radii(robot.chain, robot.geometry)
    worst = float(np.linalg.norm(R, axis=1).max()) if len(R) else 0.0
    length = chain_length(robot.chain)
    value = RANGE_REACH * length / worst if worst > 0 and length > 0 else 1.0
    if len(_RANGES) > 64:
        _RANGES.clear()
    _RANGES[key] = (robot.chain, robot.geometry, value)
    return value


def _solve(robot, cls, checker: JointSpaceChecker, start_q, goal_q, time_limit, seed, objective, simplify,
           planner_range=None):
    """One OMPL run → (simplified path (M, n) or None, unsimplified path or None, status text)."""
    n = robot.n
    quiet_rng_seed(seed)
    space, si = joint_space(robot)
    mv = _MotionValidator(si, checker)
    if checker.native is not None and not checker.extras and not checker.hulls:
        # every question is answered in C: OMPL calls the native checker directly, no Python in between
        si.setStateValidityChecker(checker.native.ompl_state())
        mv.checkMotion = checker.native.ompl_motion()
    else:
        si.setStateValidityChecker(lambda s: checker.state_valid([s[i] for i in range(n)]))
    si.setMotionValidator(mv)
    si.setup()
    pdef, (s0, s1) = start_goal(space, si, start_q, goal_q)
    keep = [space, si, mv, pdef, s0, s1]
    # OMPL's PRM family searches its roadmap in a second thread; a Python objective there deadlocks
    # (it waits for the GIL this thread holds while joining it).  Those planners grow their roadmap
    # under the (C++) length objective; the singularity objective then picks the path on the roadmap.
    roadmap_objective = objective == "singularity" and cls.__name__ in THREADED_SEARCH
    if roadmap_objective:
        length = ob.PathLengthOptimizationObjective(si)
        pdef.setOptimizationObjective(length)
        keep.append(length)
    elif objective != "none":
        length = ob.PathLengthOptimizationObjective(si)
        if objective == "singularity":
            multi = ob.MultiOptimizationObjective(si)
            sing = _SingularityCost(si, checker, scale=SINGULARITY_SCALE)
            multi.addObjective(length, 1.0)
            multi.addObjective(sing, 1.0)
            keep += [length, sing]
            pdef.setOptimizationObjective(multi)
            keep.append(multi)
        else:
            pdef.setOptimizationObjective(length)
            keep.append(length)
    # Tree planners' run times are heavy-tailed (a few seeds wander for long in a narrow passage): with
    # the native checker, a run that checks more motions than its budget is restarted from a new seed
    # with twice the budget, until the time limit.  Budgets count motions, not seconds, so the same seed
    # gives the same path on any machine.
    restart = (objective == "none" and cls.__name__ in RESTARTABLE and checker.native is not None
               and not checker.extras)
    # the roadmap search is part of the budget: the roadmap grows for 70 % of it
    solve_time = float(time_limit) * (0.7 if roadmap_objective else 1.0)
    deadline = time.perf_counter() + solve_time
    budget, attempt = RESTART_CHECKS, 0
    while True:
        if attempt:
            quiet_rng_seed(seed + RESTART_SEED_STEP * attempt)
            pdef, (s0, s1) = start_goal(space, si, start_q, goal_q)
            keep += [pdef, s0, s1]
        pl = cls(si)
        if hasattr(pl, "setRange"):
            pl.setRange(default_range(robot) if planner_range is None else float(planner_range))
        pl.setProblemDefinition(pdef)
        pl.setup()
        keep.append(pl)
        if not restart:
            status = pl.solve(solve_time)
            break
        # with hulls OMPL calls the Python checker (which asks the native one first): it counts the motions
        calls = checker.native.motion_calls() if not checker.hulls else (lambda: checker.motions)
        first, limit = calls(), budget
        # each callback wraps OMPL's states in new Python objects: the cyclic collector would walk the heap
        # again and again (a few % of a long run); nothing cyclic is made meanwhile
        collecting = gc.isenabled()
        gc.disable()
        try:
            status = pl.solve(ob.PlannerTerminationCondition(
                lambda: calls() - first > limit or time.perf_counter() >= deadline))
        finally:
            if collecting:
                gc.enable()
        if (bool(status) and pdef.hasExactSolution()) or time.perf_counter() >= deadline:
            break
        attempt, budget = attempt + 1, 2 * budget
    text = str(status)
    runs = f" ({attempt + 1} runs: a run restarts from a new seed after {RESTART_CHECKS}·2^k motion checks)" \
        if attempt else ""
    if not bool(status) or not pdef.hasExactSolution():
        why = {"Approximate solution": f"only an approximate one within {float(time_limit):g} s",
               "Timeout": f"time limit {float(time_limit):g} s reached"}.get(text, f"OMPL: {text}")
        return None, None, f"no exact solution: {why}{runs}"
    text += runs
    path = pdef.getSolutionPath()
    raw = np.array([[path.getState(k)[i] for i in range(n)] for k in range(path.getStateCount())])
    if roadmap_objective:
        best = _roadmap_search(robot, pdef, pl, n, space.getLongestValidSegmentLength())
        if best is not None:
            raw = best
            text += "; singularity objective minimised on the roadmap"
            path = og.PathGeometric(si)
            for row in raw:
                st = space.allocState()
                for i in range(n):
                    st[i] = float(row[i])
                path.append(st)
                keep.append(st)
    out = raw
    if simplify and checker.native is not None and not checker.extras:
        out, _ = checker.native.shortcut(raw, seed=seed)          # in C, every new motion proven
    elif simplify:
        og.PathSimplifier(si).simplifyMax(path)
        out = np.array([[path.getState(k)[i] for i in range(n)] for k in range(path.getStateCount())])
    del keep
    return out, raw, text
