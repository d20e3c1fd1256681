"""Proofs that straight joint-space segments stay out of point-set windows.

A point-set window (:class:`planning.windows.PointSetWindow`, the window of a singular component
found numerically) holds every configuration whose distance, over the window's joints J, to the
nearest of its points c_i is at most the width w.  Over J a straight segment q(t) = a + t·(b − a),
t ∈ [0, 1], is a straight segment x(t) = x_a + t·d, and the window is the union of the balls
B(c_i, w), so "the segment is clear" is decided exactly by segment–point distances, without
sampling:

    dist(c, segment) = ‖x_a + t*·d − c‖,  t* = clamp((c − x_a)·d / (d·d), 0, 1),

and the segment meets B(c, w) on the interval t ∈ [t* − h, t* + h] ∩ [0, 1] (h = √((w² − δ²)/d·d),
δ the distance from c to the segment's line) when δ ≤ w.  Only points that can be that close are
looked at: the segment is cut into pieces of length at most :data:`PIECE_WIDTHS` × the enclosing
radius, and the points within (half the piece) + (the enclosing radius) of a piece's midpoint come
from the window's KD-tree (``query_ball_point``) — any ball that meets the piece has its centre there.

With ``normals`` and ``radius`` (a hypersurface: each point stands for the disc of radius r_i about
c_i in the plane normal to n_i, and the distance is to the nearest disc,
:func:`kin.singular.numeric.sampled_distance`) the window is enclosed: a configuration within w of
disc i lies in the ball B(c_i, w + r_i) and in the slab |n_i·(x − c_i)| ≤ w (both follow from the
distance's formula as written, √((n·Δ)² + max(‖Δ_t‖ − r, 0)²) ≤ w, whatever the rounding of n).
The segment meets that convex enclosure on an interval of t found in closed form (a quadratic and a
linear inequality).  The enclosure is a true superset of the window — of every disc's neighbourhood,
and ``contains`` looks only at the 16 nearest discs, so at a subset of those — and reaches at most
(√2 − 1)·w ≈ 0.41·w beyond the union of the discs' w-neighbourhoods (at the rim of a disc).

Every test carries a slack of :data:`SLACK` (joint units): a segment is *proven clear* when every
enclosure it is compared with is missed by more than the slack, so that rounding (about 10⁻¹⁵ here)
can never turn a state of the segment into one that ``contains`` calls inside.  Where an enclosure
is met, a *violation* is looked for and reported only when ``window.contains`` itself says the state
is inside: for balls, the first entry into each ball met (moved 10⁻⁹ inwards) and its deepest point;
for discs, the entry into the disc's neighbourhood and the point nearest the disc (golden-section
search on the convex distance along the segment, then bisection).  The earliest such state is the
violation, the first state inside the window up to 10⁻⁹ for balls.  A segment that meets an
enclosure where no state is confirmed inside (a graze within the slack, or a disc's enclosure met
beside the disc) is *unproven* — never reported as clear; callers then sample it (``check_path``) or
reject it (the planner).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["PointSetProof", "PointSetProver", "certify_point_set", "segment_clear", "SLACK", "PIECE_WIDTHS",
           "MAX_PAIRS"]

#: a segment is proven clear of a ball or slab only when it misses it by more than this (rad or m)
SLACK = 1e-9
#: pieces of a segment are at most this many times the enclosing radius long (w, or w + max r)
PIECE_WIDTHS = 8.0
#: a segment is cut into at most this many pieces (longer pieces only mean more candidate points)
MAX_PIECES_PER_SEGMENT = 64
#: segment–point pairs examined at once at most (a memory bound: pieces are queried in chunks)
MAX_PAIRS = 2_000_000
#: iterations of the golden-section search and of the bisection along a disc's enclosure
SEARCH_STEPS = 60
#: how far (rad or m) a ball's entry state is moved inwards before ``contains`` is asked
INWARD = 1e-9


@dataclass
class PointSetProof:
    """Result of :func:`certify_point_set` for one window and one path: ``violation`` — (segment,
    t, depth) of the first state found inside (``contains`` says so; depth = w − distance, joint
    units), or None; ``unproven`` — segments neither proven clear nor refuted (before the violation's
    segment, or all when there is none); ``pairs`` — segment–point pairs examined."""

    violation: tuple[int, float, float] | None
    unproven: list[int] = field(default_factory=list)
    pairs: int = 0


def _columns(window) -> np.ndarray:
    return np.array([j - 1 for j in window.joints], dtype=int)


def _enclosing(window) -> tuple[np.ndarray | None, float]:
    """(per-point enclosing radius (K,) or None for plain balls of the width, the largest one)."""
    if window.radius is None or window.normals is None:
        return None, float(window.width)
    R = float(window.width) + window.radius
    return R, float(R.max()) if len(R) else float(window.width)


def _pieces(X: np.ndarray, Y: np.ndarray, piece: float):
    """Cut the segments X[k] → Y[k] (m, d) into pieces no longer than ``piece`` (at most
    :data:`MAX_PIECES_PER_SEGMENT` each) → (segment index, t0, t1) per piece."""
    length = np.sqrt(((Y - X) ** 2).sum(axis=1))
    count = np.clip(np.ceil(length / piece), 1, MAX_PIECES_PER_SEGMENT).astype(int)
    seg = np.repeat(np.arange(len(X)), count)
    first = np.concatenate([[0], np.cumsum(count)[:-1]])
    k = np.arange(len(seg)) - first[seg]
    return seg, k / count[seg], (k + 1) / count[seg]


def _candidates(window, X, Y, seg, t0, t1, R_max: float):
    """Segment–point pairs (segment index, point index) whose point may lie within its enclosing
    radius of the piece, in chunks of at most about :data:`MAX_PAIRS` pairs."""
    tree = window.tree
    per_chunk = max(1, MAX_PAIRS // max(len(window.points), 1))
    for s in range(0, len(seg), per_chunk):
        sg, a, b = seg[s:s + per_chunk], t0[s:s + per_chunk], t1[s:s + per_chunk]
        D = Y[sg] - X[sg]
        mid = X[sg] + (0.5 * (a + b))[:, None] * D
        half = 0.5 * (b - a) * np.sqrt((D * D).sum(axis=1))
        r = (half + R_max + SLACK) * (1 + 1e-12) + 1e-12
        lists = tree.query_ball_point(mid, r)
        counts = np.fromiter((len(x) for x in lists), dtype=np.int64, count=len(lists))
        if counts.sum() == 0:
            continue
        yield np.repeat(sg, counts), np.concatenate([np.asarray(x, dtype=np.int64) for x in lists if len(x)])


def _enclosure_hits(window, X, Y, sp, pt, R):
    """For pairs (segment sp, point pt): the interval [lo, hi] ⊂ [0, 1] of t where the segment is
    within the enclosure of the point (ball, and slab for a disc) grown by :data:`SLACK`; ``hit``
    where it is not empty.  Also the line's nearest parameter and squared distance for balls."""
    A, D = X[sp], Y[sp] - X[sp]
    E = A - window.points[pt]                          # x(t) − c = E + t·D
    dd = (D * D).sum(axis=1)
    ed = (E * D).sum(axis=1)
    moving = dd > 0
    tl = np.where(moving, -ed / np.where(moving, dd, 1.0), 0.0)       # the line's nearest parameter
    F = E + tl[:, None] * D
    line2 = (F * F).sum(axis=1)                                       # squared distance to the line
    Rp = window.width if R is None else R[pt]
    Rs = Rp + SLACK
    half = np.sqrt(np.maximum(Rs * Rs - line2, 0.0) / np.where(moving, dd, 1.0))
    lo = np.where(moving, tl - half, 0.0)
    hi = np.where(moving, tl + half, 1.0)
    inside_line = line2 <= Rs * Rs
    if R is not None:                                  # the disc's slab |n·(x − c)| ≤ w
        N = window.normals[pt]
        h0, h1 = (N * E).sum(axis=1), (N * D).sum(axis=1)
        ws = window.width + SLACK
        flat = np.abs(h1) <= 1e-300
        with np.errstate(divide="ignore", invalid="ignore"):
            s0, s1 = (-ws - h0) / h1, (ws - h0) / h1
        slo = np.where(flat, np.where(np.abs(h0) <= ws, 0.0, 2.0), np.minimum(s0, s1))
        shi = np.where(flat, np.where(np.abs(h0) <= ws, 1.0, -1.0), np.maximum(s0, s1))
        lo, hi = np.maximum(lo, slo), np.minimum(hi, shi)
    lo, hi = np.maximum(lo, 0.0), np.minimum(hi, 1.0)
    hit = inside_line & (lo <= hi)
    return hit, lo, hi, tl, line2, dd


