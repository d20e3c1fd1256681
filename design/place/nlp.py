"""The placement NLP: one CasADi problem over the robot's base placement u and one configuration
q_k per target, solved by IPOPT with exact derivatives — the per-target inverse kinematics is the
constraint.

Variables: the free placement coordinates (within the region), q_k (within the joint limits), an
L1 slack s_k ≥ 0 (3) on each target's position, and two epigraph variables per target: d_k ≤ the
dexterity of q_k (0 ≤ d_k ≤ the score's reference) and m_k ≤ its joint-limit margin (0 ≤ m_k ≤ 1).

* position: −s_k ≤ T(u)·FK(q_k) − x_k ≤ s_k (cell frame);
* orientation, with R = R(u)·R_FK(q_k): "pose" — x·z* = y·z* = y·x* = 0, z·z* ≥ 0, x·x* ≥ 0;
  "axis" — x·a = y·a = 0, z·a ≥ 0 (free about the axis: no spins needed here); "cone" — z·a ≥ cos α;
* σ_min ≥ d_k: with G the smaller Gram matrix of the translational Jacobian rows (identically zero
  rows dropped), the leading principal minors of G − d_k² I are ≥ 0 (Sylvester); manipulability:
  det G_task ≥ d_k²;
* joint-limit margin: m_k ≤ (q_ki − lo_i)/h_i and m_k ≤ (hi_i − q_ki)/h_i, h_i half the range;
* keep-out floor rectangles: per solve, the base origin on one chosen side of each rectangle (a
  linear constraint; the side is the start's, see :meth:`PlacementNlp.solve`).

Objective: minimise  W·Σ|s_k|/L − (1/N)·Σ (w_d·d_k/ref + w_l·m_k)/(w_d + w_l + w_c),  with L the
robot's reach and W = 100: coverage first (an exact L1 penalty: a target's slack outweighs the
whole score), then the reach score.  The score's
clearance term is not smooth and is left to the verification (every answer is re-verified by the
reach study, which checks collisions).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from design.metrics import structural_length
from design.optimise.nlp import orientation_terms
from design.place.region import PlacementRegion
from design.reach.score import ScoreWeights
from design.task.model import Targets

__all__ = ["PlacementNlp", "NlpRun", "COVERAGE_WEIGHT"]

#: weight of the coverage slack against the score (per reach length)
COVERAGE_WEIGHT = 100.0


@dataclass
class NlpRun:
    """One IPOPT run: start and final placement (6,), objective, status, iterations, time (s)."""

    u0: np.ndarray
    u: np.ndarray
    q: np.ndarray
    objective: float
    success: bool
    status: str
    iterations: int
    time_s: float
    sides: tuple[str, ...] = ()
    history: list[float] = field(default_factory=list)


def _rotation(r, p, y):
    cr, sr, cp, sp, cy, sy = ca.cos(r), ca.sin(r), ca.cos(p), ca.sin(p), ca.cos(y), ca.sin(y)
    return ca.vertcat(ca.horzcat(cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
                      ca.horzcat(sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
                      ca.horzcat(-sp, cp * sr, cp * cr))


class PlacementNlp:
    """The placement NLP of one robot, target set and region; built once, solved from many starts.

    ``dex_ref``: the score's dexterity reference (SI); ``cell``: whether the score has a clearance
    term (it is constant here); ``max_iter``, ``max_time`` (CPU s) per solve."""

    def __init__(self, robot, targets: Targets, region: PlacementRegion, weights: ScoreWeights, dex_ref: float,
                 cell: bool, max_iter: int = 500, max_time: float = 60.0):
        self.robot, self.targets, self.region = robot, targets, region
        chain = robot.chain
        N, n = len(targets), robot.n
        self.N, self.n = N, n
        free = region.free
        self.free = free
        kf = int(free.sum())
        v = ca.SX.sym("v", kf)
        lo = region.bounds[:, 0]
        u, j = [], 0
        for i in range(6):
            if free[i]:
                u.append(v[j])
                j += 1
            else:
                u.append(ca.DM(lo[i]))
        Rb = _rotation(u[3], u[4], u[5])
        tb = ca.vertcat(u[0], u[1], u[2])
        Q = ca.SX.sym("Q", n, N)
        S = ca.SX.sym("S", 3, N)
        D = ca.SX.sym("D", N)
        M = ca.SX.sym("M", N)
        fkj = robot.symbolic.fkj_function
        p0 = ca.DM(chain.parameter_values) if chain.parameters else ca.DM.zeros(0, 1)
        g, lbg, ubg = [], [], []

        def add(expr, lo_, hi_):
            g.append(expr)
            lbg.extend([lo_] * expr.numel())
            ubg.extend([hi_] * expr.numel())

        half = 0.5 * (chain.upper - chain.lower)
        measure = weights.measure
        for k in range(N):
            T, J = fkj(Q[:, k], p0)
            pos = Rb @ T[:3, 3] + tb
            r = pos - ca.DM(targets.positions[k])
            add(r - S[:, k], -ca.inf, 0.0)
            add(r + S[:, k], 0.0, ca.inf)
            eq, ineq = orientation_terms(targets, k, Rb @ T[:3, :3])
            for e in eq:
                add(e, 0.0, 0.0)
            for e in ineq:
                add(e, 0.0, ca.inf)
            if weights.dexterity > 0:
                if measure == "manipulability":
                    Jt = J[list(robot.task_rows), :]
                    Gm = Jt @ Jt.T if Jt.shape[0] <= Jt.shape[1] else Jt.T @ Jt
                    add(ca.det(Gm) - D[k] ** 2, 0.0, ca.inf)
                else:
                    Jv = J[:3, :]
                    G = Jv @ Jv.T if n >= 3 else Jv.T @ Jv
                    keep = [i for i in range(G.shape[0]) if not ca.SX(G[i, i]).is_zero()]
                    Gs = G[keep, keep] - D[k] ** 2 * ca.SX.eye(len(keep))
                    for m in range(1, len(keep) + 1):
                        add(ca.det(Gs[:m, :m]), 0.0, ca.inf)
            if weights.limits > 0:
                add((Q[:, k] - ca.DM(chain.lower)) / ca.DM(half) - M[k], 0.0, ca.inf)
                add((ca.DM(chain.upper) - Q[:, k]) / ca.DM(half) - M[k], 0.0, ca.inf)
        self.n_fixed_g = len(lbg)
        # keep-out rectangles: the base origin's x and y, bounded per solve
        for _ in region.keep_out:
            add(ca.vertcat(u[0], u[1]), -ca.inf, ca.inf)
        reach = max(structural_length(chain), 0.1)
        wsum = weights.dexterity + weights.limits + (weights.clearance if cell else 0.0)
        score = (weights.dexterity * ca.sum1(D) / dex_ref + weights.limits * ca.sum1(M)) / wsum
        f = COVERAGE_WEIGHT * ca.sum1(ca.sum2(S)) / reach - score / N
        x = ca.vertcat(v, ca.vec(Q), ca.vec(S), D, M)
        b = region.bounds[free]
        self.lbx = np.concatenate([b[:, 0], np.tile(chain.lower, N), np.zeros(3 * N), np.zeros(N), np.zeros(N)])
        self.ubx = np.concatenate([b[:, 1], np.tile(chain.upper, N), np.full(3 * N, np.inf),
                                   np.full(N, dex_ref), np.ones(N)])
        self.lbg, self.ubg = np.array(lbg, float), np.array(ubg, float)
        self.kf, self.dex_ref, self.weights = kf, dex_ref, weights
        opts = {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes", "ipopt.max_iter": max_iter,
                "ipopt.max_cpu_time": max_time, "ipopt.tol": 1e-9, "ipopt.acceptable_tol": 1e-7}
        self.solver = ca.nlpsol("placement", "ipopt", {"x": x, "f": f, "g": ca.vertcat(*g)}, opts)

    def sides(self, u0: np.ndarray) -> tuple[str, ...]:
        """For each keep-out rectangle, the side the start u0 is on (or nearest to, when inside)."""
        out = []
        for x0, x1, y0, y1 in self.region.keep_out:
            gaps = {"x<": u0[0] - x0, "x>": x1 - u0[0], "y<": u0[1] - y0, "y>": y1 - u0[1]}
            out.append(min(gaps, key=gaps.get))     # the most negative gap: where it stands out most
        return tuple(out)

    def solve(self, u0: np.ndarray, q0: np.ndarray) -> NlpRun:
        """One IPOPT run from placement u0 (6,) and configurations q0 (N, n); SI."""
        robot, chain, t = self.robot, self.robot.chain, self.targets
        N, n = self.N, self.n
        b = self.region.bounds
        u0 = np.clip(np.asarray(u0, float), b[:, 0], b[:, 1])
        q0 = np.clip(np.asarray(q0, float), chain.lower, chain.upper)
        from design.place.region import placement_transform
        from design.reach.score import limit_margin
        from design.reach.study import _dexterity
        P = placement_transform(u0)
        pos = robot.fk(q0)[:, :3, 3] @ P[:3, :3].T + P[:3, 3]
        d0 = np.clip(_dexterity(robot, q0, self.weights.measure), 0, self.dex_ref) * 0.99
        m0 = limit_margin(q0, chain.lower, chain.upper) * 0.99
        x0 = np.concatenate([u0[self.free], q0.ravel(), np.abs(pos - t.positions).ravel(), d0, m0])
        lbg, ubg = self.lbg.copy(), self.ubg.copy()
        sides = self.sides(u0)
        i = self.n_fixed_g
        for (x_0, x_1, y_0, y_1), side in zip(self.region.keep_out, sides):
            if side == "x<":
                ubg[i] = x_0
            elif side == "x>":
                lbg[i] = x_1
            elif side == "y<":
                ubg[i + 1] = y_0
            else:
                lbg[i + 1] = y_1
            i += 2
        t0 = time.perf_counter()
        sol = self.solver(x0=x0, lbx=self.lbx, ubx=self.ubx, lbg=lbg, ubg=ubg)
        dt = time.perf_counter() - t0
        st = self.solver.stats()
        xs = np.array(sol["x"]).ravel()
        u = b[:, 0].copy()
        u[self.free] = np.clip(xs[:self.kf], b[self.free, 0], b[self.free, 1])
        q = xs[self.kf:self.kf + n * N].reshape(N, n)
        return NlpRun(u0=u0, u=u, q=q, objective=float(sol["f"]), success=bool(st["success"]),
                      status=str(st["return_status"]), iterations=int(st.get("iter_count", 0)), time_s=dt,
                      sides=sides, history=[float(v) for v in st.get("iterations", {}).get("obj", [])])
