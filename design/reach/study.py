"""The reach study: which targets of a task a robot, placed in a work cell, reaches — and how well,
and why not.

For every target (cell frame) the robot, standing at ``placement`` (its base placement in the cell;
default the cell's ``[robot]`` placement, or the identity without a cell), gets inverse-kinematics
runs from a fixed set of starts: the ``starts`` configurations nearest to the target among a Halton
sequence of ``samples`` configurations (scipy.stats.qmc, unscrambled), so **no seed enters a
verdict**: the same inputs give the same verdicts on every run and machine.  A target's
orientation requirement is met by pose IK at ``spins`` rotations about the tool axis ("axis": the
tool axis along the target's, free about itself — welding, drilling), at those rotations about six
tilted axes too ("cone"), or as a pose ("pose").

An IK solution *counts* when it is inside the joint limits, within the target's tolerance, clear
of the cell and of the robot itself by ``clearance`` (with a cell), outside every singular window
(``windows``) and, with a dexterity requirement, at least that dexterous.  A target is *reached*
when a solution counts; its score (:mod:`design.reach.score`) is the best of those solutions'.
An unreached target gets the reason of the furthest stage any solution passed:

``out_of_reach``  no solution even with the joint limits lifted (revolute joints free over a full
                  turn, prismatic strokes tripled about their middle);
``joint_limits``  reached only with the limits lifted;
``collision``     reached within the limits, but every solution collides (``detail`` names the
                  pair of the least colliding one, ``obstacle`` the object);
``window``        reached clear, but only inside a singular window;
``dexterity``     reached clear and outside windows, but below the required dexterity.

``support`` counts the starts (of ``starts``) from which a counting solution was found: a target
reached from one start only is *fragile* — a different sample size or start count may flip it.
Everything SI (m, rad).
"""
from __future__ import annotations

import dataclasses
import math
import time
from typing import Callable

import numpy as np
from scipy.stats import qmc
from sklearn.neighbors import NearestNeighbors

import kin
from design.reach.result import REASONS, ReachStudy
from design.reach.score import ScoreWeights, limit_margin
from design.reach.settings import ReachSettings
from design.task.model import Dexterity, Targets, TaskError
from design.task.targets import axis_frames
from design.task.targets import orientation_variants as target_variants
from kin.ik import local_ik

__all__ = ["ReachSettings", "ReachStudy", "reach_study", "REASONS", "halton_configurations", "target_variants",
           "ReachProblem",
           "placement_matrix"]



# ---- helpers shared with the placement search ---------------------------------------------------------
def placement_matrix(placement) -> np.ndarray:
    """A placement as a 4×4: a :class:`kin.Placement`, a 4×4 array, or (x, y, z, roll, pitch, yaw) (m, rad)."""
    from kin.transforms import make_transform, rigidity_defect, rpy_to_matrix
    if isinstance(placement, kin.Placement):
        return placement.matrix
    A = np.asarray(placement, dtype=float) if not isinstance(placement, str) else np.array([])
    if A.shape == (6,) and np.all(np.isfinite(A)):
        return make_transform(rpy_to_matrix(A[3:]), A[:3])
    if A.shape == (4, 4) and np.all(np.isfinite(A)) and rigidity_defect(A) <= 1e-6:
        return A.copy()
    raise TaskError(f"placement must be x y z roll pitch yaw (m, rad) or a rigid 4×4 transform, got {placement!r}")


def halton_configurations(robot: kin.Robot, samples: int) -> np.ndarray:
    """``samples`` configurations (samples, n) of an unscrambled Halton sequence over the joint limits
    (its first point, the lower corner, skipped): fixed for a robot, no seed."""
    H = qmc.Halton(d=robot.n, scramble=False).random(samples + 1)[1:]
    return robot.chain.lower + H * (robot.chain.upper - robot.chain.lower)


def _lifted(robot: kin.Robot) -> kin.Robot:
    """The robot with its joint limits lifted: revolute joints over at least a full turn, prismatic
    strokes tripled about their middle (the "joint limits" reason)."""
    joints = []
    for j in robot.chain.joints:
        lo, hi = j.limits
        if j.is_revolute:
            lo, hi = min(lo, -math.pi), max(hi, math.pi)
        else:
            mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
            lo, hi = mid - 3 * half, mid + 3 * half
        joints.append(dataclasses.replace(j, limits=(lo, hi)))
    return kin.Robot(dataclasses.replace(robot.chain, joints=tuple(joints)))


