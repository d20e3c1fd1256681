"""Evaluators of a factor's expression tree (:mod:`kin.singular.tree`): :func:`batch_function` for
numpy batches of configurations and :func:`scalar_function` for one configuration as plain floats
(the hot path of a planner's validity checker).

Both are nested closures built from the tree — no source text is generated, compiled or evaluated,
and no sympy is involved.  The scalar closures are specialised for the shapes singular factors
have (sums of a coefficient times sin or cos of a sum of joint variables, products, small powers),
so that a typical factor costs a handful of Python calls.  Division by zero and overflow give what
numpy gives (±inf, nan) in both evaluators, never an exception.
"""
from __future__ import annotations

import math
from operator import itemgetter
from typing import Callable, Sequence

import numpy as np

from kin.singular.tree import Add, Cos, Mul, Node, Num, Pow, Sin, Var

__all__ = ["batch_function", "scalar_function", "BatchFn", "ScalarFn"]

BatchFn = Callable[[np.ndarray], np.ndarray]
ScalarFn = Callable[[Sequence[float]], float]

#: sin/cos of a linear form whose coefficients stay below this cannot see an infinite argument for
#: any joint value a chain has (|q| < 1e200), so the scalar evaluator needs no exception guard there
_SAFE_COEF = 1e100


# ---- numpy batches -----------------------------------------------------------------------------------
def _batch(e: Node) -> Callable:
    if isinstance(e, Num):
        v = e.value
        return lambda Q: v
    if isinstance(e, Var):
        i = e.index
        return lambda Q: Q[:, i]
    if isinstance(e, Add):
        fs = [_batch(t) for t in e.terms]

        def total(Q, fs=fs):
            r = fs[0](Q)
            for f in fs[1:]:
                r = r + f(Q)
            return r
        return total
    if isinstance(e, Mul):
        fs = [_batch(f) for f in e.factors]

        def product(Q, fs=fs):
            r = fs[0](Q)
            for f in fs[1:]:
                r = r * f(Q)
            return r
        return product
    if isinstance(e, Pow):
        b, k = _batch(e.base), e.exp
        if k == 2:
            return lambda Q: np.square(b(Q))
        return lambda Q: np.power(b(Q), float(k))
    if isinstance(e, (Sin, Cos)):
        a, fn = _batch(e.arg), (np.sin if isinstance(e, Sin) else np.cos)
        return lambda Q: fn(a(Q))
    raise TypeError(f"not an expression tree node: {e!r}")


