"""The gradient-based design optimisation: one CasADi NLP over the design parameters p and one
configuration q_k per target, solved by IPOPT with exact derivatives.

Variables: p (n_p, within the parameter bounds), q_k (n, within the joint limits) per target, and
when the objective is coverage an L1 slack s_k ≥ 0 (3) on each target's position.  Constraints:

* position: FK(q_k, p) − x_k = 0 (or −s_k ≤ FK(q_k, p) − x_k ≤ s_k);
* orientation: "pose" — tool x·z* = 0, y·z* = 0, y·x* = 0, z·z* ≥ 0, x·x* ≥ 0; "axis" — x·a = 0,
  y·a = 0, z·a ≥ 0; "cone" — z·a ≥ cos(half-angle);
* dexterity σ_min ≥ s: with G the smaller Gram matrix of the dexterity Jacobian (JᵀJ or JJᵀ),
  G/s² − I ⪰ 0 through its leading principal minors ≥ 0 (Sylvester; polynomial, so IPOPT
  differentiates it exactly); manipulability ≥ m: det G / m² ≥ 1;
* total length (optional): Σ(|a_i| + |d_i|) = L, with |x| smoothed as √(x² + ε²).

Objectives: "length" minimises Σ(|a_i| + |d_i|); "coverage" minimises Σ s_k (maximises coverage).
Non-smooth objectives (Q_L, GCI) are for differential evolution (:mod:`design.optimise.de`).
The dexterity threshold carries a small margin (``margin``, relative) so that the optimum, which
lies on that constraint, passes the independent verification with the exact threshold.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

import kin
from design.task.model import Task, TaskError

__all__ = ["NlpStart", "DesignNlp", "solve_nlp", "IPOPT_OBJECTIVES", "orientation_terms"]

IPOPT_OBJECTIVES = ("length", "coverage")
_EPS = 1e-9


@dataclass
class NlpStart:
    """One IPOPT run: initial and final parameters (SI), objective, IPOPT's status and statistics."""

    p0: np.ndarray
    p: np.ndarray
    objective: float
    success: bool
    status: str
    iterations: int
    time_s: float
    history: list[float] = field(default_factory=list)
    constraint_violation: list[float] = field(default_factory=list)
    q: np.ndarray | None = None


def _abs(x):
    return ca.sqrt(x * x + _EPS ** 2)


def _dh_length(chain: kin.Chain, p: ca.SX) -> ca.SX:
    names = list(chain.parameters)
    total = 0
    for j in chain.joints:
        for f in ("a", "d"):
            v = getattr(j, f)
            total = total + (_abs(p[names.index(v)]) if isinstance(v, str) else abs(float(v)))
    return total


def _minors(G: ca.SX) -> list[ca.SX]:
    return [ca.det(G[:k, :k]) for k in range(1, G.shape[0] + 1)]


def _dexterity_terms(task: Task, J: ca.SX, margin: float) -> list[ca.SX]:
    """Constraint expressions ≥ 0 for the dexterity requirement at one configuration."""
    dex, chain = task.dexterity, task.robot.chain
    if dex.kind == "none" or dex.value <= 0:
        return []
    if dex.kind == "sigma_min_full":
        L = dex.characteristic_length
        scale_c = ca.DM([L if not j.is_revolute else 1.0 for j in chain.joints]).T
        Jd = ca.vertcat(J[:3, :] / L, J[3:, :]) * ca.repmat(scale_c, 6, 1)
    elif dex.kind == "manipulability":
        Jd = J[list(task.robot.task_rows), :]
    else:
        Jd = J[:3, :]
    m, n = Jd.shape
    G = Jd.T @ Jd if m > n else Jd @ Jd.T
    if dex.kind == "manipulability":
        return [ca.det(G) / (dex.value * (1 + margin)) ** 2 - 1.0]
    s2 = (dex.value * (1 + margin)) ** 2
    # drop identically-zero rows/columns (e.g. the z row of a planar arm): they would make G singular
    keep = [i for i in range(G.shape[0]) if not ca.SX(G[i, i]).is_zero()]
    Gs = G[keep, keep] / s2 - ca.SX.eye(len(keep))
    return _minors(Gs)


def orientation_terms(targets, k: int, R: ca.SX) -> tuple[list[ca.SX], list[ca.SX]]:
    """(equalities = 0, inequalities ≥ 0) of target k's orientation requirement, R the tool's rotation
    (CasADi, 3×3) in the targets' frame (:class:`design.task.model.Targets`): "pose" x·z* = y·z* =
    y·x* = 0, z·z* ≥ 0, x·x* ≥ 0; "axis" x·a = y·a = 0, z·a ≥ 0; "cone" z·a ≥ cos(half-angle)."""
    t = targets
    x, y, z = R[:, 0], R[:, 1], R[:, 2]
    if t.orientation == "pose":
        Rs = t.rotations[k]
        xs, zs = ca.DM(Rs[:, 0]), ca.DM(Rs[:, 2])
        return [ca.dot(x, zs), ca.dot(y, zs), ca.dot(y, xs)], [ca.dot(z, zs), ca.dot(x, xs)]
    if t.orientation == "axis":
        a = ca.DM(t.axes[k])
        return [ca.dot(x, a), ca.dot(y, a)], [ca.dot(z, a)]
    if t.orientation == "cone":
        return [], [ca.dot(z, ca.DM(t.axes[k])) - np.cos(t.cone_half_angle)]
    return [], []


