"""Interval arithmetic over the expressions of singular factors, vectorised over boxes.

A singular factor g is a sum of products of numbers, sin and cos of linear combinations of the
joint variables (and, for prismatic joints, the joint variables themselves).  :func:`compile_interval`
turns its expression tree (:mod:`kin.singular.tree`, as read by
:func:`kin.singular.expression.parse_tree`) or its sympy expression (converted to a tree first)
into a function that takes a batch of boxes in joint space, ``lo`` and ``hi`` of shape (B, n), and
returns ``(glo, ghi)`` of shape (B,) with glo ≤ g(q) ≤ ghi for every q in each box.  The enclosure
is rigorous up to floating-point rounding, which is covered by widening every result by a few ulps
of its magnitude (see :data:`ROUNDING`), and the results of sin and cos by a few ulps of their
argument's magnitude.

Supported nodes: numbers, symbols q1…qn, ``+``, ``*``, non-negative integer powers, ``sin``,
``cos``; anything else (a division, a negative power) raises :class:`IntervalError` (the caller then
falls back to sampling and says so).  This module does not import sympy: a sympy expression is
only converted (:mod:`kin.singular.tree_sympy`) when one is given.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from kin.singular.tree import Add, Cos, Mul, Node, Num, Pow, Sin, Var
from planning.errors import PlanningError

__all__ = ["IntervalError", "compile_interval", "cos_interval", "sin_interval", "ROUNDING"]

#: relative widening of every interval result, covering the rounding of the few float operations
#: behind each node (each is exact to half an ulp, 2⁻⁵³ ≈ 1.1e-16)
ROUNDING = 4e-16

IntervalFn = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]


class IntervalError(PlanningError):
    """An expression holds a node the interval evaluator does not support."""


def _widen(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    pad = ROUNDING * np.maximum(np.abs(lo), np.abs(hi)) + 1e-300
    return lo - pad, hi + pad


def cos_interval(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Range of cos over [lo, hi] (arrays): the end values, 1 where the interval holds a multiple of
    2π, −1 where it holds an odd multiple of π."""
    clo, chi = np.cos(lo), np.cos(hi)
    out_lo, out_hi = np.minimum(clo, chi), np.maximum(clo, chi)
    k_max = np.ceil(lo / (2 * math.pi))              # smallest k with 2πk ≥ lo
    has_max = 2 * math.pi * k_max <= hi
    k_min = np.ceil((lo - math.pi) / (2 * math.pi))  # smallest k with π + 2πk ≥ lo
    has_min = math.pi + 2 * math.pi * k_min <= hi
    out_hi = np.where(has_max, 1.0, out_hi)
    out_lo = np.where(has_min, -1.0, out_lo)
    wide = (hi - lo) >= 2 * math.pi
    out_lo = np.where(wide, -1.0, out_lo)
    out_hi = np.where(wide, 1.0, out_hi)
    # the argument carries a rounding error of a few ulps of its magnitude (|d cos| ≤ 1 passes it on)
    pad = 4.5e-16 * (np.maximum(np.abs(lo), np.abs(hi)) + 4.0)
    return np.maximum(out_lo - pad, -1.0), np.minimum(out_hi + pad, 1.0)


def sin_interval(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Range of sin over [lo, hi]: sin x = cos(x − π/2)."""
    return cos_interval(lo - math.pi / 2, hi - math.pi / 2)


def _mul(alo, ahi, blo, bhi):
    p = np.stack([alo * blo, alo * bhi, ahi * blo, ahi * bhi])
    return _widen(p.min(axis=0), p.max(axis=0))


def _pow(lo, hi, k: int):
    if k == 0:
        return np.ones_like(lo), np.ones_like(hi)
    a, b = lo ** k, hi ** k
    if k % 2:
        return _widen(a, b)
    low = np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(a, b))
    return _widen(low, np.maximum(a, b))


def _tree(expr, symbols) -> Node:
    """The tree of a sympy expression (expanded when it is a sum, as the factors are printed), or
    :class:`IntervalError` for what a tree cannot hold."""
    import sympy as sp

    from kin.singular.expression import ExpressionError
    from kin.singular.tree_sympy import from_sympy
    if symbols is None:
        raise IntervalError("a sympy expression needs its variables (symbols q1…qn)")
    try:
        return from_sympy(sp.expand(expr, trig=False) if expr.is_Add else expr, tuple(symbols))
    except ExpressionError as e:
        raise IntervalError(str(e)) from None


def _build(e: Node, n: int | None, seen: dict) -> IntervalFn:
    if isinstance(e, Num):
        v = float(e.value)
        if not math.isfinite(v):
            raise IntervalError(f"non-finite number {v} in a factor")
        return lambda lo, hi: _widen(np.full(len(lo), v), np.full(len(lo), v))
    if isinstance(e, Var):
        i = e.index
        if n is not None and not 0 <= i < n:
            raise IntervalError(f"unknown variable q{i + 1} in a factor of {n} variables")
        return lambda lo, hi: (lo[:, i], hi[:, i])
    if isinstance(e, Add):
        parts = [_build(a, n, seen) for a in e.terms]

        def add(lo, hi):
            rs = [p(lo, hi) for p in parts]
            return _widen(sum(r[0] for r in rs), sum(r[1] for r in rs))
        return add
    if isinstance(e, Mul):
        parts = [_build(a, n, seen) for a in e.factors]

        def mul(lo, hi):
            alo, ahi = parts[0](lo, hi)
            for p in parts[1:]:
                blo, bhi = p(lo, hi)
                alo, ahi = _mul(alo, ahi, blo, bhi)
            return alo, ahi
        return mul
    if isinstance(e, Pow):
        if e.exp < 0:
            raise IntervalError(f"power {e.exp} in a factor (only non-negative integer powers are supported)")
        b, k = _build(e.base, n, seen), e.exp
        return lambda lo, hi: _pow(*b(lo, hi), k)
    if isinstance(e, (Sin, Cos)):
        # a factor repeats the same sin and cos many times: each is evaluated once per call
        inner = _build(e.arg, n, seen)
        f = sin_interval if isinstance(e, Sin) else cos_interval
        values = seen["values"]

        def trig(lo, hi, key=e):
            hit = values.get(key)
            if hit is None:
                hit = values[key] = f(*inner(lo, hi))
            return hit
        return trig
    raise IntervalError(f"unsupported operation {type(e).__name__} in a factor")


def compile_interval(expr, symbols=None) -> IntervalFn:
    """An interval evaluator of ``expr`` over boxes (see the module docstring): ``expr`` a tree
    (:mod:`kin.singular.tree`; ``symbols``, when given, only sets the number of variables) or a
    sympy expression in the variables ``symbols`` (q1…qn in the boxes' column order; a sum is
    expanded first).  Raises :class:`IntervalError` for an unsupported node."""
    if isinstance(expr, Node):
        tree = expr
        n = None if symbols is None else len(symbols)
    else:
        tree = _tree(expr, symbols)
        n = len(symbols)
    seen: dict = {"values": {}}
    fn = _build(tree, n, seen)

    def evaluate(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lo = np.asarray(lo, dtype=float)
        hi = np.asarray(hi, dtype=float)
        seen["values"].clear()
        try:
            glo, ghi = fn(lo, hi)
        finally:
            seen["values"].clear()
        return np.broadcast_to(glo, (len(lo),)).copy(), np.broadcast_to(ghi, (len(lo),)).copy()
    return evaluate
