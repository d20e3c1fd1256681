"""Bounds of a singular factor over the whole joint box, proven by interval arithmetic.

A window |g(q)| ≤ ε of half-width w must hold every configuration within joint distance w of the
zero set of g.  If G bounds ‖∇g‖ over the joint box B (the joint limits), the mean value theorem
gives, for a zero z and any q in B with ‖q − z‖ ≤ w (the segment between them lies in B, a box is
convex): |g(q)| = |g(q) − g(z)| ≤ G·‖q − z‖ ≤ G·w.  So ε = w·G is a proof, not a first-order
estimate, and it depends on nothing but g, B and w.

:func:`gradient_bound` finds G by branch and bound over boxes: each box gets a rigorous upper bound
of ‖∇g‖ (the interval enclosures of the partial derivatives, :mod:`planning.certify.intervals`)
and a value attained at its centre; boxes whose upper bound exceeds the best attained value by
more than ``rel_tol`` are halved along their widest joint, until none is left or the box budget is
spent.  The answer is the largest upper bound among the boxes it kept — a proven bound, within
``rel_tol`` of the true maximum when the budget sufficed — and the search is deterministic: no
sample, seed or clock enters it.

:func:`zero_free` proves, the same way, that g has no zero in the box (the factor's singular set
lies outside the joint limits).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kin.errors import ConfigurationError
from kin.singular.evaluate import batch_function
from kin.singular.tree import Node, derivative, variables
from planning.certify.intervals import compile_interval

__all__ = ["GradientBound", "gradient_bound", "zero_free", "REL_TOL", "MAX_BOXES"]

#: the bound is within this share of the attained maximum of ‖∇g‖ (when the box budget suffices)
REL_TOL = 1e-3
#: boxes evaluated at most by one search (a budget: past it the bound is still proven, only looser)
MAX_BOXES = 400_000
#: relative widening of the norm computed from the partials' enclosures (a few float operations)
NORM_ROUNDING = 1e-12
#: boxes halved per round of the best-first search
BATCH = 2048


@dataclass(frozen=True)
class GradientBound:
    """``bound``: G ≥ ‖∇g(q)‖ for every q in the box (proven); ``attained``: ‖∇g‖ at ``at`` (a
    configuration of the box, SI), so bound ≥ max ‖∇g‖ ≥ attained; ``boxes``: boxes evaluated;
    ``converged``: bound ≤ attained·(1 + rel_tol) (False when the budget ran out first)."""

    bound: float
    attained: float
    at: tuple[float, ...]
    boxes: int
    converged: bool


def _as_tree(expr, n: int) -> Node:
    """The expression tree of ``expr`` (a tree already, or a sympy expression in q1…qn)."""
    if isinstance(expr, Node):
        return expr
    from kin.singular.expression import joint_symbols
    from kin.singular.tree_sympy import from_sympy
    return from_sympy(expr, joint_symbols(n))


def _split(lo: np.ndarray, hi: np.ndarray, cols: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Halve every box along its widest joint of ``cols``: (2B, n) boxes, each box's halves adjacent."""
    width = (hi - lo)[:, cols]
    axis = np.asarray(cols)[np.argmax(width, axis=1)]
    rows = np.arange(len(lo))
    mid = 0.5 * (lo[rows, axis] + hi[rows, axis])
    lo2, hi2 = np.repeat(lo, 2, axis=0), np.repeat(hi, 2, axis=0)
    hi2[2 * rows, axis] = mid
    lo2[2 * rows + 1, axis] = mid
    return lo2, hi2


def _start(lower, upper, n: int) -> tuple[np.ndarray, np.ndarray]:
    lo = np.asarray(lower, dtype=float).reshape(1, n).copy()
    hi = np.asarray(upper, dtype=float).reshape(1, n).copy()
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo <= hi)):
        raise ConfigurationError("the joint box needs finite limits with lower ≤ upper")
    return lo, hi


