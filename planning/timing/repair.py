"""Local repair of the greedy profile where it comes to rest mid-path: :func:`repair_rests`.

TOPP-RA's forward pass (:mod:`planning.timing.reachability`) takes, at every grid point in turn, the
largest b_{i+1} the stage allows from the b_i already chosen.  With speed and acceleration rows on a
grid fine against the path's curvature that is the minimum-time profile; torque rows break it: their
ṡ² terms make some rows bind both ends of an interval from above (a speed-dependent torque), and the
largest b_i that can still reach the end is then often reached only with b_{i+1} = 0 — the greedy
pass takes it and stops the robot where nothing requires a stop.

The repair: around every interior grid point k where the profile is at rest although the point is
not a stop, the profile on a window of grid points k − w … k + w (ends fixed) is replaced by the
solution of two small LPs over every row of every stage touching the window and 0 ≤ b ≤ the stage
box — first the largest b_k, then the largest Σ b_j / cap_j with b_k ≥ 0.9 of that — solved by
HiGHS; of the windows of half-width 4, 8, … :data:`MAX_WINDOW` the one that lets b_k rise the most
is kept. Only rows that involve the window change, the rest of the profile is untouched, so the
result is feasible whenever the LP's is (the caller scales it to meet every row exactly).
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import linprog

from planning.timing.reachability import half_planes
from planning.timing.stages import Stages

__all__ = ["repair_rests", "MAX_WINDOW"]

#: half-width of the first window (grid points) and the largest one
FIRST_WINDOW = 4
MAX_WINDOW = 64


def _window_lp(A, C, R, off, cap, b: np.ndarray, lo_i: int, hi_i: int, k: int) -> np.ndarray | None:
    """b with b[lo_i+1 : hi_i] re-optimised (ends lo_i, hi_i fixed) so that b_k > 0, or None when
    that is impossible or HiGHS fails."""
    var = np.arange(lo_i + 1, hi_i)
    m = len(var)
    rows_a, rows_b = [], []
    for i in range(lo_i, hi_i):                        # stage i: x = b_i, y = b_{i+1}
        sl = slice(off[i], off[i + 1])
        a, c, r = A[sl], C[sl], R[sl]
        coef = np.zeros((len(a), m))
        rhs = r.copy()
        if lo_i < i:
            coef[:, i - lo_i - 1] += a
        else:
            rhs -= a * b[i]
        if i + 1 < hi_i:
            coef[:, i - lo_i] += c
        else:
            rhs -= c * b[i + 1]
        rows_a.append(coef)
        rows_b.append(rhs)
    cw = cap[var]
    A_ub, b_ub = np.vstack(rows_a), np.concatenate(rows_b)
    upper = np.where(np.isfinite(cw), cw, None)
    # first the largest b_k alone (the rest point k), then the most of every b with b_k kept near it:
    # Σ b alone would trade the rest point for its neighbours
    k = k - lo_i - 1
    goal = np.zeros(m)
    goal[k] = -1.0
    first = linprog(goal, A_ub=A_ub, b_ub=b_ub, bounds=np.c_[np.zeros(m), upper], method="highs")
    if first.status != 0 or first.x is None or first.x[k] <= 0:
        return None
    low = np.zeros(m)
    low[k] = 0.9 * first.x[k]
    scale = np.where(np.isfinite(cw) & (cw > 0), cw, max(float(first.x.max()), 1e-12))
    res = linprog(-1.0 / scale, A_ub=A_ub, b_ub=b_ub, bounds=np.c_[low, upper], method="highs")
    if res.status != 0 or res.x is None:
        return None
    out = b.copy()
    out[var] = np.maximum(res.x, 0.0)
    return out


def repair_rests(st: Stages, b: np.ndarray) -> tuple[np.ndarray, int]:
    """``b`` (feasible for every row of ``st``) with its needless rests repaired (module docstring);
    returns the profile and how many rests were repaired."""
    inner = np.flatnonzero((b <= 0) & (st.ub > 0))
    inner = inner[(inner > 0) & (inner < st.K)]
    if not len(inner):
        return b, 0
    A, C, R, off, cap = half_planes(st)
    fixed = 0
    for k in inner:
        if b[k] > 0:                                   # repaired with a neighbour's window
            continue
        best, w = None, FIRST_WINDOW
        while w <= MAX_WINDOW:                          # the window that lets b_k rise the most
            lo_i, hi_i = max(k - w, 0), min(k + w, st.K)
            new = _window_lp(A, C, R, off, cap, b, lo_i, hi_i, k)
            if new is not None and (best is None or new[k] > best[k]):
                best = new
            if lo_i == 0 and hi_i == st.K:
                break
            w *= 2
        if best is not None:
            b = best
            fixed += 1
    return b, fixed
