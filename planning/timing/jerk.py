"""Jerk limits for :func:`planning.timing.time_parameterize` (``j_max``), a pass over the minimum-time
profile of the speed and acceleration limits (TOPP-RA has none).

What is guaranteed.  The trajectory's s̈ is constant on each grid interval, so q̈ jumps at grid
points (and the blends' q″ jumps at piece boundaries): a continuous jerk does not exist.  What is
bounded is the jerk of the trajectory sampled at its grid times t_i: for every joint j,

    |q̈_j(t_{i+1}⁺) − q̈_j(t_i⁺)| ≤ j_max_j · (t_{i+1} − t_i),

q̈(t_i⁺) the value on the interval starting at grid point i (at the end, the last interval's), and
the same from rest (q̈ = 0) to grid point 0 and from the last grid point back to q̈ = 0, over the
first and last intervals.  A controller that takes the grid samples and interpolates q̈ linearly in
time sees |q⃛| ≤ j_max.  The bound depends on the grid (a finer grid means shorter Δt for the jump of
q″ at a blend's ends, so a slower passage there).  The speed and acceleration limits still hold on
the whole continuous trajectory (every row of :mod:`planning.timing.stages`).

How.  q̈ at a grid point is linear in b (q̈_i = q′_i·a_i + q″_i·b_i, a_i = (b_{i+1} − b_i)/(2h_i)), so
each change of q̈ is D·b over three consecutive b; Δt of interval k, φ_k(b) = 2h_k/(√b_k + √b_{k+1}),
is convex in b.  The rows |D·b| ≤ j_max·φ_k(b) are a convex function below another one; the
convex-concave procedure replaces φ_k by its tangent at a reference profile b̂ — below φ_k
everywhere, equal at b̂ — which makes them linear and only stronger.  Each pass minimises the exact
duration T(b) = Σ φ_k(b) (convex) under those rows and the stage rows by a primal-dual interior-point
method with pentadiagonal Newton systems (``jerk_ipm.c``, compiled like the reachability passes;
:mod:`planning.timing.jerk_numpy` without a compiler, the same method).  Every pass's result meets
the true rows and is feasible for the next pass (its tangent is exact there), so T never increases;
the passes stop when T improves by less than :data:`PASS_TOL`.  The first reference is the
speed/acceleration profile scaled by one factor so that it meets the jerk rows (q̈ scales with c, Δt
with c^(−1/2): the ratio with c^(3/2)).  The result is scaled by one factor ≤ 1 against rounding and
its jerk ratio re-computed from its own Δt (:func:`jerk_ratio`).  Near rest (long first and last
intervals) the bound lets q̈ step by j_max·Δt at once, so the duration can be a little shorter than
the continuous S-curve's (4–5 % in the one-joint tests).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sps

from planning.timing.native import load_jerk
from planning.timing.reachability import half_planes
from planning.timing.stages import Stages
from planning.timing.trajectory import BlendedPath, TimingError

__all__ = ["jerk_limit", "jerk_ratio", "interval_times", "jerk_windows", "PASSES", "PASS_TOL", "NEWTON_MAX"]

#: convex-concave passes at most
PASSES = 30
#: the passes stop when the duration improves by less than this (relative)
PASS_TOL = 1e-4
#: Newton iterations of the interior-point method per pass at most
NEWTON_MAX = 200


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


def change_intervals(K: int) -> np.ndarray:
    """The interval (K+2,) over which each change of q̈ happens: the first and last intervals for the
    changes from and back to rest, the interval between the two grid points otherwise."""
    return np.r_[0, np.arange(K), K - 1]


def jerk_windows(D: sps.csr_matrix, K: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The rows of D on windows of three consecutive b: first column jc0 (K+2,) of change m (min(max(m −
    1, 0), K − 2)) and coefficients jd (K+2, n, 3).  Needs K ≥ 2."""
    jc0 = np.clip(np.arange(K + 2) - 1, 0, K - 2)
    C = D.tocoo()
    m = C.row // n
    pos = C.col - jc0[m]
    if np.any((pos < 0) | (pos > 2)):
        raise AssertionError("a change of q̈ spans more than three grid points")
    jd = np.zeros((K + 2, n, 3))
    np.add.at(jd, (m, C.row % n, pos), C.data)
    return jc0.astype(np.int64), jd


def interval_times(st: Stages, b: np.ndarray) -> np.ndarray:
    """Δt (K,) of every grid interval, exact for b linear in s: 2h/(√b_i + √b_{i+1})."""
    sq = np.sqrt(np.maximum(b, 0.0))
    with np.errstate(divide="ignore"):
        return 2 * st.h / (sq[:-1] + sq[1:])