def gradient_bound(expr, n: int, lower, upper, rel_tol: float = REL_TOL,
                   max_boxes: int = MAX_BOXES) -> GradientBound:
    """A proven bound of ‖∇g‖ over the box [lower, upper] (SI, (n,)), g an expression tree
    (:mod:`kin.singular.tree`) or a sympy expression in q1…qn.  Raises
    :class:`~planning.certify.intervals.IntervalError` when g holds an operation that interval
    arithmetic does not support.  See the module docstring."""
    tree = _as_tree(expr, n)
    cols = sorted(variables(tree))
    lo, hi = _start(lower, upper, n)
    if not cols:
        return GradientBound(0.0, 0.0, tuple(float(x) for x in 0.5 * (lo[0] + hi[0])), 0, True)
    partials = [derivative(tree, k) for k in cols]
    enclose = [compile_interval(p) for p in partials]
    values = [batch_function(p) for p in partials]

    def norm_at(Q: np.ndarray) -> np.ndarray:
        return np.sqrt(sum(np.square(v(Q)) for v in values))

    best, best_at, kept, boxes = -1.0, lo[0].copy(), 0.0, 0
    open_lo, open_hi, open_ub = lo[:0], hi[:0], np.zeros(0)
    while len(lo):
        boxes += len(lo)
        mags = [np.maximum(np.abs(a), np.abs(b)) for a, b in (f(lo, hi) for f in enclose)]
        upper_b = np.sqrt(np.sum(np.square(mags), axis=0)) * (1 + NORM_ROUNDING)
        centre = 0.5 * (lo + hi)
        at_centre = norm_at(centre)
        i = int(np.argmax(at_centre))
        if at_centre[i] > best:
            best, best_at = float(at_centre[i]), centre[i].copy()
        open_lo, open_hi = np.concatenate([open_lo, lo]), np.concatenate([open_hi, hi])
        open_ub = np.concatenate([open_ub, upper_b])
        done = open_ub <= best * (1 + rel_tol)
        if done.any():
            kept = max(kept, float(open_ub[done].max()))
            open_lo, open_hi, open_ub = open_lo[~done], open_hi[~done], open_ub[~done]
        if not len(open_ub):
            break
        if boxes + 2 * min(len(open_ub), BATCH) > max_boxes:
            return GradientBound(max(kept, float(open_ub.max())), best, tuple(float(x) for x in best_at), boxes,
                                 False)
        # best first: halve the boxes with the largest upper bounds (they set the bound)
        top = (np.argpartition(-open_ub, BATCH)[:BATCH] if len(open_ub) > BATCH
               else np.arange(len(open_ub)))
        rest = np.ones(len(open_ub), bool)
        rest[top] = False
        lo, hi = _split(open_lo[top], open_hi[top], cols)
        open_lo, open_hi, open_ub = open_lo[rest], open_hi[rest], open_ub[rest]
    return GradientBound(max(kept, best), best, tuple(float(x) for x in best_at), boxes, True)


def zero_free(expr, n: int, lower, upper, max_boxes: int = MAX_BOXES // 4) -> bool:
    """True when g (a tree or a sympy expression in q1…qn) is proven nonzero on the whole box
    [lower, upper]; False when a zero or a sign change was found, or the budget ran out before a
    proof."""
    tree = _as_tree(expr, n)
    cols = sorted(variables(tree))
    lo, hi = _start(lower, upper, n)
    f = batch_function(tree)
    if not cols:
        return float(f(lo)[0]) != 0.0
    enclose = compile_interval(tree)
    sign = None
    boxes = 0
    while len(lo):
        boxes += len(lo)
        glo, ghi = enclose(lo, hi)
        g = f(0.5 * (lo + hi))
        if np.any(g == 0) or not np.all(np.isfinite(g)):
            return False
        s = np.sign(g)
        if sign is None:
            sign = s[0]
        if np.any(s != sign):
            return False
        open_ = ~((glo > 0) | (ghi < 0))
        lo, hi = lo[open_], hi[open_]
        if boxes + 2 * len(lo) > max_boxes:
            return False
        if len(lo):
            lo, hi = _split(lo, hi, cols)
    return True

