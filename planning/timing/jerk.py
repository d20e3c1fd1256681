"""Jerk limits for :func:`planning.timing.time_parameterize` (``j_max``), a post-pass over the
minimum-time profile of the speed and acceleration limits (TOPP-RA has none).

What is guaranteed.  The trajectory's s̈ is constant on each grid interval, so q̈ jumps at grid
points (and the blends' q″ jumps at piece boundaries): a continuous jerk does not exist.  What is
bounded is the jerk of the trajectory sampled at its grid times t_i: for every joint j,

    |q̈_j(t_{i+1}⁺) − q̈_j(t_i⁺)| ≤ j_max_j · (t_{i+1} − t_i),

q̈(t_i⁺) the value on the interval starting at grid point i (at the end, the last interval's), and
the same from rest (q̈ = 0) to grid point 0 and from the last grid point back to q̈ = 0, over the
first and last intervals.  A controller that takes the grid samples and interpolates q̈ linearly in
time sees |q⃛| ≤ j_max.  The bound depends on the grid (a finer grid means shorter Δt for the jump of
q″ at a blend's ends, so a slower passage there).  The speed and acceleration limits still hold on
the whole continuous trajectory.

How.  The q̈ at a grid point is linear in b (q̈_i = q′_i·a_i + q″_i·b_i, a_i = (b_{i+1} − b_i)/(2h_i)),
but Δt is not.  With Δt taken from a reference profile b̂, the rows above are linear, and the
problem — every row of :mod:`planning.timing.stages`, the jerk rows, 0 ≤ b ≤ g·b̂ — is an LP, solved
by HiGHS (``scipy.optimize.linprog``) with the objective the time linearised at b̂.  The bound
b ≤ g·b̂ makes every Δt ≥ Δt(b̂)/√g, so with the rows' right-hand sides divided by √g the result
meets its jerk rows with its own Δt.  The first pass takes b̂ = the speed/acceleration profile and
g = 1; later passes re-linearise at the previous result with g = :data:`GROW` (a trust region), until
the duration improves by less than 0.2 % or :data:`PASSES` / :data:`BUDGET` run out.  Each result is
scaled by one factor ≤ 1 against the LP solver's tolerance (q̈ scales with c, Δt with c^(−1/2)) and
its jerk ratio re-computed; the fastest verified one is kept.  Near rest (long first and last
intervals) the bound lets q̈ step by j_max·Δt at once, so the duration can be a little shorter than
the continuous S-curve's (about 2 % in the one-joint tests).
"""
from __future__ import annotations

import math
import time

import numpy as np
import scipy.sparse as sps
from scipy.optimize import linprog

from planning.timing.qp import row_matrix
from planning.timing.stages import Stages
from planning.timing.trajectory import BlendedPath, TimingError

__all__ = ["jerk_limit", "jerk_ratio", "interval_times", "PASSES", "GROW", "BUDGET"]

#: linearisation passes at most
PASSES = 8
#: after the first pass, b may grow by this factor per pass (a trust region that keeps the rows valid)
GROW = 1.5
#: seconds HiGHS may spend on all passes together
BUDGET = 60.0


def _jerk_matrix(st: Stages, bp: BlendedPath, n: int) -> sps.csr_matrix:
    """D (n·(K+2), K+1): the changes of q̈ at the grid points — from 0 to grid point 0, between
    consecutive grid points, from grid point K back to 0 — row-major (change m, joint j).  q̈ at grid
    point i < K is the value on the interval starting there (q̈ = q′·a_i + q″·b_i, the piece to the
    right); at s_K the end of the last interval."""
    K = st.K
    s = st.s
    piece = np.r_[bp.piece_of(s[:-1], "right"), bp.piece_of(s[-1:], "left")]
    _, d1, d2 = bp.evaluate(s, piece)
    iv = np.r_[np.arange(K), K - 1]
    g = 1.0 / (2 * st.h[iv])[:, None]
    th = np.r_[np.zeros(K), 1.0][:, None]
    alpha = -d1 * g + d2 * (1 - th)            # coefficient of b_iv
    gamma = d1 * g + d2 * th                   # coefficient of b_iv+1
    rows = np.arange((K + 1) * n)
    cols = np.repeat(iv, n)
    Q = sps.csr_matrix((np.r_[alpha.ravel(), gamma.ravel()], (np.r_[rows, rows], np.r_[cols, cols + 1])),
                       shape=((K + 1) * n, K + 1))
    E = sps.diags([np.ones(K + 1), -np.ones(K + 1)], [0, -1], shape=(K + 2, K + 1), format="csr")
    return (sps.kron(E, sps.identity(n), format="csr") @ Q).tocsr()


