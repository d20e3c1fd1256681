"""The geometric joint path that :func:`planning.timing.time_parameterize` times: waypoints thinned
(:func:`simplify_path`) and joined by quadratic Bézier pieces (:func:`blend_path`, :class:`BlendedPath`),
parameterised by joint-space arc length s.

Corners.  A piecewise-linear joint path has corners where q′ jumps; passing one at non-zero speed
would need an infinite acceleration, so without blending the path must stop there.  By default every
corner is cut by a quadratic Bézier blend: the curve leaves the first segment at distance r before
the waypoint and joins the next segment at distance r after it, with the waypoint as control point
(r = min(``blend``, half of either adjacent segment)).  Parameterised over a length 2r, the path is
C¹ in s (q′ continuous, unit length on the lines) and q″ is piecewise constant, so the trajectory
does not stop at corners; the blend passes the waypoint at joint-space distance ≤ r/2 (reported as
``max_deviation``; a collinear waypoint is passed exactly).  With ``blend=0`` the path is followed
exactly and the trajectory stops at every corner (b = 0 there).  Consecutive duplicate waypoints are
dropped, and a dense path (the samples of a smooth curve, e.g. a path follower's output) is first
thinned by Ramer–Douglas–Peucker with tolerance ``simplify`` (default 1e-4 rad): the tiny corners
between consecutive samples are artefacts of the sampling, and thinning keeps the QP small and well
conditioned.

SI units throughout: rad for revolute joints, m for prismatic ones.
"""
from __future__ import annotations

import math

import numpy as np

from planning.timing.trajectory import BlendedPath, TimingError

__all__ = ["blend_path", "simplify_path"]



def simplify_path(path, tolerance: float) -> np.ndarray:
    """Ramer–Douglas–Peucker in joint space: the fewest waypoints (a subset, ends and reversals kept)
    such that every dropped waypoint lies within ``tolerance`` (rad or m, Euclidean) of the simplified
    polyline.  The
    ranges still to split are processed together, one numpy pass per level of the recursion."""
    W = np.asarray(path, dtype=float)
    if len(W) <= 2 or tolerance <= 0:
        return W.copy()
    keep = np.zeros(len(W), bool)
    keep[0] = keep[-1] = True
    # a reversal (the path turns back by more than 90° between steps longer than the tolerance) is
    # kept: the classic distance test would drop a point lying on the chord it came along, and a
    # zig-zag back and forth along one line would collapse to a single segment
    step = np.diff(W, axis=0)
    long_ = np.linalg.norm(step, axis=1) > tolerance
    turn = np.einsum("ij,ij->i", step[:-1], step[1:]) < 0
    keep[1:-1] |= turn & long_[:-1] & long_[1:]
    at = np.flatnonzero(keep)
    lo, hi = at[:-1], at[1:]
    while len(lo):
        lens = hi - lo - 1
        inner = lens > 0
        lo, hi, lens = lo[inner], hi[inner], lens[inner]
        if not len(lo):
            break
        seg = np.repeat(np.arange(len(lo)), lens)              # range of every interior point
        starts = np.cumsum(lens) - lens
        idx = lo[seg] + 1 + np.arange(len(seg)) - starts[seg]
        a = W[lo[seg]]
        d = W[hi[seg]] - a
        X = W[idx] - a
        L2 = np.einsum("ij,ij->i", d, d)
        u = np.where(L2 > 0, np.clip(np.einsum("ij,ij->i", X, d) / np.where(L2 > 0, L2, 1.0), 0.0, 1.0), 0.0)
        dist = np.linalg.norm(X - u[:, None] * d, axis=1)
        mx = np.maximum.reduceat(dist, starts)
        pos = np.flatnonzero(dist == mx[seg])                  # the first farthest point of every range
        _, first = np.unique(seg[pos], return_index=True)
        m = idx[pos[first]]
        split = mx > tolerance
        keep[m[split]] = True
        lo, hi = np.r_[lo[split], m[split]], np.r_[m[split], hi[split]]
    return W[keep]