def _dexterity(robot: kin.Robot, Q: np.ndarray, measure: str) -> np.ndarray:
    if measure == "manipulability":
        return np.asarray(robot.manipulability(Q), float)
    J = robot.jacobian(Q)
    return np.linalg.svd(J[:, :3, :], compute_uv=False)[:, -1]


class ReachProblem:
    """The parts of a reach study that do not depend on the placement: robot, targets, the start
    sample and its nearest-neighbour index, the collision world, the windows, the dexterity reference."""

    def __init__(self, robot, targets: Targets, cell, clearance: float, windows, weights: ScoreWeights,
                 settings: ReachSettings, dexterity: Dexterity | None):
        self.robot, self.targets, self.weights, self.settings = robot, targets, weights, settings
        self.windows = windows
        self.dex = dexterity if dexterity is not None and dexterity.kind != "none" else None
        if self.dex is not None and self.dex.kind not in ("sigma_min", "manipulability"):
            raise TaskError(f"the reach study checks dexterity 'sigma_min' or 'manipulability', not {self.dex.kind!r}")
        self.Qs = halton_configurations(robot, settings.samples)
        T = robot.fk(self.Qs)
        self.scale = max(float(np.ptp(targets.positions, axis=0).max()), 0.1)
        self.with_axes = targets.axes is not None
        feats = T[:, :3, 3] if not self.with_axes else np.hstack([T[:, :3, 3], self.scale * T[:, :3, 2]])
        self.nn = NearestNeighbors(n_neighbors=settings.starts, algorithm="kd_tree").fit(feats)
        self.V = target_variants(targets, settings.spins)
        self.nv = 1 if self.V is None else self.V.shape[1]
        ref = weights.dexterity_ref
        if ref is None:
            ref = float(np.max(_dexterity(robot, self.Qs, weights.measure)))
        self.dex_ref = ref if ref > 0 else 1.0
        self.world = None
        self.cell_name = ""
        if cell is not None:
            from planning.collision import collision_world
            self.world = collision_world(robot, cell, clearance)
            self.cell_name = cell.name
            self.default_base = np.array(cell.base)
        else:
            self.default_base = np.eye(4)
        self.clearance = clearance
        self._lifted = None
        #: time.perf_counter() past which a study stops early (after its first start; None: never) —
        #: a placement search's budget; what a study cut is said in its notes
        self.deadline: float | None = None
        self.cut: list[str] = []

    def _late(self) -> bool:
        return self.deadline is not None and time.perf_counter() > self.deadline

    def lifted(self):
        if self._lifted is None:
            self._lifted = _lifted(self.robot)
        return self._lifted

    def run(self, P: np.ndarray, explain: bool = False, hint: np.ndarray | None = None) -> dict:
        """The study at placement P (4×4): per-target arrays (see :func:`reach_study`)."""
        return _decide(self, P, *_evaluate(self, P, explain, hint), explain)

    def study(self, P: np.ndarray, hint: np.ndarray | None = None) -> ReachStudy:
        """The whole study at placement P (4×4), reasons explained (what :func:`reach_study` returns);
        a placement search verifies its answers here, with the problem it already built."""
        robot, t = self.robot, self.targets
        if hint is not None and np.shape(hint) != (len(t), robot.n):
            raise TaskError(f"hint must have shape ({len(t)}, {robot.n}), got {np.shape(hint)}")
        self.cut = []
        d = self.run(P, explain=True, hint=hint)
        notes = [] if self.world is not None else [
            "no work cell: collisions not checked; the score has no clearance term"]
        notes += [f"the time budget ran out: {c}" for c in self.cut]
        return ReachStudy(robot=robot.name, positions=t.positions.copy(), placement=np.array(P, float),
                          reached=d["reached"], score=d["score"], dexterity=d["dexterity"], clearance=d["clearance"],
                          limit_margin=d["limit_margin"], q=d["q"], reason=d["reason"], detail=d["detail"],
                          obstacle=d["obstacle"], support=d["support"], settings=self.settings, weights=self.weights,
                          dexterity_ref=self.dex_ref, cell=self.cell_name, orientation=t.orientation,
                          required_clearance=self.clearance,
                          windows=0 if self.windows is None else len(self.windows.windows), notes=notes)

    def goals(self, P: np.ndarray):
        """Targets seen from placement P (4×4): goals per row (N·V) and the starts (N, k, n)."""
        t = self.targets
        Ri, ti = P[:3, :3].T, -P[:3, :3].T @ P[:3, 3]
        pos = t.positions @ Ri.T + ti
        q = pos if not self.with_axes else np.hstack([pos, self.scale * (t.axes @ Ri.T)])
        starts = self.Qs[self.nn.kneighbors(q, return_distance=False)]
        rows_t = np.repeat(np.arange(len(t)), self.nv)
        if self.V is None:          # as 4×4 goals: an (N, 3) batch of N = 3 would read as one 3×3 pose
            G = np.tile(np.eye(4), (len(t), 1, 1))
            G[:, :3, 3] = pos
            return G, starts, "position"
        G = np.tile(np.eye(4), (len(rows_t), 1, 1))
        G[:, :3, :3] = np.einsum("ij,njk->nik", Ri, self.V.reshape(-1, 3, 3))
        G[:, :3, 3] = pos[rows_t]
        return G, starts, "pose"