def batch_function(tree: Node) -> BatchFn:
    """g(Q) for a batch Q (N, n) of configurations (SI) → float array (N,) (read-only when g is a
    constant)."""
    f = _batch(tree)

    def g(Q: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            r = f(Q)
        return np.broadcast_to(np.asarray(r, dtype=float), (Q.shape[0],))
    return g


# ---- one configuration, plain floats ----------------------------------------------------------------
def _linear(e: Node) -> tuple[float, list[tuple[float, int]]] | None:
    """(c0, [(c, i), …]) when e = c0 + Σ c·q_i, else None."""
    if isinstance(e, Num):
        return e.value, []
    if isinstance(e, Var):
        return 0.0, [(1.0, e.index)]
    if isinstance(e, Mul) and len(e.factors) == 2 and isinstance(e.factors[0], Num):
        lin = _linear(e.factors[1])
        if lin is None:
            return None
        c = e.factors[0].value
        return c * lin[0], [(c * a, i) for a, i in lin[1]]
    if isinstance(e, Add):
        c0, terms = 0.0, []
        for t in e.terms:
            lin = _linear(t)
            if lin is None:
                return None
            c0 += lin[0]
            terms += lin[1]
        return c0, terms
    return None


def _linear_fn(c0: float, terms: list[tuple[float, int]]) -> ScalarFn:
    if c0 == 0.0 and all(c == 1.0 for c, _ in terms):
        if len(terms) == 1:
            return itemgetter(terms[0][1])
        if len(terms) == 2:
            i, j = terms[0][1], terms[1][1]
            return lambda q: q[i] + q[j]
    if c0 == 0.0 and len(terms) == 2 and terms[0][0] == 1.0 and terms[1][0] == -1.0:
        i, j = terms[0][1], terms[1][1]
        return lambda q: q[i] - q[j]
    if len(terms) == 1:
        (c, i), = terms
        return (lambda q: c * q[i]) if c0 == 0.0 else (lambda q: c * q[i] + c0)

    def lin(q, terms=tuple(terms)):
        s = c0
        for c, i in terms:
            s += c * q[i]
        return s
    return lin


def _trig(e: Node) -> tuple[Callable, tuple[int, ...]] | None:
    """(math.sin or math.cos, joints) when e is sin/cos of one joint or of a sum of two, else None."""
    if not isinstance(e, (Sin, Cos)):
        return None
    lin = _linear(e.arg)
    if lin is None or lin[0] != 0.0 or len(lin[1]) not in (1, 2) or any(c != 1.0 for c, _ in lin[1]):
        return None
    return (math.sin if isinstance(e, Sin) else math.cos), tuple(i for _, i in lin[1])


def _scaled_trig(c: float, fn: Callable, idx: tuple[int, ...]) -> ScalarFn:
    if len(idx) == 1:
        i, = idx
        return (lambda q: fn(q[i])) if c == 1.0 else (lambda q: c * fn(q[i]))
    i, j = idx
    return (lambda q: fn(q[i] + q[j])) if c == 1.0 else (lambda q: c * fn(q[i] + q[j]))


def _scaled(e: Node) -> tuple[float, Callable, tuple[int, ...]] | None:
    """(c, math.sin or math.cos, joints) when e = c·sin or c·cos of one joint or a sum of two."""
    c, f = (e.factors[0].value, e.factors[1]) if isinstance(e, Mul) and len(e.factors) == 2 \
        and isinstance(e.factors[0], Num) else (1.0, e)
    t = _trig(f)
    return None if t is None else (c, *t)


def _pair(t0, t1, k: float) -> ScalarFn:
    """c0·f0(…) + c1·f1(…) + k in one call (the arguments one joint or the sum of two)."""
    (c0, f0, a0), (c1, f1, a1) = t0, t1
    i0, j0 = a0[0], a0[-1]
    i1, j1 = a1[0], a1[-1]
    if len(a0) == 1 and len(a1) == 1:
        return lambda q: c0 * f0(q[i0]) + c1 * f1(q[i1]) + k
    if len(a0) == 1:
        return lambda q: c0 * f0(q[i0]) + c1 * f1(q[i1] + q[j1]) + k
    if len(a1) == 1:
        return lambda q: c0 * f0(q[i0] + q[j0]) + c1 * f1(q[i1]) + k
    return lambda q: c0 * f0(q[i0] + q[j0]) + c1 * f1(q[i1] + q[j1]) + k


def _sum(e: Add) -> ScalarFn:
    """A sum: its scaled sin/cos terms two to a call (:func:`_pair`, with the constant), the other
    terms one call each, added in one more call (which also takes an odd trig term itself)."""
    k = sum(t.value for t in e.terms if isinstance(t, Num))
    trig = [t for t in (_scaled(u) for u in e.terms) if t is not None]
    fs = [_scalar(u) for u in e.terms if not isinstance(u, Num) and _scaled(u) is None]
    for a in range(0, len(trig) - 1, 2):
        fs.insert(a // 2, _pair(trig[a], trig[a + 1], k))
        k = 0.0
    if len(trig) % 2 and len(fs) == 1:          # f(q) + c·sin(…) in the adding call itself
        (c, fn, idx), (f0,) = trig[-1], fs
        if len(idx) == 1:
            i, = idx
            return lambda q: f0(q) + c * fn(q[i]) + k
        i, j = idx
        return lambda q: f0(q) + c * fn(q[i] + q[j]) + k
    if len(trig) % 2:
        fs.append(_scaled_trig(*trig[-1]))
    if len(fs) == 1:
        f0, = fs
        return f0 if k == 0.0 else (lambda q: f0(q) + k)
    if len(fs) == 2:
        f0, f1 = fs
        return lambda q: f0(q) + f1(q) + k
    if len(fs) == 3:
        f0, f1, f2 = fs
        return lambda q: f0(q) + f1(q) + f2(q) + k

    def total(q, fs=tuple(fs)):
        s = k
        for f in fs:
            s += f(q)
        return s
    return total


def _scalar(e: Node) -> ScalarFn:
    if isinstance(e, Num):
        v = e.value
        return lambda q: v
    if isinstance(e, Var):
        return itemgetter(e.index)
    if isinstance(e, (Add, Mul)):
        lin = _linear(e)
        if lin is not None:
            return _linear_fn(*lin)
    if isinstance(e, (Sin, Cos)):
        t = _trig(e)
        if t is not None:
            return _scaled_trig(1.0, *t)
        a, fn = _scalar(e.arg), (math.sin if isinstance(e, Sin) else math.cos)
        return lambda q: fn(a(q))
    if isinstance(e, Pow):
        b, k = _scalar(e.base), e.exp
        if k == 2:
            def square(q):
                v = b(q)
                return v * v
            return square
        if k == -1:
            return lambda q: 1.0 / b(q)
        return lambda q: b(q) ** k
    if isinstance(e, Mul):
        c, factors = (e.factors[0].value, e.factors[1:]) if isinstance(e.factors[0], Num) else (1.0, e.factors)
        if len(factors) == 1 and _trig(factors[0]) is not None:
            return _scaled_trig(c, *_trig(factors[0]))
        fs = [_scalar(f) for f in factors]
        if len(fs) == 1:
            f0, = fs
            return lambda q: c * f0(q)
        if len(fs) == 2:
            f0, f1 = fs
            return (lambda q: f0(q) * f1(q)) if c == 1.0 else (lambda q: c * f0(q) * f1(q))
        if len(fs) == 3:
            f0, f1, f2 = fs
            return lambda q: c * f0(q) * f1(q) * f2(q)

        def product(q, fs=tuple(fs)):
            r = c
            for f in fs:
                r *= f(q)
            return r
        return product
    if isinstance(e, Add):
        return _sum(e)
    raise TypeError(f"not an expression tree node: {e!r}")


def _may_raise(e: Node) -> bool:
    """Whether float arithmetic on the tree can raise (a division, a power that may overflow, sin or
    cos of an argument that may be infinite)."""
    if isinstance(e, (Num, Var)):
        return False
    if isinstance(e, Pow):
        return e.exp < 0 or e.exp > 2 or _may_raise(e.base)
    if isinstance(e, (Sin, Cos)):
        lin = _linear(e.arg)
        return lin is None or any(abs(c) > _SAFE_COEF for c, _ in lin[1])
    return any(_may_raise(p) for p in (e.terms if isinstance(e, Add) else e.factors))


def scalar_function(tree: Node) -> ScalarFn:
    """g(q) for one configuration q, a sequence of n floats (SI) → float, with ``math``.

    Where float arithmetic would raise (a division by zero, an overflowing power), the value is
    the numpy evaluator's (±inf or nan) instead."""
    f = _scalar(tree)
    if not _may_raise(tree):
        return f
    batch = batch_function(tree)

    def guarded(q):
        try:
            return f(q)
        except (ZeroDivisionError, OverflowError, ValueError):
            return float(batch(np.asarray(q, dtype=float).reshape(1, -1))[0])
    return guarded