class DesignNlp:
    """The NLP of a task, built once (CasADi graph and IPOPT instance) and solved from many starts.

    ``margin``: relative margin on the dexterity threshold; ``max_iter``, ``max_time`` (CPU s):
    IPOPT's limits per solve."""

    def __init__(self, task: Task, margin: float = 2e-3, max_iter: int = 1000, max_time: float = 120.0):
        robot, chain, targets = task.robot, task.robot.chain, task.targets
        if task.objective not in IPOPT_OBJECTIVES:
            raise TaskError(f"objective {task.objective!r} is not smooth; IPOPT handles "
                            f"{', '.join(IPOPT_OBJECTIVES)} (use the differential evolution method)")
        if not chain.parameters:
            raise TaskError(f"{robot.name} has no design parameters to optimise")
        self.task = task
        N, n, npar = len(targets), robot.n, len(chain.parameters)
        self.N, self.n, self.npar = N, n, npar
        self.cover = cover = task.objective == "coverage"
        p = ca.SX.sym("p", npar)
        Q = ca.SX.sym("Q", n, N)
        S = ca.SX.sym("S", 3, N) if cover else ca.SX(3, 0)
        fkj = robot.symbolic.fkj_function
        g, lbg, ubg = [], [], []

        def add(expr, lo, hi):
            g.append(expr)
            lbg.extend([lo] * expr.numel())
            ubg.extend([hi] * expr.numel())

        for k in range(N):
            T, J = fkj(Q[:, k], p)
            r = T[:3, 3] - ca.DM(targets.positions[k])
            if cover:
                add(r - S[:, k], -ca.inf, 0.0)
                add(r + S[:, k], 0.0, ca.inf)
            else:
                add(r, 0.0, 0.0)
            eq, ineq = orientation_terms(task.targets, k, T[:3, :3])
            for e in eq:
                add(e, 0.0, 0.0)
            for e in ineq:
                add(e, 0.0, ca.inf)
            for e in _dexterity_terms(task, J, margin):
                add(e, 0.0, ca.inf)
        if task.total_length is not None:
            add(_dh_length(chain, p) - task.total_length, 0.0, 0.0)
        f = ca.sum1(ca.sum2(S)) / (N * max(task.total_length or 1.0, 1e-3)) if cover else _dh_length(chain, p)
        x = ca.vertcat(p, ca.vec(Q), ca.vec(S))
        self.bounds = np.array([par.bounds for par in chain.parameters.values()])
        self.lbx = np.concatenate([self.bounds[:, 0], np.tile(chain.lower, N), np.zeros(S.numel())])
        self.ubx = np.concatenate([self.bounds[:, 1], np.tile(chain.upper, N), np.full(S.numel(), np.inf)])
        self.lbg, self.ubg = lbg, ubg
        opts = {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes", "ipopt.max_iter": max_iter,
                "ipopt.max_cpu_time": max_time, "ipopt.tol": 1e-9, "ipopt.acceptable_tol": 1e-6}
        self.solver = ca.nlpsol("design", "ipopt", {"x": x, "f": f, "g": ca.vertcat(*g) if g else ca.SX(0, 1)}, opts)

    def solve(self, p0: np.ndarray, q0: np.ndarray) -> NlpStart:
        """One IPOPT run from design p0 (n_p,) and configurations q0 (N, n); SI throughout."""
        robot, chain, targets = self.task.robot, self.task.robot.chain, self.task.targets
        N, n, npar = self.N, self.n, self.npar
        b = self.bounds
        x0 = np.concatenate([np.clip(p0, b[:, 0], b[:, 1]), np.clip(q0, chain.lower, chain.upper).ravel(),
                             np.zeros(len(self.lbx) - npar - n * N)])
        if self.cover:   # initial slack: the initial residuals, so the start is feasible
            pos = robot.fk(np.clip(q0, chain.lower, chain.upper), params=np.clip(p0, b[:, 0], b[:, 1]))[:, :3, 3]
            x0[npar + n * N:] = np.abs(pos - targets.positions).ravel()
        t0 = time.perf_counter()
        sol = self.solver(x0=x0, lbx=self.lbx, ubx=self.ubx, lbg=self.lbg, ubg=self.ubg)
        dt = time.perf_counter() - t0
        st = self.solver.stats()
        it = st.get("iterations", {})
        xs = np.array(sol["x"]).ravel()
        return NlpStart(p0=np.asarray(p0, float), p=xs[:npar], objective=float(sol["f"]),
                        success=bool(st["success"]), status=str(st["return_status"]),
                        iterations=int(st.get("iter_count", len(it.get("obj", [])))), time_s=dt,
                        history=[float(v) for v in it.get("obj", [])],
                        constraint_violation=[float(v) for v in it.get("inf_pr", [])],
                        q=xs[npar:npar + n * N].reshape(N, n))


def solve_nlp(task: Task, p0: np.ndarray, q0: np.ndarray, margin: float = 2e-3, max_iter: int = 1000,
              max_time: float = 120.0) -> NlpStart:
    """One IPOPT run from design p0 (n_p,) and configurations q0 (N, n) (builds the NLP each call;
    use :class:`DesignNlp` for many starts)."""
    return DesignNlp(task, margin, max_iter, max_time).solve(p0, q0)
