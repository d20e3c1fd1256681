"""Bounds of a factor over the joint box (planning.certify.gradient) against closed forms and a dense
finite-difference grid: the bound is never below the true maximum of ‖∇g‖, and within the stated
tolerance of it when the budget suffices; zero-freedom is proven only where there is no zero."""
from __future__ import annotations

import math

import numpy as np
import pytest

from kin.singular.expression import parse_expression, parse_tree
from planning.certify.gradient import REL_TOL, gradient_bound, zero_free

#: the test texts written again by hand in numpy (an independent evaluation of each)
NUMPY = {
    "3*sin(q1) + 4*cos(q2)": lambda q: 3 * np.sin(q[0]) + 4 * np.cos(q[1]),
    "0.74*sin(q2 + q3) + 0.77*cos(q2) + 0.1*cos(q2 + q3) + 0.15":
        lambda q: 0.74 * np.sin(q[1] + q[2]) + 0.77 * np.cos(q[1]) + 0.1 * np.cos(q[1] + q[2]) + 0.15,
    "q1*q2 + sin(q1)^2": lambda q: q[0] * q[1] + np.sin(q[0]) ** 2,
}


def _grid_max(text: str, n: int, lo, hi, k: int = 401) -> float:
    """max ‖∇g‖ on a k^d grid over the joints g depends on, ∇g by central differences (numpy only)."""
    g = NUMPY[text]
    used = [i for i in range(n) if f"q{i + 1}" in text]
    axes = np.meshgrid(*[np.linspace(lo[i], hi[i], k) for i in used], indexing="ij")
    h = 1e-6
    Q = [np.full(axes[0].shape, 0.5 * (lo[i] + hi[i])) for i in range(n)]
    for a, i in zip(axes, used):
        Q[i] = a
    sq = 0.0
    for i in used:
        Qp, Qm = list(Q), list(Q)
        Qp[i], Qm[i] = Q[i] + h, Q[i] - h
        sq = sq + ((g(Qp) - g(Qm)) / (2 * h)) ** 2
    return float(np.sqrt(sq).max())


@pytest.mark.parametrize("text, lo, hi, exact", [
    # ‖∇g‖ = sqrt(9 cos² q1 + 16 sin² q2): 5 where q1 = 0 and q2 = π/2 are both in the box
    ("3*sin(q1) + 4*cos(q2)", [-1, 0], [1, 2], 5.0),
    # the same with q2 kept away from π/2: max at q1 = 0, q2 = 1
    ("3*sin(q1) + 4*cos(q2)", [-1, 0], [1, 1], math.sqrt(9 + 16 * math.sin(1) ** 2)),
    # the FANUC M-16iB/20 shoulder factor over its limits (no closed form: the grid decides)
    ("0.74*sin(q2 + q3) + 0.77*cos(q2) + 0.1*cos(q2 + q3) + 0.15", [-2.97, -1.57, -2.97], [2.97, 2.79, 5.06],
     None),
    ("q1*q2 + sin(q1)^2", [-1, -2], [2, 1], None),
])
def test_the_bound_holds_and_is_tight(text, lo, hi, exact):
    n = len(lo)
    b = gradient_bound(parse_expression(text, n), n, lo, hi)
    truth = exact if exact is not None else _grid_max(text, n, lo, hi)
    assert b.converged
    assert b.bound >= truth * (1 - 1e-9)
    assert b.bound <= truth * (1 + REL_TOL) * (1 + 1e-6) + (0 if exact is not None else 1e-3 * truth)
    assert b.attained <= b.bound and b.attained >= truth * (1 - 1e-3)
    assert all(lo[i] <= b.at[i] <= hi[i] for i in range(n))


def test_a_spent_budget_still_gives_a_proven_bound():
    text = "0.74*sin(q2 + q3) + 0.77*cos(q2) + 0.1*cos(q2 + q3) + 0.15"
    lo, hi = [-2.97, -1.57, -2.97], [2.97, 2.79, 5.06]
    b = gradient_bound(parse_expression(text, 3), 3, lo, hi, max_boxes=50)
    assert not b.converged and b.bound >= _grid_max(text, 3, lo, hi)


def test_no_dependence_no_gradient():
    b = gradient_bound(parse_expression("2.5", 2), 2, [0, 0], [1, 1])
    assert b.bound == 0.0 and b.converged


@pytest.mark.parametrize("text, lo, hi, free", [
    ("2 + sin(q1)", [-10], [10], True),
    ("sin(q1)", [0.1, ], [3.0], True),
    ("sin(q1)", [-1], [1], False),
    ("sin(q1)", [0.0], [1], False),                  # a zero on the boundary is a zero
    ("q1^2 + q2^2 - 1", [-2, -2], [2, 2], False),
    ("q1^2 + q2^2 - 1", [1.1, -2], [2, 2], True),
    ("(q1 - 0.5)^2", [0, 0], [1, 1], False),         # a double root: no sign change, still not zero-free
])
def test_zero_free_is_proven_only_without_a_zero(text, lo, hi, free):
    n = len(lo)
    assert zero_free(parse_expression(text, n), n, lo, hi) is free


def test_a_tree_and_its_sympy_form_give_the_same_bound():
    text = "0.74*sin(q2 + q3) + 0.77*cos(q2) + 0.1*cos(q2 + q3) + 0.15"
    lo, hi = [-2.97, -1.57, -2.97], [2.97, 2.79, 5.06]
    a = gradient_bound(parse_tree(text, 3), 3, lo, hi)
    b = gradient_bound(parse_expression(text, 3), 3, lo, hi)
    assert a.bound == pytest.approx(b.bound, rel=1e-12) and a.converged and b.converged
