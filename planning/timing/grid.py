"""The default grid of :func:`planning.timing.time_parameterize`: uniform over the whole path, refined
so that every piece of the path (straight segment, corner blend, spline span) is resolved.

A uniform grid of path length / K leaves a path of many short pieces — a zig-zag of 200 short
rest-to-rest moves, say — with one or two intervals per piece, and the minimum time on such a grid
is far above the true one (b = ṡ² is linear on every interval, and the switch from accelerating to
braking falls between grid points).  :func:`default_grid` therefore keeps the uniform points and,
in every piece that holds fewer than :data:`MIN_INTERVALS_PER_PIECE` of its intervals, replaces
them by that many equal intervals of the piece (its ends become grid points).  A path whose every
piece already holds that many intervals keeps the uniform grid exactly.  The refinement is bounded
by a budget on the total number of intervals: the per-piece minimum is lowered to fit it (down to
one interval per piece — the piece boundaries become grid points), and dropped when not even that
fits.

SI units: s is joint-space arc length (rad or m)."""
from __future__ import annotations

import numpy as np

from planning.timing.trajectory import BlendedPath

__all__ = ["default_grid", "MIN_INTERVALS_PER_PIECE"]

#: every piece of the path (segment, blend, spline span) gets at least this many grid intervals from
#: the default grid (fewer only when the budget does not allow it)
MIN_INTERVALS_PER_PIECE = 16


def default_grid(bp: BlendedPath, K: int, budget: int, per_piece: int = MIN_INTERVALS_PER_PIECE) -> np.ndarray | None:
    """Grid points from 0 to ``bp.length``: ``K`` uniform intervals, with every piece holding fewer
    than ``per_piece`` of them divided into ``per_piece`` equal intervals instead; at most ``budget``
    intervals in all (``per_piece`` lowered to fit, at least 1).  None when the uniform grid needs no
    refinement (or none fits the budget): then the caller's uniform grid is used unchanged."""
    L = bp.length
    if L <= 0 or len(bp.ell) == 0:
        return None
    uniform = np.linspace(0.0, L, K + 1)
    ends = np.r_[bp.s0, L]
    # uniform intervals overlapping each piece, approximately: its length over the uniform step, + 1
    held = np.floor(bp.ell / (L / K)).astype(np.int64) + 1
    short = np.flatnonzero((held < per_piece) & (bp.ell > 1e-12 * L))
    if not len(short):
        return None
    k = per_piece
    while k >= 1:
        if K + k * len(short) <= budget:
            break
        k //= 2
    if k < 1:
        return None
    a, b = ends[short], ends[short + 1]
    step = (b - a) / k
    lo_i = np.searchsorted(uniform, a - 0.5 * step, side="left")
    hi_i = np.searchsorted(uniform, b + 0.5 * step, side="right")
    cover = np.zeros(len(uniform) + 1, np.int64)
    np.add.at(cover, lo_i, 1)
    np.add.at(cover, hi_i, -1)
    inside = np.cumsum(cover[:-1]) > 0               # uniform points inside (or near) a refined piece
    inside[0] = inside[-1] = False
    fine = (a[:, None] + step[:, None] * np.arange(k + 1)[None, :]).ravel()
    s = np.unique(np.r_[uniform[~inside], fine])
    s = s[(s >= 0.0) & (s <= L)]
    s = s[np.r_[True, np.diff(s) > 1e-12 * max(L, 1.0)]]
    s[0], s[-1] = 0.0, L
    return s
