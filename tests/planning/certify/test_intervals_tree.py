"""Interval enclosures of expression trees (planning.certify.intervals on kin.singular.tree): on
random texts of the grammar and random boxes every sampled value lies inside the enclosure, and for
factor-shaped texts the tree's enclosure holds the one of the sympy path (sympy only merges terms
and powers, which can only tighten an enclosure), equal up to rounding where it merges nothing."""
from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from kin.singular.evaluate import batch_function
from kin.singular.expression import ExpressionError, joint_symbols, parse_expression, parse_tree
from kin.singular.tree import Node, Pow
from planning.certify.intervals import IntervalError, compile_interval
from tests.kin.singular.test_tree import FACTORS, GRAMMAR, TRIG_SUMS

N = 6
Q = joint_symbols(N)
SEEDS = st.integers(0, 2**32 - 1)


def _boxes(seed: int, count: int = 24) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    centre = rng.uniform(-3, 3, (count, N))
    half = rng.uniform(0, 1.2, (count, N)) ** 2
    return centre - half, centre + half


def _has_negative_power(e) -> bool:
    if isinstance(e, Pow):
        return e.exp < 0 or _has_negative_power(e.base)
    return any(_has_negative_power(c) for c in getattr(e, "terms", getattr(e, "factors", ()))) or \
        (hasattr(e, "arg") and _has_negative_power(e.arg))


def _samples_inside(tree: Node, fn, lo, hi, seed: int, f=None) -> None:
    """Values at points of each box (by ``f``, default the tree's numpy evaluator) lie in the enclosure."""
    glo, ghi = fn(lo, hi)
    f = f or batch_function(tree)
    rng = np.random.default_rng(seed + 1)
    for b in range(len(lo)):
        pts = lo[b] + rng.random((300, N)) * (hi[b] - lo[b])
        pts = np.vstack([pts, lo[b], hi[b]])
        v = f(pts)
        v = v[np.isfinite(v)]
        assert np.all(v >= glo[b]) and np.all(v <= ghi[b]), (str(tree), b, v.min(), v.max(), glo[b], ghi[b])


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(GRAMMAR, FACTORS, TRIG_SUMS), SEEDS)
def test_tree_enclosure_holds_every_sampled_value(text, seed):
    try:
        tree = parse_tree(text, N)
    except ExpressionError:
        assume(False)
    if _has_negative_power(tree):
        with pytest.raises(IntervalError, match="only non-negative integer powers"):
            compile_interval(tree)
        return
    lo, hi = _boxes(seed)
    _samples_inside(tree, compile_interval(tree), lo, hi, seed)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(FACTORS, TRIG_SUMS), SEEDS)
def test_tree_enclosure_holds_the_sympy_paths(text, seed):
    tree = parse_tree(text, N)
    expr = parse_expression(text, N)
    lo, hi = _boxes(seed)
    alo, ahi = compile_interval(tree)(lo, hi)
    slo, shi = compile_interval(expr, Q)(lo, hi)
    tol = 1e-12 * (1 + np.maximum(np.abs(slo), np.abs(shi)))
    assert np.all(alo <= slo + tol) and np.all(ahi >= shi - tol)
    g = sp.lambdify([Q], expr, "numpy")          # the sympy path bounds sympy's expression (terms merged)
    _samples_inside(tree, compile_interval(expr, Q), lo, hi, seed,
                    lambda P: np.broadcast_to(np.asarray(g(P.T), dtype=float), (len(P),)))


def test_equal_where_sympy_merges_nothing():
    text = "0.74*sin(q2 + q3) + 0.77*cos(q2) + 0.1*cos(q2 + q3) + 0.15"
    lo, hi = _boxes(5, 200)
    alo, ahi = compile_interval(parse_tree(text, N))(lo, hi)
    slo, shi = compile_interval(parse_expression(text, N), Q)(lo, hi)
    scale = 1 + np.maximum(np.abs(slo), np.abs(shi))
    assert np.allclose(alo, slo, rtol=0, atol=1e-14 * scale.max()) and np.allclose(ahi, shi, rtol=0,
                                                                                    atol=1e-14 * scale.max())


def test_a_sympy_expression_is_converted_to_the_same_evaluator():
    x = Q[:3]
    expr = (sp.sin(2 * x[0] - x[1]) + sp.Rational(1, 3)) ** 3 - x[2] ** 2
    lo, hi = _boxes(7, 50)
    a = compile_interval(expr, Q)(lo, hi)
    from kin.singular.tree_sympy import from_sympy
    b = compile_interval(from_sympy(sp.expand(expr, trig=False), Q))(lo, hi)      # a sum is expanded first
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    with pytest.raises(IntervalError, match="only non-negative integer powers"):
        compile_interval(1 / (x[0] ** 2 + 1), Q)
    with pytest.raises(IntervalError, match="sympy expression needs its variables"):
        compile_interval(expr)
