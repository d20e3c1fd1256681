"""Joint torque limits for :func:`planning.timing.time_parameterize` (``robot=``, ``tau_max=``): the
torque rows of the discretised problem and the dense torque re-check.

The rows.  Along a path q(s) traversed forwards the joint torques are (kin's
:meth:`~kin.Robot.path_torque_coefficients`)

    τ = A(s)·s̈ + B(s)·ṡ² + C(s) + V(s)·ṡ,     A = M·q′, B = M·q″ + c(q, q′), C = g + coulomb·sign(q′),

V = viscous·q′.  At a constraint point of :mod:`planning.timing.stages` (grid interval i, fraction θ)
s̈ = a_i = (b_{i+1} − b_i)/(2h_i) and ṡ² = b(s) = (1 − θ)·b_i + θ·b_{i+1}, so without viscous friction
|τ_j| ≤ τmax_j is one row ``ci·b_i + cj·b_{i+1} ∈ [−τmax_j − C_j, τmax_j − C_j]`` — linear but not
homogeneous (the constant C).  The stage polygons stay convex and contain (0, 0) exactly when
|C_j| ≤ τmax_j, i.e. when the robot can hold the path at rest (:func:`path_model` raises
:class:`TimingError` naming the joint, s and the torque needed otherwise); then c·b with c ∈ [0, 1]
stays feasible for every feasible b (convexity), which the solvers and the scale repair rely on.

Viscous friction V·ṡ = V·√b is not linear in b.  √b is concave, so its tangent at β² > 0 bounds it
from above for every b ≥ 0: 0 ≤ √b ≤ (β + b/β)/2.  Each torque bound is imposed with the side of
V·ṡ that can push it over: for V_j > 0 the upper row gets + V_j·(β + b/β)/2 and the lower row
nothing (V_j·ṡ ≥ 0), and the reverse for V_j < 0 — conservative for any β > 0, exact where
b = β².  β at each point comes from the previous solve (re-linearised every round); it is capped
so that the tangent's offset |V|·β/2 leaves (0, 0) feasible.

What is guaranteed.  The rows hold at the constraint points (both ends of every segment); A, B, C, V
vary nonlinearly between them, so the torque between constraint points is not bounded by them.
The result is therefore re-checked with the actual τ (``Robot.inverse_dynamics`` of q, q̇, q̈ from
the exact s(t)) at :data:`DENSE_TORQUE` + 1 times in every interval between the trajectory's
samples; where |τ_j| exceeds τmax_j by the ratio r in grid interval i, joint j's limit in that
interval's rows is scaled by 1/r and the problem re-solved, at most :data:`ROUNDS` times within
:data:`BUDGET` seconds.  The returned ``max_torque_ratio`` is the dense ratio of the trajectory
returned — ≤ 1 + :data:`TOL` when the rounds sufficed, larger (and reported) otherwise: a dense
sample check, not a proof for every instant.

SI units throughout: N·m for revolute joints, N for prismatic ones.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from planning.timing.limits import dense_times
from planning.timing.stages import Stages
from planning.timing.trajectory import TimingError

__all__ = ["TorqueModel", "torque_limits", "path_model", "torque_rows", "dense_torque", "tighten",
           "DENSE_TORQUE", "ROUNDS", "BUDGET", "TOL"]

#: dense re-check: this many + 1 times per interval between the trajectory's samples
DENSE_TORQUE = 4
#: tightening rounds at most (after the first solve)
ROUNDS = 8
#: seconds the tightening rounds may take together
BUDGET = 30.0
#: relative excess of the dense torque over τmax accepted without another round
TOL = 1e-6


@dataclass
class TorqueModel:
    """The torque coefficients at the constraint points of a :class:`Stages` (records ``ri, rs, rp``):
    ``A, B, C, V`` (R, n) per record (V = viscous·q′), ``tau_max`` (n,) (inf: that joint unlimited)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    V: np.ndarray
    tau_max: np.ndarray

    @property
    def limited(self) -> np.ndarray:
        return np.flatnonzero(np.isfinite(self.tau_max))

    @property
    def viscous(self) -> bool:
        return bool(np.any(self.V[:, self.limited] != 0.0))


def _unit(robot, j: int) -> str:
    return "N·m" if robot.chain.joints[j].is_revolute else "N"


def torque_limits(robot, tau_max, n: int) -> np.ndarray | None:
    """τmax (n,) for ``robot`` (validated): ``tau_max`` (a positive scalar or n of them, N·m or N; inf:
    no limit on that joint) or, when None, the joints' ``max_torque`` where known (inf elsewhere);
    None when no joint is limited.  Raises :class:`TimingError` for a bad value or a robot of another size, and
    :class:`kin.DynamicsError` when the robot has no inertial data."""
    if robot.n != n:
        raise TimingError(f"robot {robot.name} has {robot.n} joints; the path has {n}")
    robot.dynamics                                     # DynamicsError (one line) without inertial data
    if tau_max is None:
        known = [j.max_torque for j in robot.chain.joints]
        if all(v is None for v in known):
            return None
        return np.array([np.inf if v is None else float(v) for v in known])
    arr = np.asarray(tau_max, dtype=float) if not isinstance(tau_max, str) else np.array(np.nan)
    v = np.full(n, float(arr)) if arr.ndim == 0 else arr
    if v.shape != (n,) or np.any(np.isnan(v)) or not np.all(v > 0):
        raise TimingError(f"tau_max {tau_max!r} must be a positive number or {n} of them (N·m or N; inf: "
                          f"no limit on that joint)")
    return None if np.all(np.isinf(v)) else v.astype(float)


