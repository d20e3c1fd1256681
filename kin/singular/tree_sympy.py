"""Sympy expressions → trees (:mod:`kin.singular.tree`), so that the tree evaluators serve a sympy
expression too (interval arithmetic over a sympy derivative, :mod:`planning.certify.intervals`).
The way back is :func:`kin.singular.expression.to_sympy`."""
from __future__ import annotations

import math

from kin.singular.expression import ExpressionError
from kin.singular.tree import Cos, Node, Num, Sin, Var, add, mul, power

__all__ = ["from_sympy"]


def from_sympy(expr, symbols) -> Node:
    """The tree of a sympy expression in ``symbols`` (q1…qn in order: Var(i) is ``symbols[i]``).

    Numbers become floats; only numbers, the symbols, sums, products, integer powers, sin and cos
    are accepted — anything else (another symbol, exp, sqrt, a non-finite number) raises
    :class:`ExpressionError` naming it.
    """
    index = {s: i for i, s in enumerate(symbols)}

    def build(e) -> Node:
        if e.is_Number:
            try:
                v = float(e)
            except (TypeError, ValueError, OverflowError):
                v = math.nan
            if not math.isfinite(v):
                raise ExpressionError(f"non-finite number {e} in a factor")
            return Num(v)
        if e.is_Symbol:
            if e not in index:
                raise ExpressionError(f"unknown variable {e} in a factor")
            return Var(index[e])
        if e.is_Add:
            return add([build(a) for a in e.args])
        if e.is_Mul:
            return mul([build(a) for a in e.args])
        if e.is_Pow:
            base, ex = e.args
            if not ex.is_Integer:
                raise ExpressionError(f"power {ex} in a factor (only integer powers are supported)")
            return power(build(base), int(ex))
        name = type(e).__name__
        if name in ("sin", "cos") and len(e.args) == 1:
            return (Sin if name == "sin" else Cos)(build(e.args[0]))
        raise ExpressionError(f"unsupported operation {name} in a factor")
    return build(expr)