def _judge(pb: ReachProblem, goal: np.ndarray, q0: np.ndarray, mode: str):
    """IK from q0 for each goal row, then each solution's stage (0 none, 1 in limits, 2 clear,
    3 outside windows, 4 dexterous enough), score (−1 unless stage 4), terms (dexterity, clearance,
    limit margin) and configuration."""
    robot, t, s = pb.robot, pb.targets, pb.settings
    R = len(goal)
    res = local_ik(robot, goal, q0, mode=mode, max_iter=s.max_iter, tol_position=t.tolerance)   # this start only
    ok = np.asarray(res.success, bool)
    Q = np.asarray(res.q).reshape(R, robot.n)
    stage = ok.astype(np.int8)
    score = np.full(R, -1.0)
    terms = np.full((R, 3), np.nan)
    if ok.any():
        Qk = Q[ok]
        clear = np.full(len(Qk), np.nan)
        good = np.ones(len(Qk), bool)
        if pb.world is not None:
            clear = np.asarray(pb.world.clearance(Qk), float)
            good = clear > pb.world.margin
        out_win = np.ones(len(Qk), bool) if pb.windows is None else ~np.asarray(pb.windows.contains(Qk), bool)
        dexv = _dexterity(robot, Qk, pb.weights.measure)
        dex_ok = np.ones(len(Qk), bool)
        if pb.dex is not None:
            dex_ok = _dexterity(robot, Qk, pb.dex.kind) >= pb.dex.value
        st = 1 + good.astype(np.int8) + (good & out_win).astype(np.int8) + (good & out_win & dex_ok).astype(np.int8)
        stage[ok] = st
        d_term = np.clip(dexv / pb.dex_ref, 0.0, 1.0)
        c_term = None if pb.world is None else np.clip(clear / pb.weights.clearance_ref, 0.0, 1.0)
        l_term = limit_margin(Qk, robot.chain.lower, robot.chain.upper)
        score[ok] = np.where(st == 4, pb.weights.combine(d_term, c_term, l_term), -1.0)
        terms[ok] = np.column_stack([dexv, clear, l_term])
    return stage, score, terms, Q