def jerk_ratio(D: sps.csr_matrix, b: np.ndarray, dt: np.ndarray, jmax: np.ndarray) -> float:
    """Largest |Δq̈_j|/(j_max_j·Δt) of profile b with interval times dt."""
    n = len(jmax)
    dq = np.abs(D @ b).reshape(-1, n)
    return float(np.max(dq / (jmax[None, :] * dt[change_intervals(len(dt))][:, None])))


def _stage_rows(st: Stages, prune) -> tuple[np.ndarray, ...]:
    """The stage half-planes a·b_i + c·b_{i+1} ≤ r (r > 0) as (iv, a, c, r), those that cannot bind
    dropped when ``prune`` (``rmt_prune``) is given, and the box bound xcap (K+1,)."""
    A, C, R, off, xcap = half_planes(st)
    iv = np.repeat(np.arange(st.K + 1), np.diff(np.r_[off, len(A)])).astype(np.int64)
    if prune is not None and len(A):
        keep = np.zeros(len(A), dtype=np.uint8)
        m = int(np.max(np.diff(off), initial=0)) + 4
        wx, wy = np.empty(2 * m), np.empty(2 * m)
        prune(st.K, off.ctypes.data, A.ctypes.data, C.ctypes.data, R.ctypes.data, xcap.ctypes.data,
              keep.ctypes.data, wx.ctypes.data, wy.ctypes.data)
        k = keep.astype(bool)
        iv, A, C, R = iv[k], A[k], C[k], R[k]
    return (np.ascontiguousarray(iv), np.ascontiguousarray(A), np.ascontiguousarray(C), np.ascontiguousarray(R),
            xcap)


def jerk_limit(st: Stages, b0: np.ndarray, bp: BlendedPath, jmax: np.ndarray,
               backend: str = "auto") -> tuple[np.ndarray, float, str]:
    """Profile b (K+1,) meeting every row of ``st`` and the jerk rows of the module docstring, from the
    minimum-time profile ``b0`` of the speed/acceleration problem (meeting every row of ``st``), its
    jerk ratio (≤ 1) and the backend used (``"c"`` or ``"numpy"``; ``backend`` as for
    :func:`planning.timing.reachability.reach`)."""
    n, K = len(jmax), st.K
    free = st.ub > 0
    if K < 2 or not np.all(b0[free] > 0):
        raise TimingError(f"the jerk pass needs a profile moving on every interval ({K} grid intervals): "
                          "limits too tight for the grid or a degenerate path")
    D = _jerk_matrix(st, bp, n)
    kch = change_intervals(K).astype(np.int64)
    jc0, jd = jerk_windows(D, K, n)
    # the first reference: b0 scaled to meet the jerk rows (the ratio scales with c^(3/2))
    r0 = jerk_ratio(D, b0, interval_times(st, b0), jmax)
    ref = np.ascontiguousarray(b0 * (0.999 * min(1.0, r0 ** (-2.0 / 3.0))))
    fns = None if backend == "numpy" else load_jerk()
    if fns is None and backend == "c":
        raise TimingError("backend 'c' needs a C compiler (set CC or RMTKIT_CC)")
    h = np.ascontiguousarray(st.h)
    fr = free.astype(np.uint8)
    jm = np.ascontiguousarray(jmax, dtype=float)
    if fns is not None:
        run, prune = fns
        iv, A, C, R, xcap = _stage_rows(st, prune)
        b = ref.copy()
        info = np.zeros(4)
        status = run(K, n, h.ctypes.data, fr.ctypes.data, xcap.ctypes.data, len(A), iv.ctypes.data, A.ctypes.data,
                     C.ctypes.data, R.ctypes.data, jc0.ctypes.data, jd.ctypes.data, kch.ctypes.data, jm.ctypes.data,
                     b.ctypes.data, PASSES, PASS_TOL, NEWTON_MAX, info.ctypes.data)
        used = "c"
    else:
        from planning.timing.jerk_numpy import jerk_passes

        iv, A, C, R, xcap = _stage_rows(st, None)
        b, status = jerk_passes(h, free, xcap, iv, A, C, R, jc0, jd, kch, jm, ref, PASSES, PASS_TOL, NEWTON_MAX)
        used = "numpy"
    if status != 0:
        raise TimingError(f"the jerk pass failed (status {status}, {K} grid intervals)")
    # exact feasibility despite rounding: the stage rows scale with c, the jerk ratio with c^(3/2)
    b = np.minimum(np.maximum(b, 0.0), np.where(free, np.inf, 0.0))
    r = jerk_ratio(D, b, interval_times(st, b), jmax)
    b = b * min(st.residual_scale(b), 1.0, r ** (-2.0 / 3.0) if r > 0 else 1.0)
    dt = interval_times(st, b)
    if not np.all(np.isfinite(dt)):
        raise TimingError(f"the jerk pass left the path at rest over an interval ({K} grid intervals): "
                          "j_max too small for the grid")
    return b, jerk_ratio(D, b, dt, jmax), used