def interval_times(st: Stages, b: np.ndarray) -> np.ndarray:
    """Δt (K,) of every grid interval, exact for b linear in s: 2h/(√b_i + √b_{i+1})."""
    sq = np.sqrt(np.maximum(b, 0.0))
    with np.errstate(divide="ignore"):
        return 2 * st.h / (sq[:-1] + sq[1:])


def _dt_per_change(dt: np.ndarray) -> np.ndarray:
    """Time over which each change of q̈ happens: the first and last intervals for the changes from
    and back to rest, the interval between the two grid points otherwise."""
    return np.r_[dt[0], dt, dt[-1]]


def jerk_ratio(D: sps.csr_matrix, b: np.ndarray, dt: np.ndarray, jmax: np.ndarray) -> float:
    """Largest |Δq̈_j|/(j_max_j·Δt) of profile b with interval times dt."""
    n = len(jmax)
    dq = np.abs(D @ b).reshape(-1, n)
    return float(np.max(dq / (jmax[None, :] * _dt_per_change(dt)[:, None])))


def jerk_limit(st: Stages, b0: np.ndarray, bp: BlendedPath, jmax: np.ndarray) -> tuple[np.ndarray, float]:
    """Profile b (K+1,) meeting every row of ``st`` and the jerk rows of the module docstring, from the
    minimum-time profile ``b0`` of the speed/acceleration problem, and its jerk ratio (≤ 1)."""
    n = len(jmax)
    A = row_matrix(st)
    fu, fl = np.isfinite(st.up), np.isfinite(st.lo)
    D = _jerk_matrix(st, bp, n)
    A_ub = sps.vstack([A[fu], -A[fl], D, -D], format="csr")
    r_rows = np.r_[st.up[fu], -st.lo[fl]]
    cap = np.minimum(st.ub, b0)
    ref, grow = b0, 1.0            # first pass: b ≤ b0, the greatest element
    best, best_T, best_r = None, np.inf, np.inf
    deadline = time.monotonic() + BUDGET
    for _ in range(PASSES):
        dt_ref = interval_times(st, ref)
        # b ≤ grow·ref ⇒ every Δt ≥ Δt_ref/√grow: the rows below then hold for the result's own Δt
        lim = (jmax[None, :] * _dt_per_change(dt_ref)[:, None]).ravel() / math.sqrt(grow)
        # objective: the time Σ 2h/(√b_i + √b_{i+1}) linearised at the reference profile
        sq = np.sqrt(np.maximum(ref, 1e-9 * max(float(ref.max()), 1e-300)))
        w = 2 * st.h / (sq[:-1] + sq[1:]) ** 2
        g = np.zeros(st.K + 1)
        g[:-1] -= w / (2 * sq[:-1])
        g[1:] -= w / (2 * sq[1:])
        g /= np.max(np.abs(g))
        hi = np.minimum(cap, grow * ref)
        left = deadline - time.monotonic()
        if left <= 0:
            break
        res = linprog(g, A_ub=A_ub, b_ub=np.r_[r_rows, lim, lim], bounds=np.c_[np.zeros(st.K + 1), hi],
                      method="highs", options={"time_limit": left})
        if res.status != 0 or res.x is None:
            if best is not None:
                break
            raise TimingError(f"the jerk-limit LP failed: {res.message} ({st.K} grid intervals)")
        b = np.clip(res.x, 0.0, hi)
        # exact feasibility despite HiGHS's tolerance: b = 0 meets every row and the jerk rows are homogeneous
        b = b * min(st.residual_scale(b), 1.0 / max(float(np.max(np.abs(D @ b) / lim)), 1.0))
        dt = interval_times(st, b)
        if not np.all(np.isfinite(dt)):
            break
        r = jerk_ratio(D, b, dt, jmax)
        T = float(dt.sum())
        if T < best_T and r <= 1.0 + 1e-9:
            improved = T < best_T * (1 - 2e-3)
            best, best_T, best_r = b, T, r
            if not improved:
                break
        else:
            break
        ref, grow = b, GROW
    if best is None:
        raise TimingError(f"the jerk-limit LP left the path at rest over an interval ({st.K} grid intervals): "
                          "j_max too small for the grid")
    return best, best_r