def _snapped(pb: ReachProblem, P: np.ndarray, q: np.ndarray, mode: str) -> np.ndarray:
    """Goals (robot frame) for configurations q (N, n) offered as solutions: each target's position,
    with the orientation the target requires nearest to q's own (about a free axis: q's rotation)."""
    t = pb.targets
    Ri, ti = P[:3, :3].T, -P[:3, :3].T @ P[:3, 3]
    pos = t.positions @ Ri.T + ti
    G = np.tile(np.eye(4), (len(t), 1, 1))
    G[:, :3, 3] = pos
    if mode == "position":
        return G
    if t.orientation == "pose":
        G[:, :3, :3] = np.einsum("ij,njk->nik", Ri, t.rotations)
        return G
    F = pb.robot.fk(q)[:, :3, :3]
    a = t.axes @ Ri.T
    if t.orientation == "cone":        # the tool axis as it is, if inside the cone, else pulled onto its rim
        z = F[:, :, 2]
        c = np.einsum("ij,ij->i", z, a)
        lim = np.cos(t.cone_half_angle)
        w = z - c[:, None] * a
        wn = np.linalg.norm(w, axis=1, keepdims=True)
        w = np.where(wn > 1e-12, w / np.where(wn > 0, wn, 1), F[:, :, 0])
        a = np.where((c >= lim)[:, None], z, lim * a + np.sqrt(1 - lim ** 2) * w)
    x = F[:, :, 0] - np.einsum("ij,ij->i", F[:, :, 0], a)[:, None] * a
    xn = np.linalg.norm(x, axis=1, keepdims=True)
    x = np.where(xn > 1e-9, x / np.where(xn > 0, xn, 1), axis_frames(a, 1)[:, 0, :, 0])
    G[:, :3, 0], G[:, :3, 1], G[:, :3, 2] = x, np.cross(a, x), a
    return G


def _evaluate(pb: ReachProblem, P: np.ndarray, explain: bool, hint: np.ndarray | None = None):
    """One placement: every (target, variant, start) judged; ``hint`` (N, n) adds one start per target
    (another solver's configuration, e.g. the placement NLP's), judged like the others."""
    robot, t, s = pb.robot, pb.targets, pb.settings
    N, nv, k, n = len(t), pb.nv, s.starts, robot.n
    goal, starts, mode = pb.goals(P)
    if pb.world is not None:
        pb.world.move_base(P)
    kk = k + (hint is not None)
    stage = np.zeros((N, nv, kk), np.int8)
    score = np.full((N, nv, kk), -1.0)
    terms = np.full((N, nv, kk, 3), np.nan)
    qs = np.zeros((N, nv, kk, n))
    rows_t = np.repeat(np.arange(N), nv)
    for j in range(k):
        if j and pb._late():
            pb.cut.append(f"IK from {j} of the {k} starts per target (unreached targets may be reachable)")
            break
        st, sc, te, Q = _judge(pb, goal, starts[rows_t, j], mode)
        stage[:, :, j], score[:, :, j] = st.reshape(N, nv), sc.reshape(N, nv)
        terms[:, :, j], qs[:, :, j] = te.reshape(N, nv, 3), Q.reshape(N, nv, n)
    if hint is not None:
        h = np.clip(np.asarray(hint, float), robot.chain.lower, robot.chain.upper)
        st, sc, te, Q = _judge(pb, _snapped(pb, P, h, mode), h, mode)
        stage[:, 0, k], score[:, 0, k], terms[:, 0, k], qs[:, 0, k] = st, sc, te, Q
        if nv > 1:
            qs[:, 1:, k] = Q[:, None]
    return stage, score, terms, qs


