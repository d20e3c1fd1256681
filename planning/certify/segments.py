"""Proofs that straight joint-space segments stay out of singular windows.

A sampled check looks at finitely many states and can miss a segment that grazes a window between
two of them.  Here each segment q(t) = a + t·(b − a), t ∈ [0, 1], is proven clear of each window:

* an interval window on joint j (q_j ∈ [lo, hi]): q_j is linear in t, so whether the segment meets
  an interval — and where it enters first — is decided exactly;
* a window |g(q)| ≤ ε: the piece [t0, t1] of the segment lies in the box spanned by q(t0) and
  q(t1) (q is linear), and interval arithmetic (:mod:`planning.certify.intervals`) bounds g on that
  box.  If the bound excludes [−ε, ε] the piece is proven clear; if g at the piece's midpoint is
  inside the window a violation is found; otherwise the piece is halved.  Pieces still open after
  ``max_depth`` halvings (a segment touching the window's boundary tangentially) are reported as
  unproven, never as clear;
* a point-set window (every configuration within w of a sampled point, over the window's joints):
  the segment is decided by its distances to the points near it, found with the window's KD-tree
  (:mod:`planning.certify.points`; discs are enclosed by a ball and a slab).  A segment that meets
  an enclosure where no state is confirmed inside is reported as unproven.

The pieces of every segment of a path are processed together as one numpy batch per window.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from kin.errors import ConfigurationError
from kin.singular.expression import parse_tree
from kin.singular.tree import Node
from planning.certify.intervals import IntervalError, compile_interval
from planning.certify.points import certify_point_set

__all__ = ["SegmentViolation", "PathProof", "certify_path", "MAX_DEPTH", "MAX_PIECES"]

#: halvings of a segment before a piece is left unproven (2⁻⁴⁰ of the segment)
MAX_DEPTH = 40
#: pieces evaluated per window and path at most (a budget: beyond it the rest is unproven)
MAX_PIECES = 2_000_000


@dataclass(frozen=True)
class SegmentViolation:
    """A state inside a window: segment ``segment`` (its first row), at fraction ``t`` of it,
    configuration ``q`` (SI), window ``window`` (its name), ``depth`` = ε − |g| (how far inside;
    for an interval window the joint distance to the interval's nearer end, for a point-set window
    the width minus the distance to the nearest point)."""

    segment: int
    t: float
    q: np.ndarray
    window: str
    depth: float


@dataclass
class PathProof:
    """Result of :func:`certify_path`: ``proven`` — every segment was proven clear of every window
    (the path is valid by proof); ``violation`` — the first state found inside a window (None when
    none); ``unproven`` — (segment, window) pairs neither proven nor refuted; ``pieces`` — boxes
    evaluated (and segment–point pairs examined); ``methods`` — per window name, ``"exact"``
    (interval windows), ``"interval"`` (proof by interval arithmetic), ``"distance"`` (a point-set
    window of a numeric component: segment–point distances, :mod:`planning.certify.points`) or
    ``"sampled"`` (the expression is not supported: not proven)."""

    proven: bool
    violation: SegmentViolation | None
    unproven: list[tuple[int, str]] = field(default_factory=list)
    pieces: int = 0
    methods: dict[str, str] = field(default_factory=dict)


def window_expression(window) -> Node:
    """The expression tree of a non-interval window's factor g (in q1…qn; :mod:`kin.singular.tree`),
    read by the safe grammar of :mod:`kin.singular.expression` (the window's own when it has one)."""
    tree = None if getattr(window, "is_point_set", False) else getattr(window, "tree", None)
    return tree if isinstance(tree, Node) else parse_tree(window.expr, window.n, f"window {window.name!r}")


def _interval_window(window, P: np.ndarray) -> SegmentViolation | None:
    """First entry of the path's segments into an interval window (exact; None when none)."""
    j = window.joint
    a, b = P[:-1, j], P[1:, j]
    best = None
    for lo, hi in window.intervals:
        smin, smax = np.minimum(a, b), np.maximum(a, b)
        hit = (smax >= lo) & (smin <= hi)
        if not hit.any():
            continue
        k = int(np.argmax(hit))
        d = b[k] - a[k]
        if lo <= a[k] <= hi:
            t = 0.0
        else:
            t = float(((lo if d > 0 else hi) - a[k]) / d)
        t = min(max(t, 0.0), 1.0)
        cand = (k, t, lo, hi)
        if best is None or (cand[0], cand[1]) < (best[0], best[1]):
            best = cand
    if best is None:
        return None
    k, t, lo, hi = best
    q = P[k] + t * (P[k + 1] - P[k])
    q[j] = min(max(q[j], lo), hi)            # the entry lies on the interval's end (no rounding outside)
    depth = float(min(q[j] - lo, hi - q[j]))
    return SegmentViolation(k, t, q, window.name, max(depth, 0.0))


def _predicate_window(window, fn, P: np.ndarray, max_depth: int, max_pieces: int):
    """(first violation or None, unproven segment indices, pieces evaluated) for a |g| ≤ ε window."""
    eps = float(window.epsilon)
    m = len(P) - 1
    A, D = P[:-1], P[1:] - P[:-1]
    seg = np.arange(m)
    t0 = np.zeros(m)
    t1 = np.ones(m)
    depth = 0
    pieces = 0
    found: tuple[int, float, float] | None = None      # (segment, t, |g| - eps)
    unproven: set[int] = set()
    # the rows themselves
    g_ends = np.abs(window.g(P)) - eps
    inside_ends = np.nonzero(g_ends <= 0)[0]
    if len(inside_ends):
        r = int(inside_ends[0])
        found = (r, 0.0, float(g_ends[r])) if r < m else (m - 1, 1.0, float(g_ends[r]))
    while len(seg):
        if found is not None:                          # only pieces that could come earlier matter
            keep = (seg < found[0]) | ((seg == found[0]) & (t0 < found[1]))
            seg, t0, t1 = seg[keep], t0[keep], t1[keep]
            if not len(seg):
                break
        qa = A[seg] + t0[:, None] * D[seg]
        qb = A[seg] + t1[:, None] * D[seg]
        lo, hi = np.minimum(qa, qb), np.maximum(qa, qb)
        glo, ghi = fn(lo, hi)
        pieces += len(seg)
        open_ = ~((glo > eps) | (ghi < -eps))
        seg, t0, t1 = seg[open_], t0[open_], t1[open_]
        if not len(seg):
            break
        tm = 0.5 * (t0 + t1)
        gm = np.abs(window.g(A[seg] + tm[:, None] * D[seg])) - eps
        bad = np.nonzero(gm <= 0)[0]
        if len(bad):
            order = np.lexsort((tm[bad], seg[bad]))
            i = bad[order[0]]
            cand = (int(seg[i]), float(tm[i]), float(gm[i]))
            if found is None or cand[:2] < found[:2]:
                found = cand
        depth += 1
        if depth > max_depth or pieces + 2 * len(seg) > max_pieces:
            unproven.update(int(s) for s in seg)
            break
        seg = np.repeat(seg, 2)
        t0, t1 = np.column_stack([t0, tm]).ravel(), np.column_stack([tm, t1]).ravel()
    if found is None:
        return None, sorted(unproven), pieces
    k, t, margin = found
    q = P[k] + t * (P[k + 1] - P[k]) if m else P[0]
    return SegmentViolation(k, t, q, window.name, -margin), sorted(u for u in unproven if u < k), pieces


def certify_path(windows, path, max_depth: int = MAX_DEPTH, max_pieces: int = MAX_PIECES) -> PathProof:
    """Prove a joint path (M, n), SI, clear of every window of ``windows`` (a WindowSet), or find
    the first state inside one.  See the module docstring."""
    P = np.asarray(path, dtype=float)
    if P.ndim != 2 or len(P) == 0 or (windows is not None and P.shape[1] != windows.n):
        n = "n" if windows is None else windows.n
        raise ConfigurationError(f"path has shape {P.shape}; expected (M, {n}) with M ≥ 1")
    if not np.isfinite(P).all():
        raise ConfigurationError("path holds NaN or infinite values")
    proof = PathProof(True, None)
    if windows is None or not windows.windows:
        return proof
    if len(P) == 1:
        P = np.vstack([P, P])
    violations = []
    for w in windows.windows:
        if w.is_interval:
            proof.methods[w.name] = "exact"
            v = _interval_window(w, P)
            if v is not None:
                violations.append(v)
            continue
        if getattr(w, "is_point_set", False):         # a numeric component: no formula, its points
            proof.methods[w.name] = "distance"
            pp = certify_point_set(w, P)
            proof.pieces += pp.pairs
            proof.unproven.extend((k, w.name) for k in pp.unproven)
            if pp.violation is not None:
                k, t, depth = pp.violation
                violations.append(SegmentViolation(k, t, P[k] + t * (P[k + 1] - P[k]), w.name, depth))
            continue
        try:
            fn = compile_interval(window_expression(w))
        except IntervalError:
            proof.methods[w.name] = "sampled"
            proof.unproven.extend((k, w.name) for k in range(len(P) - 1))
            continue
        proof.methods[w.name] = "interval"
        v, unproven, pieces = _predicate_window(w, fn, P, max_depth, max_pieces)
        proof.pieces += pieces
        proof.unproven.extend((k, w.name) for k in unproven)
        if v is not None:
            violations.append(v)
    if violations:
        proof.violation = min(violations, key=lambda v: (v.segment, v.t))
        first = (proof.violation.segment, proof.violation.t)
        proof.unproven = [(k, name) for k, name in proof.unproven if k < first[0]]
    proof.proven = proof.violation is None and not proof.unproven
    return proof