def _disc_distance(window, X, Y, sp, pt, t):
    """Distance from x(t) on segment sp to disc pt (the formula of ``sampled_distance``)."""
    Dl = X[sp] + t[:, None] * (Y[sp] - X[sp]) - window.points[pt]
    h = (Dl * window.normals[pt]).sum(axis=1)
    tang = np.sqrt(np.maximum((Dl * Dl).sum(axis=1) - h * h, 0.0))
    return np.sqrt(h * h + np.maximum(tang - window.radius[pt], 0.0) ** 2)


def _disc_candidates(window, X, Y, sp, pt, lo, hi):
    """Two parameters per disc pair met by its enclosure: the point of [lo, hi] nearest the disc
    (golden-section search: the distance to a convex set is convex along a line) and the entry into
    the disc's w-neighbourhood before it (bisection: one crossing, as the distance falls up to there)."""
    def f(t):
        return _disc_distance(window, X, Y, sp, pt, t)

    g = (math.sqrt(5) - 1) / 2
    a, b = lo.copy(), hi.copy()
    for _ in range(SEARCH_STEPS):
        c, d = b - g * (b - a), a + g * (b - a)
        left = f(c) <= f(d)
        a, b = np.where(left, a, c), np.where(left, d, b)
    tmin = 0.5 * (a + b)
    out, inn = lo.copy(), tmin.copy()          # distance > w at `out` (unless lo is inside), ≤ w at `inn`
    for _ in range(SEARCH_STEPS):
        mid = 0.5 * (out + inn)
        ins = f(mid) <= window.width
        out, inn = np.where(ins, out, mid), np.where(ins, mid, inn)
    return np.where(f(lo) <= window.width, lo, inn), tmin


