"""planning.certify.intervals: every enclosure holds all values of the function on the box (dense
sampling), shrinks to the point value on tiny boxes, and cos/sin ranges match sampled ranges."""
import math

import numpy as np
import pytest
import sympy as sp

from planning.certify.intervals import IntervalError, compile_interval, cos_interval, sin_interval

Q = sp.symbols("q1:4", real=True)
EXPRS = [
    0.74 * sp.sin(Q[1] + Q[2]) + 0.77 * sp.cos(Q[1]) + 0.1 * sp.cos(Q[1] + Q[2]) + 0.15,
    0.1 * sp.sin(Q[2]) - 0.74 * sp.cos(Q[2]),
    sp.sin(Q[0]) * sp.cos(Q[1]) ** 2 - 3 * Q[2] ** 2 + Q[0] * Q[2],
    (sp.sin(2 * Q[0] - Q[1]) + sp.Rational(1, 3)) ** 3,
]


@pytest.mark.parametrize("k", range(len(EXPRS)))
def test_enclosure_holds_every_sampled_value(k):
    expr = EXPRS[k]
    fn = compile_interval(expr, Q)
    f = sp.lambdify([Q], expr, modules="numpy")
    rng = np.random.default_rng(k)
    centre = rng.uniform(-4, 4, (200, 3))
    half = rng.uniform(0, 1.5, (200, 3)) ** 2
    lo, hi = centre - half, centre + half
    glo, ghi = fn(lo, hi)
    for b in range(200):
        pts = lo[b] + rng.random((400, 3)) * (hi[b] - lo[b])
        pts = np.vstack([pts, lo[b], hi[b]])
        vals = np.broadcast_to(f(pts.T), (len(pts),))
        assert vals.min() >= glo[b] and vals.max() <= ghi[b]


@pytest.mark.parametrize("k", range(len(EXPRS)))
def test_enclosure_of_a_point_is_the_value(k):
    fn = compile_interval(EXPRS[k], Q)
    f = sp.lambdify([Q], EXPRS[k], modules="numpy")
    q = np.random.default_rng(10 + k).uniform(-3, 3, (50, 3))
    glo, ghi = fn(q, q + 1e-12)
    v = np.broadcast_to(f(q.T), (50,))
    scale = 1 + np.abs(v)
    assert np.all(ghi - glo < 1e-9 * scale)
    assert np.all((glo <= v) & (v <= ghi))


def test_cos_and_sin_ranges_match_dense_sampling():
    rng = np.random.default_rng(3)
    lo = rng.uniform(-10, 10, 500)
    hi = lo + rng.uniform(0, 7, 500)
    for fn, f in ((cos_interval, np.cos), (sin_interval, np.sin)):
        clo, chi = fn(lo, hi)
        for a, b, l_, h_ in zip(lo, hi, clo, chi):
            v = f(np.linspace(a, b, 20001))
            assert l_ <= v.min() and v.max() <= h_
            assert v.min() - l_ < 1e-6 and h_ - v.max() < 1e-6      # tight (up to the sampling)


def test_unsupported_nodes_are_refused():
    with pytest.raises(IntervalError):
        compile_interval(sp.exp(Q[0]), Q)
    with pytest.raises(IntervalError):
        compile_interval(sp.sqrt(Q[0] ** 2 + 1), Q)
    with pytest.raises(IntervalError):
        compile_interval(sp.Symbol("x") + 1, Q)


def test_full_period_gives_the_whole_range():
    lo, hi = cos_interval(np.array([0.3]), np.array([0.3 + 2 * math.pi]))
    assert lo[0] == -1.0 and hi[0] == 1.0