def path_model(robot, st: Stages, bp, tau_max: np.ndarray) -> TorqueModel:
    """The :class:`TorqueModel` of ``st`` (one batch call over the distinct constraint points).  Raises
    :class:`TimingError` when some joint cannot hold the path at rest: |C_j| > τmax_j at a point."""
    key = np.c_[st.rs, st.rp.astype(float)]
    uk, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.ravel()
    q, d1, d2 = bp.evaluate(uk[:, 0], uk[:, 1].astype(np.int64))
    A, B, C = robot.path_torque_coefficients(q, d1, d2)
    A, B, C = (np.atleast_2d(x) for x in (A, B, C))
    V = d1 * robot.dynamics.viscous[None, :]
    ratio = np.abs(C) / tau_max[None, :]
    if np.any(ratio > 1.0):
        p, j = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        u = _unit(robot, j)
        raise TimingError(f"joint {j + 1} cannot hold the path at rest: it needs |τ| = {abs(C[p, j]):.4g} {u} "
                          f"(gravity + Coulomb friction) at s = {uk[p, 0]:.4g} but tau_max = {tau_max[j]:.4g} {u}")
    return TorqueModel(A=A[inv], B=B[inv], C=C[inv], V=V[inv], tau_max=tau_max)


def _b_at(st: Stages, b: np.ndarray) -> np.ndarray:
    """b(s) at every record: linear on each grid interval."""
    return (1 - st.theta) * b[st.ri] + st.theta * b[st.ri + 1]


def torque_rows(st: Stages, tm: TorqueModel, w: np.ndarray, b_ref: np.ndarray | None) -> Stages:
    """``st`` with the torque rows of the module docstring added: joint j's limit in grid interval i
    is ``w[i, j]·τmax_j``; viscous friction by the tangent at β = √b_ref(s) (ignored with ``b_ref``
    None — not conservative, only a first estimate)."""
    J = tm.limited
    if not len(J):
        return st
    g = (1.0 / (2 * st.h[st.ri]))[:, None]
    th = st.theta[:, None]
    A, B, C, V = tm.A[:, J], tm.B[:, J], tm.C[:, J], tm.V[:, J]
    ci = -A * g + B * (1 - th)
    cj = A * g + B * th
    lim = w[st.ri][:, J] * tm.tau_max[None, J]
    if b_ref is None or not tm.viscous:
        k = c0 = np.zeros_like(A)
    else:
        bs = _b_at(st, b_ref)
        floor = 1e-9 * np.sqrt(max(float(np.max(b_ref)), 1e-300))
        beta = np.maximum(np.sqrt(np.maximum(bs, 0.0)), floor)[:, None]
        slack = np.maximum(lim - np.abs(C), 0.0)
        with np.errstate(divide="ignore"):
            beta = np.maximum(np.minimum(beta, np.where(V != 0, slack / np.abs(V), np.inf)), 1e-300)
        k = np.abs(V) / (2 * beta)
        c0 = np.abs(V) * beta / 2
    pos, neg = V > 0, V < 0
    kp, km = np.where(pos, k, 0.0), np.where(neg, k, 0.0)
    c0p, c0m = np.where(pos, c0, 0.0), np.where(neg, c0, 0.0)
    r = np.repeat(st.ri, len(J))
    inf = np.full(r.shape, np.inf)
    iv = np.r_[st.iv, r, r]
    o = np.argsort(iv, kind="stable")
    ci_all = np.r_[st.ci, (ci + kp * (1 - th)).ravel(), (ci - km * (1 - th)).ravel()]
    cj_all = np.r_[st.cj, (cj + kp * th).ravel(), (cj - km * th).ravel()]
    lo_all = np.r_[st.lo, -inf, (-lim - C + c0m).ravel()]
    up_all = np.r_[st.up, (lim - C - c0p).ravel(), inf]
    return replace(st, iv=iv[o], ci=ci_all[o], cj=cj_all[o], lo=lo_all[o], up=up_all[o])


def dense_torque(robot, traj, ki: np.ndarray, per: int = DENSE_TORQUE) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The actual τ (inverse dynamics of q, q̇, q̈ from the exact s(t)) at ``per`` + 1 times in every
    interval between the trajectory's samples and at its end: τ (M, n), the grid interval of each
    time (M,) (``ki`` (S,): the grid interval starting at each sample), and τ at the samples (S, n)."""
    t = traj.t
    times = dense_times(t, per)
    q, qd, qdd = traj.sample(times)
    tau = np.atleast_2d(robot.inverse_dynamics(q, qd, qdd))
    S = len(t)
    if S < 2:
        return tau, np.zeros(len(tau), dtype=np.int64), tau
    interval = np.r_[np.repeat(ki[:-1], per + 1), ki[-2]]
    at = np.r_[np.arange(S - 1) * (per + 1), len(times) - 1]
    return tau, interval, tau[at]


def tighten(w: np.ndarray, tau: np.ndarray, interval: np.ndarray, tm: TorqueModel, st: Stages) -> bool:
    """Scale w[i, j] by 1/r where the dense |τ_j|/τmax_j peaks at r > 1 + TOL in grid interval i (at
    most down to 5 % of the headroom over |C_j| left in that interval); False when nothing changed."""
    r = np.abs(tau) / tm.tau_max[None, :]
    worst = np.zeros_like(w)
    np.maximum.at(worst, interval, r)
    rest = np.zeros_like(w)
    np.maximum.at(rest, st.ri, np.abs(tm.C) / tm.tau_max[None, :])
    wmin = rest + 0.05 * (1.0 - rest)
    new = np.where(worst > 1.0 + TOL, np.maximum(w / np.maximum(worst, 1.0) * (1 - 1e-4), wmin), w)
    changed = bool(np.any(new < w * (1 - 1e-12)))
    w[:] = np.minimum(new, w)
    return changed