def _decide(pb: ReachProblem, P: np.ndarray, stage, score, terms, qs, explain: bool) -> dict:
    N, n = len(pb.targets), pb.robot.n
    flat_score = score.reshape(N, -1)
    best = flat_score.argmax(axis=1)
    ar = np.arange(N)
    reached = flat_score[ar, best] >= 0
    support = (score >= 0).any(axis=1).sum(axis=1)
    top = stage.reshape(N, -1).max(axis=1)
    # the least failing solution where unreached: the furthest stage, then (in collision) the clearest
    key = stage.reshape(N, -1).astype(float)
    if pb.world is not None:
        key = key + 1e-3 * np.tanh(np.nan_to_num(terms[..., 1].reshape(N, -1), nan=-1e3))
    pick = np.where(reached, best, key.argmax(axis=1))
    Q = qs.reshape(N, -1, n)[ar, pick]
    T = terms.reshape(N, -1, 3)[ar, pick]
    out = {"reached": reached, "score": np.where(reached, flat_score[ar, best], 0.0), "q": Q,
           "dexterity": np.where(reached, T[:, 0], np.nan),
           "clearance": np.where(reached | (top >= 1), T[:, 1], np.nan),
           "limit_margin": np.where(reached, T[:, 2], np.nan), "support": support, "top": top}
    if not explain:
        return out
    reason = np.array(["reached"] * N, dtype=object)
    detail = np.array([""] * N, dtype=object)
    obstacle = np.array([""] * N, dtype=object)
    stage_reason = {3: "dexterity", 2: "window", 1: "collision"}
    for i in np.flatnonzero(~reached):
        reason[i] = stage_reason.get(int(top[i]), "out_of_reach")
    # collisions: name the pair of the least colliding solution
    col = np.flatnonzero(reason == "collision")
    if len(col) and pb.world is not None:
        c = pb.world.nearest(Q[col])
        for m, i in enumerate(col):
            b, o, d = int(c.body[m]), int(c.other[m]), float(c.clearance[m])
            detail[i] = pb.world.describe(b, o, d)
            obstacle[i] = pb.world.obstacles[o].name if o >= 0 else pb.world.body_names[-1 - o]
    for i in np.flatnonzero(reason == "window"):
        detail[i] = "every clear solution is inside a singular window"
    for i in np.flatnonzero(reason == "dexterity"):
        detail[i] = f"every clear solution has {pb.dex.kind} below {pb.dex.value:g}"
    far = np.flatnonzero(reason == "out_of_reach")
    if len(far):       # reachable with the limits lifted?
        lifted = pb.lifted()
        t = pb.targets
        goal, starts, mode = pb.goals(P)
        rows = (far[:, None] * pb.nv + np.arange(pb.nv)[None]).ravel()
        hit = np.zeros(len(far), bool)
        for j in range(starts.shape[1]):       # the study's starts, each with random restarts over the lifted range
            left = ~hit
            if not left.any():
                break
            if pb._late():
                pb.cut.append(f"{int(left.sum())} unreached target(s) not tried with the joint limits lifted "
                              "(said out of reach)")
                break
            sub = (np.flatnonzero(left)[:, None] * pb.nv + np.arange(pb.nv)[None]).ravel()
            res = lifted.ik(goal[rows[sub]], seed=j, q0=np.repeat(starts[far[left], j], pb.nv, axis=0), mode=mode,
                            restarts=4, rounds=2, max_iter=pb.settings.max_iter, tol_position=t.tolerance)
            hit[left] = np.asarray(res.success, bool).reshape(int(left.sum()), pb.nv).any(axis=1)
        for i, h in zip(far, hit):
            reason[i] = "joint_limits" if h else "out_of_reach"
            detail[i] = ("reached only beyond the joint limits" if h else
                         "no solution, even with the joint limits lifted")
    out.update(reason=reason.astype(str), detail=detail.astype(str), obstacle=obstacle.astype(str))
    return out


def reach_study(robot: kin.Robot, targets: Targets, cell=None, placement=None, clearance: float = 0.0,
                windows=None, weights: ScoreWeights | None = None, settings: ReachSettings | None = None,
                dexterity: Dexterity | None = None, progress: Callable[[str], None] | None = None,
                hint: np.ndarray | None = None) -> ReachStudy:
    """Reach study of ``targets`` (cell frame) by ``robot`` at ``placement`` in ``cell``.

    ``cell``: a :class:`planning.cell.Cell` (or None: no collisions); ``placement``: the robot's base
    placement in the cell (a :class:`kin.Placement`, 4×4, or x y z roll pitch yaw; None: the cell's
    own); ``clearance``: what a solution needs (m); ``windows``: a
    :class:`planning.windows.WindowSet` whose inside does not count; ``dexterity``: a required
    σ_min or manipulability; ``hint`` (N, n): one more start per target, e.g. the configurations a
    placement optimisation found (judged like every other start: IK from it to the target, then the
    limits, the cell, the windows).  See the module text for verdicts, reasons and the score.
    """
    if not isinstance(targets, Targets):
        raise TaskError(f"targets must be design.task.Targets, got {type(targets).__name__}")
    weights = weights or ScoreWeights()
    settings = settings or ReachSettings()
    pb = ReachProblem(robot, targets, cell, clearance, windows, weights, settings, dexterity)
    P = pb.default_base if placement is None else placement_matrix(placement)
    if progress:
        progress(f"reach study: {len(targets)} targets × {pb.nv} orientation(s) × {settings.starts} starts")
    return pb.study(P, hint)
