"""Interval arithmetic over the expressions of singular factors, vectorised over boxes.

A singular factor g is a sum of products of numbers, sin and cos of linear combinations of the
joint variables (and, for prismatic joints, the joint variables themselves).  :func:`compile_interval`
turns its sympy expression into a function that takes a batch of boxes in joint space, ``lo`` and
``hi`` of shape (B, n), and returns ``(glo, ghi)`` of shape (B,) with glo ≤ g(q) ≤ ghi for every q
in each box.  The enclosure is rigorous up to floating-point rounding, which is covered by widening
every result by a few ulps of its magnitude (see :data:`ROUNDING`), and the results of sin and cos
by a few ulps of their argument's magnitude.

Supported nodes: numbers, symbols q1…qn, ``+``, ``*``, integer powers, ``sin``, ``cos``; anything
else raises :class:`IntervalError` (the caller then falls back to sampling and says so).
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np
import sympy as sp

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


def compile_interval(expr: sp.Expr, symbols: tuple[sp.Symbol, ...]) -> IntervalFn:
    """An interval evaluator of ``expr`` over boxes in the variables ``symbols`` (see the module
    docstring).  Raises :class:`IntervalError` for an unsupported node."""
    index = {s: i for i, s in enumerate(symbols)}

    def build(e) -> IntervalFn:
        if e.is_Number:
            v = float(e)
            if not math.isfinite(v):
                raise IntervalError(f"non-finite number {e} in a factor")
            return lambda lo, hi, v=v: _widen(np.full(len(lo), v), np.full(len(lo), v))
        if e.is_Symbol:
            if e not in index:
                raise IntervalError(f"unknown variable {e} in a factor")
            i = index[e]
            return lambda lo, hi, i=i: (lo[:, i], hi[:, i])
        if e.is_Add:
            parts = [build(a) for a in e.args]

            def add(lo, hi, parts=parts):
                rs = [p(lo, hi) for p in parts]
                return _widen(sum(r[0] for r in rs), sum(r[1] for r in rs))
            return add
        if e.is_Mul:
            parts = [build(a) for a in e.args]

            def mul(lo, hi, parts=parts):
                alo, ahi = parts[0](lo, hi)
                for p in parts[1:]:
                    blo, bhi = p(lo, hi)
                    alo, ahi = _mul(alo, ahi, blo, bhi)
                return alo, ahi
            return mul
        if e.is_Pow:
            base, ex = e.args
            if not (ex.is_Integer and int(ex) >= 0):
                raise IntervalError(f"power {ex} in a factor (only non-negative integer powers are supported)")
            b = build(base)
            k = int(ex)
            return lambda lo, hi, b=b, k=k: _pow(*b(lo, hi), k)
        if isinstance(e, (sp.sin, sp.cos)):
            inner = build(e.args[0])
            f = sin_interval if isinstance(e, sp.sin) else cos_interval
            return lambda lo, hi, inner=inner, f=f: f(*inner(lo, hi))
        raise IntervalError(f"unsupported operation {type(e).__name__} in a factor")

    fn = build(sp.expand(expr, trig=False) if expr.is_Add else expr)

    def evaluate(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lo = np.asarray(lo, dtype=float)
        hi = np.asarray(hi, dtype=float)
        glo, ghi = fn(lo, hi)
        return np.broadcast_to(glo, (len(lo),)).copy(), np.broadcast_to(ghi, (len(lo),)).copy()
    return evaluate