def blend_path(path, blend: float = 0.05, simplify: float = 1e-4) -> BlendedPath:
    """Pieces of a piecewise-linear joint path (M, n) with every corner cut by a quadratic Bézier of
    half-length r = min(``blend``, half of each adjacent segment); ``blend=0`` keeps the corners (the
    trajectory will stop at them).  The waypoints are first thinned by :func:`simplify_path` with
    tolerance ``simplify`` (0: keep them all) — on a dense path, the corners between consecutive
    samples of a smooth curve are artefacts of the sampling.  See the module docstring."""
    W = np.asarray(path, dtype=float)
    if W.ndim != 2 or len(W) < 1 or W.shape[1] < 1:
        raise TimingError(f"path has shape {W.shape}; expected (M, n) joint waypoints with M ≥ 1")
    if not np.all(np.isfinite(W)):
        raise TimingError("path holds NaN or infinite values")
    if not (math.isfinite(blend) and blend >= 0):
        raise TimingError(f"blend = {blend!r} must be a finite number ≥ 0 (rad or m, joint-space distance)")
    if not (math.isfinite(simplify) and simplify >= 0):
        raise TimingError(f"simplify = {simplify!r} must be a finite number ≥ 0 (rad or m, joint-space distance)")
    keep = np.r_[True, np.linalg.norm(np.diff(W, axis=0), axis=1) > 1e-12]
    W = simplify_path(W[keep], simplify)
    n = W.shape[1]
    if len(W) == 1:
        return BlendedPath(np.zeros((0, 3, n)), np.zeros(0), np.zeros(0), np.zeros(0), 0.0, W)
    D = np.diff(W, axis=0)
    L = np.linalg.norm(D, axis=1)
    U = D / L[:, None]
    M = len(W)
    total = float(L.sum())
    r = np.zeros(M)            # cut at each interior waypoint
    r[1:-1] = np.minimum(blend, 0.5 * np.minimum(L[:-1], L[1:]))
    # candidate pieces in path order: line 0, blend 1, line 1, blend 2, …, line M−2
    A = W[:-1] + r[:-1, None] * U
    B = W[1:] - r[1:, None] * U
    seg = np.linalg.norm(B - A, axis=1)
    lines = np.stack([A, 0.5 * (A + B), B], axis=1)                              # (M−1, 3, n)
    Wc, rc = W[1:-1], r[1:-1, None]
    blends = np.stack([Wc - rc * U[:-1], Wc, Wc + rc * U[1:]], axis=1)            # (M−2, 3, n)
    cand = np.empty((2 * M - 3, 3, n))
    cand[0::2], cand[1::2] = lines, blends
    ell = np.empty(2 * M - 3)
    ell[0::2], ell[1::2] = seg, 2 * r[1:-1]
    keep_p = np.empty(2 * M - 3, bool)
    keep_p[0::2], keep_p[1::2] = seg > 1e-9 * total, r[1:-1] > 0
    ends = np.cumsum(np.where(keep_p, ell, 0.0))          # s at the end of every candidate
    # an unblended corner (r = 0) where the direction changes is a stop, at the end of the line before it
    corner = (r[1:-1] <= 0) & (np.linalg.norm(U[1:] - U[:-1], axis=1) > 1e-9)
    stops = ends[0::2][:-1][corner]
    dev = float(np.max(np.linalg.norm(0.25 * (blends[:, 0] - 2 * blends[:, 1] + blends[:, 2]), axis=1)[r[1:-1] > 0],
                       initial=0.0))                      # |B(½) − P1|
    pieces, ells = cand[keep_p], ell[keep_p]
    s0s = np.r_[0.0, np.cumsum(ells)[:-1]]
    # every original waypoint lies within ``simplify`` of the simplified polyline, and the blends stay
    # within ``dev`` of it near the corners: their sum bounds the deviation
    return BlendedPath(pieces, s0s, ells, stops,
                       dev + (simplify if len(W) < len(keep) else 0.0), W)
