"""Window barriers of the path follower (:func:`planning.follow.follow_path`): the signed margin
d_w(q) of one singular error window (> 0 outside; joint distance for an interval window, |g| − ε for
a predicate window, with gradient sign(g)·∇g) and its buffer m_w, from which the follower builds the
window's constraint row ∇d_w(q_k)·q̇·Δt ≥ −γ·(d_w(q_k) − m_w).  A predicate window's g and its
partial derivatives are scalar closures of its expression tree (:mod:`kin.singular.tree`,
:mod:`kin.singular.evaluate`): no sympy.
"""
from __future__ import annotations

import math

import numpy as np

from kin.singular.evaluate import scalar_function
from kin.singular.tree import derivative
from planning.certify.segments import window_expression
from planning.windows import Window


class _Barrier:
    """Signed margin d(q) of one window (> 0 outside) with its gradient, and the buffer m."""

    def __init__(self, w: Window, n: int, buffer: float):
        self.window = w
        self.empty = False
        if w.is_interval:
            self.joints = [w.joint]
            self.ivs = np.array(w.intervals, dtype=float).reshape(-1, 2)
            self.empty = len(self.ivs) == 0
            self.m = buffer * w.width
        elif getattr(w, "is_point_set", False):       # planning.windows.sampled: joint distance − width
            self.joints = [j - 1 for j in w.joints]
            self.empty = len(w.points) == 0
            self.m = buffer * w.width
        else:
            self.joints = [j - 1 for j in w.joints]
            self.empty = w.epsilon is None or w.epsilon < 0
            self.m = buffer * max(w.epsilon or 0.0, 0.0)
            tree = window_expression(w)
            self._g = scalar_function(tree)
            self._dg = [scalar_function(derivative(tree, j)) for j in self.joints]

    def __call__(self, q: np.ndarray) -> tuple[float, np.ndarray]:
        """(d, ∂d/∂q over ``self.joints``)."""
        if self.empty:
            return math.inf, np.zeros(len(self.joints))
        if self.window.is_interval:
            x = q[self.joints[0]]
            lo, hi = self.ivs[:, 0], self.ivs[:, 1]
            d_each = np.maximum(lo - x, x - hi)
            i = int(np.argmin(d_each))
            # the nearer edge of the interval decides the direction (outwards when inside)
            sgn = -1.0 if (lo[i] - x) > (x - hi[i]) else 1.0
            return float(d_each[i]), np.array([sgn])
        if getattr(self.window, "is_point_set", False):
            return self.window.margin_and_gradient(q)
        ql = [float(v) for v in q]
        g = float(self._g(ql))
        dg = np.array([d(ql) for d in self._dg], dtype=float)
        s = 1.0 if g >= 0 else -1.0
        return abs(g) - float(self.window.epsilon), s * dg
