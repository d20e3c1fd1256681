"""Jerk limits for :func:`planning.timing.time_parameterize` (``j_max``), a post-pass over the
minimum-time profile of the speed and acceleration limits (TOPP-RA has none).

What is guaranteed.  The trajectory's s̈ is constant on each grid interval, so q̈ jumps at grid
points and a continuous jerk does not exist; what is bounded is the jerk the *samples* show: for
consecutive samples k, k+1 of the returned :class:`~planning.timing.trajectory.TimedTrajectory`
(grid points and piece boundaries, ``qdd`` the value on the segment starting there) and every joint,

    |q̈_j(t_{k+1}) − q̈_j(t_k)| ≤ j_max_j · (t_{k+1} − t_k),

and the same from rest (q̈ = 0) to the first sample and from the last sample back to q̈ = 0 over the
first and last intervals.  A controller that interpolates the sampled q̈ linearly in time therefore
sees |q⃛| ≤ j_max.  The speed and acceleration limits still hold on the whole continuous trajectory.

How.  Each sample's q̈ is linear in b (q̈_k = q′_k·a_i + q″_k·b(s_k), a_i = (b_{i+1} − b_i)/(2h_i)),
but Δt is not.  With Δt taken from a reference profile b̂, the rows above are linear, and the
problem — every row of :mod:`planning.timing.stages`, the jerk rows, 0 ≤ b ≤ b̂ — is an LP, solved
by HiGHS (``scipy.optimize.linprog``) with the objective the time linearised at b̂.  Every feasible
b is ≤ b̂ pointwise when b̂ is the greatest element of the speed/acceleration problem (the first
pass), so its own Δt are ≥ those of b̂ and its jerk rows hold a fortiori.  Later passes re-linearise
at the previous result (its Δt are longer, the rows looser); a result whose own jerk ratio r exceeds 1
is scaled by r^(−2/3) (q̈ scales with c, Δt with c^(−1/2)).  The fastest verified profile is kept.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sps
from scipy.optimize import linprog

from planning.timing.qp import row_matrix
from planning.timing.stages import Stages, sample_profile
from planning.timing.trajectory import BlendedPath, TimingError

__all__ = ["jerk_limit", "jerk_ratio", "PASSES", "LP_TIME_LIMIT"]

#: linearisation passes at most (the first one is always feasible and verified)
PASSES = 4
#: seconds HiGHS may spend on one LP
LP_TIME_LIMIT = 60.0


def _qdd_rows(st: Stages, bp: BlendedPath) -> tuple[sps.csr_matrix, np.ndarray]:
    """Q (S·n, K+1) with the samples' q̈ = Q·b (row k·n + j: sample k, joint j), and the samples' s."""
    ks, kp, ki = st.samples(bp.length)
    _, d1, d2 = bp.evaluate(ks, kp)
    h = st.h[ki]
    th = np.clip((ks - st.s[ki]) / h, 0.0, 1.0)[:, None]
    alpha = -d1 / (2 * h[:, None]) + d2 * (1 - th)
    gamma = d1 / (2 * h[:, None]) + d2 * th
    S, n = d1.shape
    rows = np.arange(S * n)
    cols = np.repeat(ki, n)
    Q = sps.csr_matrix((np.r_[alpha.ravel(), gamma.ravel()], (np.r_[rows, rows], np.r_[cols, cols + 1])),
                       shape=(S * n, st.K + 1))
    return Q, ks


def _jerk_matrix(st: Stages, bp: BlendedPath, n: int) -> sps.csr_matrix:
    """D (J, K+1): the changes of the sampled q̈ — from 0 to sample 0, between consecutive samples,
    from the last sample to 0 — row-major (change m, joint j)."""
    Q, ks = _qdd_rows(st, bp)
    S = len(ks)
    E = sps.diags([np.ones(S), -np.ones(S)], [0, -1], shape=(S + 1, S), format="csr")   # q̈_k − q̈_{k−1}
    return (sps.kron(E, sps.identity(n), format="csr") @ Q).tocsr()


def _dt_per_change(t: np.ndarray) -> np.ndarray:
    """Time over which each change of q̈ happens: the first and last intervals for the changes from
    and back to rest, the interval between the two samples otherwise."""
    dt = np.diff(t)
    return np.r_[dt[0], dt, dt[-1]]


def jerk_ratio(D: sps.csr_matrix, b: np.ndarray, t: np.ndarray, jmax: np.ndarray) -> float:
    """Largest |Δq̈_j|/(j_max_j·Δt) of profile b with sample times t."""
    n = len(jmax)
    dq = np.abs(D @ b).reshape(-1, n)
    return float(np.max(dq / (jmax[None, :] * _dt_per_change(t)[:, None])))


def jerk_limit(st: Stages, b0: np.ndarray, bp: BlendedPath, jmax: np.ndarray) -> tuple[np.ndarray, float]:
    """Profile b (K+1,) meeting every row of ``st`` and the jerk rows of the module docstring, from the
    minimum-time profile ``b0`` of the speed/acceleration problem, and its jerk ratio (≤ 1)."""
    n = len(jmax)
    A = row_matrix(st)
    fu, fl = np.isfinite(st.up), np.isfinite(st.lo)
    A_rows = sps.vstack([A[fu], -A[fl]], format="csr")
    r_rows = np.r_[st.up[fu], -st.lo[fl]]
    D = _jerk_matrix(st, bp, n)
    bounds = np.c_[np.zeros(st.K + 1), np.minimum(st.ub, b0)]
    ref = b0
    t_ref = sample_profile(st, ref, bp)[0]
    best, best_T, best_r = None, np.inf, np.inf
    for _ in range(PASSES):
        lim = (jmax[None, :] * _dt_per_change(t_ref)[:, None]).ravel()
        # objective: the time Σ 2h/(√b_i + √b_{i+1}) linearised at the reference profile
        sq = np.sqrt(np.maximum(ref, 1e-9 * max(float(ref.max()), 1e-300)))
        w = 2 * st.h / (sq[:-1] + sq[1:]) ** 2
        g = np.zeros(st.K + 1)
        g[:-1] -= w / (2 * sq[:-1])
        g[1:] -= w / (2 * sq[1:])
        g /= np.max(np.abs(g))
        res = linprog(g, A_ub=sps.vstack([A_rows, D, -D], format="csr"), b_ub=np.r_[r_rows, lim, lim],
                      bounds=bounds, method="highs", options={"time_limit": LP_TIME_LIMIT})
        if res.status != 0 or res.x is None:
            if best is not None:
                break
            raise TimingError(f"the jerk-limit LP failed: {res.message} ({st.K} grid intervals)")
        b = np.clip(res.x, 0.0, bounds[:, 1])
        # exact feasibility: the stage rows and the jerk rows are homogeneous in b
        dq = np.abs(D @ b)
        b = b * min(st.residual_scale(b), 1.0 / max(float(np.max(dq / lim)), 1.0))
        try:
            t = sample_profile(st, b, bp)[0]
        except TimingError:
            break
        r = jerk_ratio(D, b, t, jmax)
        if r > 1.0:
            b = b * r ** (-2.0 / 3.0) * (1 - 1e-12)
            t = sample_profile(st, b, bp)[0]
            r = jerk_ratio(D, b, t, jmax)
        improved = t[-1] < best_T * (1 - 1e-3)
        if t[-1] < best_T and r <= 1.0 + 1e-9:
            best, best_T, best_r = b, float(t[-1]), r
        if not improved:
            break
        ref, t_ref = b, t
    return best, best_r