def _ball_candidates(window, lo, tl, line2, dd):
    """Two parameters per ball pair met: the entry into the ball of radius w itself (moved
    :data:`INWARD` inwards, not past the deepest point) and the deepest point of the segment."""
    w = float(window.width)
    moving = dd > 0
    half = np.sqrt(np.maximum(w * w - line2, 0.0) / np.where(moving, dd, 1.0))
    deepest = np.clip(tl, 0.0, 1.0)
    entry = np.maximum(np.where(moving, tl - half, 0.0), 0.0)
    step = INWARD / np.sqrt(np.where(moving, dd, 1.0))
    entry = np.where(entry > 0, np.minimum(entry + step, deepest), entry)
    return np.minimum(entry, deepest), deepest


def _settled(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Segments the proof can work on (m,): coordinates finite and below 10¹⁵⁰ (no product
    overflows); any other segment is left unproven."""
    with np.errstate(invalid="ignore"):
        return (np.abs(X) < 1e150).all(axis=1) & (np.abs(Y) < 1e150).all(axis=1)


def certify_point_set(window, P: np.ndarray, first_only: bool = True) -> PointSetProof:
    """Prove every straight segment of the path P (M, n), SI, clear of the point-set ``window``, or
    find the first state inside it.  See the module docstring.  ``first_only=False`` goes on past the
    first violating segment (every segment is then settled or listed as unproven)."""
    P = np.asarray(P, dtype=float)
    if len(P) == 1:
        P = np.vstack([P, P])
    m = len(P) - 1
    if len(window.points) == 0:
        return PointSetProof(None)
    cols = _columns(window)
    X, Y = P[:-1][:, cols], P[1:][:, cols]
    R, R_max = _enclosing(window)
    ok = _settled(X, Y)
    open_seg = ~ok                                     # met by an enclosure (or not workable)
    best_t = np.full(m, np.inf)                        # earliest state confirmed inside, per segment
    pairs = 0
    seg, t0, t1 = _pieces(X[ok], Y[ok], PIECE_WIDTHS * max(R_max, SLACK))
    seg = np.nonzero(ok)[0][seg]
    for sp, pt in _candidates(window, X, Y, seg, t0, t1, R_max):
        key = np.unique(sp * len(window.points) + pt)          # a point near two pieces: once
        sp, pt = key // len(window.points), key % len(window.points)
        pairs += len(sp)
        hit, lo, hi, tl, line2, dd = _enclosure_hits(window, X, Y, sp, pt, R)
        if not hit.any():
            continue
        sp, pt, lo, hi, tl, line2, dd = sp[hit], pt[hit], lo[hit], hi[hit], tl[hit], line2[hit], dd[hit]
        open_seg[sp] = True
        if R is None:
            ta, tb = _ball_candidates(window, lo, tl, line2, dd)
        else:
            ta, tb = _disc_candidates(window, X, Y, sp, pt, lo, hi)
        T = np.concatenate([ta, tb])
        S = np.concatenate([sp, sp])
        inside = window.contains(P[S] + T[:, None] * (P[S + 1] - P[S]))
        if inside.any():
            np.minimum.at(best_t, S[inside], T[inside])
    found = np.isfinite(best_t)
    unproven = open_seg & ~found
    violation = None
    if found.any():
        k = int(np.argmax(found))
        t = float(best_t[k])
        q = P[k] + t * (P[k + 1] - P[k])
        violation = (k, t, float(-window.distance_out(q[None])[0]))
        if first_only:
            unproven[k:] = False
    return PointSetProof(violation, [int(s) for s in np.nonzero(unproven)[0]], pairs)


class PointSetProver:
    """A point-set window prepared for many motion checks (the planner's): :meth:`clear` decides one
    straight motion with one KD-tree query and, only when points are near, one numpy batch."""

    def __init__(self, window):
        self.window = window
        self.cols = _columns(window)
        self.R, self.R_max = _enclosing(window)
        self.piece = PIECE_WIDTHS * max(self.R_max, SLACK)
        self.tree = window.tree if len(window.points) else None
        self.per_query = max(1, MAX_PAIRS // max(len(window.points), 1))      # pieces per KD-tree query

    def excess(self, q) -> float:
        """0 exactly when ``window.contains(q)`` at one configuration (n,), else a positive number:
        ``window.excess(q)`` (distance − width) when a point lies within width + 10⁻⁶ of q, +inf
        when none does (one ``query_ball_point``, about four times cheaper than a nearest-point
        query: the planner's state check)."""
        if self.tree is None:
            return math.inf
        if self.R is None and not self.tree.query_ball_point(np.asarray(q, dtype=float)[self.cols],
                                                             self.window.width + 1e-6):
            return math.inf
        return self.window.excess(np.asarray(q, dtype=float))

    def clear(self, a: np.ndarray, b: np.ndarray) -> bool:
        """True only when the straight motion a → b (configurations (n,), SI, numpy arrays) is proven
        clear of the window (see the module docstring); False when it enters the window or the proof
        cannot settle it."""
        if self.tree is None:
            return True
        x, y = a[self.cols], b[self.cols]
        if not (-1e150 < x.min() and x.max() < 1e150 and -1e150 < y.min() and y.max() < 1e150):
            return False                                  # not workable (or NaN): unproven
        d = y - x
        length = math.sqrt(float(d @ d))
        k = min(max(math.ceil(length / self.piece), 1), MAX_PIECES_PER_SEGMENT)
        r = (0.5 * length / k + self.R_max + SLACK) * (1 + 1e-12) + 1e-12
        if k == 1:
            near = self.tree.query_ball_point(x + 0.5 * d, r)
            return not near or not self._hits(x, y, np.asarray(near, dtype=np.int64))
        mids = x + ((np.arange(k) + 0.5) / k)[:, None] * d
        for s in range(0, k, self.per_query):             # at most about MAX_PAIRS candidates at once
            lists = self.tree.query_ball_point(mids[s:s + self.per_query], r)
            if any(lists) and self._hits(x, y, np.unique(np.concatenate(
                    [np.asarray(v, dtype=np.int64) for v in lists if v]))):
                return False
        return True

    def _hits(self, x: np.ndarray, y: np.ndarray, pt: np.ndarray) -> bool:
        """Whether the segment x → y (over the window's joints) meets the enclosure of a point of pt."""
        return bool(_enclosure_hits(self.window, x[None], y[None], np.zeros(len(pt), np.int64), pt, self.R)[0].any())


def segment_clear(window, a, b) -> bool:
    """True only when the straight motion a → b (configurations (n,), SI) is proven clear of the
    point-set ``window`` (see the module docstring); False when it enters the window or the proof
    cannot settle it.  For many motions, prepare the window once: :class:`PointSetProver`."""
    return PointSetProver(window).clear(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
