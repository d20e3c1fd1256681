"""Continuous inverse kinematics along a tool path: the solver behind
:func:`planning.toolpath.check.validate_toolpath`.

The first waypoint is solved from ``start_q`` when given (the choice of start branch; a local
solve, or :meth:`kin.Robot.ik` with ``q0 = start_q`` when that fails), otherwise by
:meth:`kin.Robot.ik` (the compiled solver of :mod:`kin.ik`, like the rare global fall-backs below;
its seeded random starts pick the branch).  Every next waypoint is solved
by Newton / damped-least-squares (Levenberg–Marquardt) steps from the previous solution, whose FK
and Jacobian are already known — on a smooth path one step and one new FK+Jacobian evaluation per
waypoint:

    J_w·Δq = e   or   (J_wᵀJ_w + μ·I)·Δq = J_wᵀ·e,
    e = [p* − p(q); w·log(R*·R(q)ᵀ)],   J_w = diag(1, 1, 1, w, w, w)·J

with w a length (half the robot's reach) that weighs radians against metres.  The undamped step is
used while J_w is square and well conditioned; near a singularity, or when a step does not lower
‖e‖, the damping μ takes over and grows until a step does.  Steps are not clipped to the joint
limits: a path that needs a joint beyond its limit is reported as such.  When the local solve fails
the waypoint is retried from the previous solution in Cartesian sub-steps, then by the global
solver (rarely: with doubling gaps along an unreachable stretch, at most :data:`MAX_GLOBAL_SOLVES`
times per path).

:func:`continuous_ik` returns the joint solution and, per waypoint, the joint step from the
previous reachable waypoint and whether it is a branch jump; judging the solution is
:mod:`planning.toolpath.check`'s work.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.linalg import lapack

from kin.transforms import log_so3, rotation_error
from planning.toolpath.geometry import slerp
from planning.toolpath.model import ToolPath

__all__ = ["continuous_ik", "ContinuousIK", "MAX_GLOBAL_SOLVES"]

#: the local solver aims this far inside the tolerances (the final check is a batch FK at the tolerances)
_AIM = 1e-1
#: at most this many waypoints per path go to the (slower) global solver
MAX_GLOBAL_SOLVES = 8


@dataclass
class ContinuousIK:
    """Result of :func:`continuous_ik`.  q (N, n) joint solution (SI); jump (N,) bool: the largest
    joint change from the previous reachable waypoint exceeds its bound (not across an unreachable
    stretch); step (N,) that largest change (0 where unreachable); prev (N,) index of the previous
    reachable waypoint (−1: none); stats: solver counts and times."""

    q: np.ndarray
    jump: np.ndarray
    step: np.ndarray
    prev: np.ndarray
    stats: dict


def _length_scale(chain) -> float:
    """A length (m) that weighs orientation errors against position errors: half the reach."""
    tab = chain.dh_table()
    reach = np.abs(tab[:, 0]).sum() + np.abs(tab[:, 2]).sum() + np.linalg.norm(chain.tool.matrix[:3, 3])
    return float(max(0.5 * reach, 0.05))


class _Tracker:
    """Newton / Levenberg–Marquardt on one configuration, cheap per step.

    A step costs one compiled FK+Jacobian call (``robot.fk_jacobian``), the residual in plain
    Python floats and one LAPACK call: a Newton step J_w·Δq = e (LU, ``dgesv``) while the weighted
    Jacobian is square and the step stays moderate, otherwise the damped normal equations
    (J_wᵀJ_w + μ·I)·Δq = J_wᵀ·e (Cholesky, ``dposv``).  A step is kept only when it lowers ‖e‖;
    otherwise the damping grows (Newton falls back to LM).  Near a singularity — where the
    undamped resolved-rate step q += J⁻¹·ẋ·Δt grows without bound — the damping keeps the step
    bounded.
    """

    def __init__(self, robot, pose: bool, w: float, tol_p: float, tol_o: float, big_step: float):
        self.fkj = robot.fk_jacobian
        self.n = n = robot.n
        self.pose = pose
        self.w = w
        self.aim_p, self.aim_o = tol_p * _AIM, tol_o * _AIM
        self.tol_p, self.tol_o = tol_p, tol_o
        self.square = (6 if pose else 3) == n
        self.big = big_step
        self.eye = np.eye(n)
        self.scale = None          # μ = λ·scale, scale = mean diagonal of J_wᵀJ_w at the first evaluation
        self.evals = 0
        self.last = None           # (q, (T, J_w)) of the last solve's result
        self.improving = False     # the last solve ran out of iterations while converging fast

    def evaluate(self, q):
        """(T as nested lists, weighted Jacobian J_w) at q: one compiled call."""
        T, J = self.fkj(q)
        self.evals += 1
        if self.pose:
            J[3:] *= self.w
            return T.tolist(), J
        return T.tolist(), J[:3]

    def error(self, T, pt, Rt):
        """(e, pe, oe): weighted error (6,) or (3,), position and orientation error (m, rad) of the
        pose T (nested lists) against the target ``pt`` (3 floats) and ``Rt`` (nested 3×3 lists)."""
        (r00, r01, r02, px), (r10, r11, r12, py), (r20, r21, r22, pz), _ = T
        ex, ey, ez = pt[0] - px, pt[1] - py, pt[2] - pz
        pe = math.sqrt(ex * ex + ey * ey + ez * ez)
        if not self.pose:
            return np.array((ex, ey, ez)), pe, 0.0
        # rotation vector of Re = Rt·Rᵀ (the geometric Jacobian's angular rows act on it)
        (a0, a1, a2), (b0, b1, b2), (c0, c1, c2) = Rt
        e00 = a0 * r00 + a1 * r01 + a2 * r02
        e11 = b0 * r10 + b1 * r11 + b2 * r12
        e22 = c0 * r20 + c1 * r21 + c2 * r22
        vx = (c0 * r10 + c1 * r11 + c2 * r12) - (b0 * r20 + b1 * r21 + b2 * r22)   # Re21 − Re12
        vy = (a0 * r20 + a1 * r21 + a2 * r22) - (c0 * r00 + c1 * r01 + c2 * r02)   # Re02 − Re20
        vz = (b0 * r00 + b1 * r01 + b2 * r02) - (a0 * r10 + a1 * r11 + a2 * r12)   # Re10 − Re01
        s2 = vx * vx + vy * vy + vz * vz
        cos = 0.5 * (e00 + e11 + e22 - 1.0)
        if s2 > 1e-28:
            sin = 0.5 * math.sqrt(s2)
            sc = math.atan2(sin, cos) / (2.0 * sin)
            ox, oy, oz = vx * sc, vy * sc, vz * sc
        elif cos > 0:   # identity up to rounding
            ox, oy, oz = 0.5 * vx, 0.5 * vy, 0.5 * vz
        else:           # a half turn: the skew part vanishes; use the exact logarithm
            ox, oy, oz = log_so3(np.array(Rt) @ np.array(T)[:3, :3].T).tolist()
        oe = math.sqrt(ox * ox + oy * oy + oz * oz)
        w = self.w
        return np.array((ex, ey, ez, w * ox, w * oy, w * oz)), pe, oe

    def converged(self, pe: float, oe: float) -> bool:
        return pe <= self.tol_p and oe <= self.tol_o

    def solve(self, q, pt, Rt, max_iter: int, at=None):
        """Iterate from q (n,) towards the target; returns (q, pe, oe, iterations).

        ``at``: (T, J_w) already evaluated at q (the previous waypoint's solution), saving a call.
        The last accepted evaluation is kept in :attr:`last` for the next waypoint.
        """
        T, J = self.evaluate(q) if at is None else at
        e, pe, oe = self.error(T, pt, Rt)
        if self.scale is None:
            self.scale = max(float(np.dot(J.ravel(), J.ravel())) / self.n, 1e-12)
        cost = float(e.dot(e))
        it = 0
        newton = self.square
        lam = 1e-6
        ratio = 1.0      # cost ratio of the last accepted step
        while (pe > self.aim_p or oe > self.aim_o) and it < max_iter:
            it += 1
            if newton:
                lu, _, dq, info = lapack.dgesv(J, e)
                u = np.abs(lu.diagonal()).tolist()
                dl = dq.tolist()
                # (nearly) singular J: a Newton step could move along the null space at will — damp instead
                if info != 0 or min(u) < 1e-8 * max(u) or max(dl) > self.big or -min(dl) > self.big:
                    newton = False      # singular or a wild step: damp instead (no evaluation spent)
                    it -= 1
                    continue
            else:
                A = J.T.dot(J)
                A += self.eye * (lam * self.scale)
                g = J.T.dot(e)
                _, dq, info = lapack.dposv(A, g)
                if info != 0:           # not positive definite numerically: least squares
                    dq = np.linalg.lstsq(A, g, rcond=None)[0]
            qn = q + dq
            Tn, Jn = self.evaluate(qn)
            en, pen, oen = self.error(Tn, pt, Rt)
            cn = float(en.dot(en))
            if cn < cost:
                ratio = cn / cost if cost > 0 else 0.0
                q, T, J, e, pe, oe, cost = qn, Tn, Jn, en, pen, oen, cn
                lam = max(lam * 0.1, 1e-12)
            elif newton:
                newton = False
            else:
                lam *= 10.0
                if lam > 1e8:
                    break
        self.last = (q, (T, J))
        # still converging fast when the iterations ran out (a reachable target, far away): worth more
        self.improving = it >= max_iter and ratio < 0.5
        return q, pe, oe, it


# ---- along the path -------------------------------------------------------------------------------
def continuous_ik(robot, toolpath: ToolPath, Pt: np.ndarray, Rt: np.ndarray, mode: str, start_q,
                  branch_seed: int, bound: np.ndarray, tol_position: float, tol_orientation: float,
                  max_iter: int, t0: float) -> ContinuousIK:
    """Follow ``toolpath`` with a continuous IK solution (see the module docstring).

    Pt (N, 3), Rt (N, 3, 3): the target positions (m) and rotations, contiguous; mode ``"pose"`` or
    ``"position"``; start_q (n,) SI or None; bound (n,) largest joint change per waypoint (rad/m);
    t0: ``time.perf_counter()`` at the start of the validation (``stats["solve_s"]`` counts from it).
    """
    chain = robot.chain
    n = chain.n
    pose = mode == "pose"
    N = len(toolpath)
    # the per-waypoint loop works on plain Python floats: numpy's per-call overhead dominates at n = 6
    Ptl, Rtl = Pt.tolist(), Rt.tolist()
    tracker = _Tracker(robot, pose, _length_scale(chain), tol_position, tol_orientation, float(bound.max()))
    ik_opts = dict(mode=mode, tol_position=tol_position, tol_orientation=tol_orientation)
    bl = bound.tolist()
    b0 = bl[0] if all(b == bl[0] for b in bl) else None

    def jump_of(q, ref) -> tuple[float, bool]:
        """(largest |Δq|, whether every joint stays within its bound)."""
        d = (q - ref).tolist()
        m = max(max(d), -min(d))
        if b0 is not None:
            return m, m <= b0
        return m, all(abs(x) <= c for x, c in zip(d, bl))

    Q = np.zeros((N, n))
    jump = np.zeros(N, bool)
    step = np.zeros(N)
    prev = np.full(N, -1)      # index of the previous reachable waypoint (the one a jump is measured from)
    stats = {"global_solves": 0, "substep_retries": 0, "iterations": 0}
    conv = tracker.converged
    lo, hi = chain.lower, chain.upper

    def inside(q) -> bool:
        return bool(np.all((q >= lo) & (q <= hi)))

    # first waypoint: the start branch
    q_first = at_prev = outside = None      # at_prev: (T, J_w) at the last reachable solution, when known
    if start_q is not None:
        q, pe, oe, it = tracker.solve(start_q.copy(), Ptl[0], Rtl[0], 50)
        stats["iterations"] += it
        if conv(pe, oe):
            if inside(q):
                q_first, at_prev = q, tracker.last[1]
            else:
                outside = (q, tracker.last[1])   # reached, beyond a limit: kept if nothing better exists
    ok0 = True
    if q_first is None:
        res = robot.ik(toolpath.poses[0], seed=branch_seed, q0=start_q, **ik_opts)
        stats["global_solves"] += 1
        if res.success or outside is None:
            q_first, ok0 = np.asarray(res.q, dtype=float), bool(res.success)
        else:
            q_first, at_prev = outside
    Q[0] = q_first
    q_prev = q_first if ok0 else None        # the last reachable solution: the continuation's seed
    i_prev = 0 if ok0 else -1

    # global solves are slow (a batch of random starts): within an unreachable stretch they are tried
    # with doubling gaps (offsets 0, 1, 3, 7, … into the stretch), at most MAX_GLOBAL_SOLVES per path
    backoff = {"next": 0, "gap": 1}

    def global_solve(i: int, q0):
        if stats["global_solves"] >= MAX_GLOBAL_SOLVES or i < backoff["next"]:
            return None
        res = robot.ik(toolpath.poses[i], seed=branch_seed, q0=q0, restarts=4, rounds=2, max_iter=100, **ik_opts)
        stats["global_solves"] += 1
        if res.success:
            return np.asarray(res.q, dtype=float), res.position_error, res.orientation_error
        backoff["next"], backoff["gap"] = i + backoff["gap"], 2 * backoff["gap"]
        return None

    for i in range(1, N):
        pt, R = Ptl[i], Rtl[i]
        if q_prev is None:   # nothing reachable yet: local from the best try so far, then (rarely) global
            q, pe, oe, it = tracker.solve(np.clip(Q[i - 1], lo, hi), pt, R, max_iter)
            stats["iterations"] += it
            Q[i] = q
            if conv(pe, oe) and inside(q):   # no continuity to keep yet: take a solution within the limits
                q_prev, i_prev, at_prev = q, i, tracker.last[1]
            elif (g := global_solve(i, start_q)) is not None:
                Q[i] = g[0]
                q_prev, i_prev, at_prev = g[0], i, None
            if q_prev is not None:
                backoff["next"], backoff["gap"] = 0, 1
            continue
        stretch = i_prev < i - 1     # inside an unreachable stretch: cheaper attempts
        # Newton from the previous solution, whose FK and Jacobian are at hand: usually one new evaluation
        q, pe, oe, it = tracker.solve(q_prev, pt, R, max_iter if stretch else 4 * max_iter, at=at_prev)
        stats["iterations"] += it
        if stretch and tracker.improving and not conv(pe, oe):   # coming back into reach: keep going
            q, pe, oe, it = tracker.solve(q, pt, R, 4 * max_iter, at=tracker.last[1])
            stats["iterations"] += it
        ok = conv(pe, oe)
        stp, near = jump_of(q, q_prev) if ok else (math.inf, False)
        at = tracker.last[1]
        if not (ok and near) and not stretch:
            # Cartesian sub-steps from the previous waypoint keep the solution on its branch if it exists
            stats["substep_retries"] += 1
            q3, ok3 = _substeps(tracker, q_prev, toolpath.poses[i - 1], toolpath.poses[i], 8, 4 * max_iter, stats)
            if ok3:
                pe3, oe3 = _errors(robot, q3, Pt[i], Rt[i], pose)
                stp3, near3 = jump_of(q3, q_prev)
                if conv(pe3, oe3) and (near3 or not ok):
                    q, pe, oe, ok, stp, near, at = q3, pe3, oe3, True, stp3, near3, None
        if not ok and (g := global_solve(i, q_prev)) is not None:
            q, pe, oe, ok = *g, True
            stp, near, at = *jump_of(q, q_prev), None
        Q[i] = q
        if ok:
            prev[i] = i_prev
            step[i] = stp
            jump[i] = not near and not stretch   # across an unreachable stretch the gap is no branch problem
            q_prev, i_prev, at_prev = q, i, at
            backoff["next"], backoff["gap"] = 0, 1
    stats["fk_jacobian_calls"] = tracker.evals
    stats["solve_s"] = time.perf_counter() - t0
    return ContinuousIK(q=Q, jump=jump, step=step, prev=prev, stats=stats)


def _errors(robot, q, pt, R, pose: bool) -> tuple[float, float]:
    T = robot.fk(q)
    pe = float(np.linalg.norm(pt - T[:3, 3]))
    oe = float(np.linalg.norm(rotation_error(R, T[:3, :3]))) if pose else 0.0
    return pe, oe


def _substeps(tracker: _Tracker, q, T0: np.ndarray, T1: np.ndarray, k: int, max_iter: int, stats: dict):
    """Follow the straight Cartesian interpolation T0 → T1 in k sub-steps from q; (q, success)."""
    u = np.arange(1, k + 1) / k
    P = T0[:3, 3][None] + u[:, None] * (T1[:3, 3] - T0[:3, 3])[None]
    R = slerp(T0[:3, :3], T1[:3, :3], u)
    Pl, Rl = P.tolist(), R.tolist()
    for j in range(k):
        q, pe, oe, it = tracker.solve(q, Pl[j], Rl[j], max_iter)
        stats["iterations"] += it
        if not tracker.converged(pe, oe):
            return q, False
    return q, True
