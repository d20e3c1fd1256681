"""The CasADi graph of a chain: frames, forward kinematics, geometric Jacobian, dexterity measures.

The graph is built once per chain with joint variables ``q`` (n,) and design parameters ``p``
(n_p,) as symbolic inputs, and wrapped in :class:`casadi.Function` objects with named inputs and
outputs.  Design parameters are ordinary inputs, so every function can be differentiated with
respect to them (``casadi.jacobian``) and used inside ``nlpsol``.

Geometric Jacobian, base frame, at the tool point:  column i is [z × (p_e − o); z] for a revolute
joint and [z; 0] for a prismatic one, where z and o are the joint's axis and a point on it.
"""
from __future__ import annotations

import math
from functools import cached_property

import casadi as ca
import numpy as np

from kin.chain import Chain

_EXACT_TOL = 1e-12


def exact_cos_sin(angle: float) -> tuple[float, float]:
    """cos and sin of a numeric angle, snapped to exact 0/±1 at multiples of π/2.

    DH tables are full of ±90° twists; cos(π/2) = 6e-17 in floating point would leave tiny
    spurious terms in every expression (and in the generated C code).
    """
    c, s = math.cos(angle), math.sin(angle)
    c = 0.0 if abs(c) < _EXACT_TOL else (math.copysign(1.0, c) if abs(abs(c) - 1) < _EXACT_TOL else c)
    s = 0.0 if abs(s) < _EXACT_TOL else (math.copysign(1.0, s) if abs(abs(s) - 1) < _EXACT_TOL else s)
    return c, s


def _cs(x):
    if isinstance(x, (int, float)):
        return exact_cos_sin(float(x))
    return ca.cos(x), ca.sin(x)


def _rz_tz_cs(c, s, d) -> ca.SX:
    return ca.SX(ca.vertcat(ca.horzcat(c, -s, 0, 0), ca.horzcat(s, c, 0, 0),
                            ca.horzcat(0, 0, 1, d), ca.horzcat(0, 0, 0, 1)))


def _tx_rx(a, alpha) -> ca.SX:
    c, s = _cs(alpha)
    return ca.SX(ca.vertcat(ca.horzcat(1, 0, 0, a), ca.horzcat(0, c, -s, 0),
                            ca.horzcat(0, s, c, 0), ca.horzcat(0, 0, 0, 1)))


class SymbolicChain:
    """CasADi expressions and functions of one chain.

    Attributes (CasADi SX): ``q`` (n,), ``p`` (n_p,), ``T`` (4×4 tool pose), ``J`` (6×n geometric
    Jacobian), ``frames`` (list of n+1 4×4 poses: base and after each joint, tool not applied),
    ``axes`` (list of n (z, o) pairs: joint axis and a point on it, base frame).
    """

    def __init__(self, chain: Chain):
        self.chain = chain
        self.n = chain.n
        self.q = ca.SX.sym("q", chain.n)
        self.p = ca.SX.sym("p", len(chain.parameters))
        self.frames, self.axes, self.T, self.J = self._build(lambda i: (ca.cos(self.q[i]), ca.sin(self.q[i])))
        # the same graph with cos q_i, sin q_i as inputs, for kernels that compute them in SIMD
        self.c = ca.SX.sym("c", chain.n)
        self.s = ca.SX.sym("s", chain.n)
        _, _, self.T_cs, self.J_cs = self._build(lambda i: (self.c[i], self.s[i]))

    def _build(self, trig):
        """Frames, axes, tool pose and Jacobian; ``trig(i)`` gives (cos q_i, sin q_i)."""
        chain = self.chain
        names = list(chain.parameters)

        def val(v):
            return self.p[names.index(v)] if isinstance(v, str) else float(v)

        T = ca.SX(chain.base.matrix)
        frames = [T]
        axes = []
        for i, j in enumerate(chain.joints):
            a, alpha, d, theta = val(j.a), val(j.alpha), val(j.d), val(j.theta)
            if j.is_revolute:
                cq, sq = trig(i)
                co, so = _cs(theta)            # offset: cos(q+o) = cq·co − sq·so
                ct, st = cq * co - sq * so, sq * co + cq * so
            else:
                d = self.q[i] + d
                ct, st = _cs(theta)
            if chain.convention == "modified":
                T = T @ _tx_rx(a, alpha)           # Rx(α)·Tx(a) == Tx(a)·Rx(α)
                axes.append((T[:3, 2], T[:3, 3]))
                T = T @ _rz_tz_cs(ct, st, d)
            else:
                axes.append((T[:3, 2], T[:3, 3]))
                T = T @ _rz_tz_cs(ct, st, d) @ _tx_rx(a, alpha)
            frames.append(T)
        Ttool = T @ ca.SX(chain.tool.matrix)
        pe = Ttool[:3, 3]
        cols = []
        for j, (z, o) in zip(chain.joints, axes):
            if j.is_revolute:
                cols.append(ca.vertcat(ca.cross(z, pe - o), z))
            else:
                cols.append(ca.vertcat(z, ca.SX.zeros(3)))
        return frames, axes, Ttool, ca.horzcat(*cols)

    # ---- casadi.Function wrappers ------------------------------------------------------------
    @cached_property
    def fk_function(self) -> ca.Function:
        """fk(q, p) → T (4×4)."""
        return ca.Function("fk", [self.q, self.p], [self.T], ["q", "p"], ["T"])

    @cached_property
    def jacobian_function(self) -> ca.Function:
        """jacobian(q, p) → J (6×n)."""
        return ca.Function("jacobian", [self.q, self.p], [self.J], ["q", "p"], ["J"])

    @cached_property
    def fkj_function(self) -> ca.Function:
        """fkj(q, p) → (T, J): the pair the compiled kernels evaluate."""
        return ca.Function("fkj", [self.q, self.p], [self.T, self.J], ["q", "p"], ["T", "J"])

    @cached_property
    def fkj_cs_function(self) -> ca.Function:
        """fkj_cs(c, s, q, p) → (T, J) with c = cos q, s = sin q given (q is read for prismatic joints only)."""
        return ca.Function("fkj_cs", [self.c, self.s, self.q, self.p], [self.T_cs, self.J_cs],
                           ["c", "s", "q", "p"], ["T", "J"])

    @cached_property
    def frames_function(self) -> ca.Function:
        """frames(q, p) → F (4 × 4(n+1)): base and every joint frame side by side, then tool pose."""
        return ca.Function("frames", [self.q, self.p], [ca.horzcat(*self.frames), self.T],
                           ["q", "p"], ["F", "T"])

    @cached_property
    def zero_rows(self) -> tuple[int, ...]:
        """Jacobian rows that are identically zero (structurally, or at random configurations)."""
        rows = []
        rng = np.random.default_rng(0)
        lo, hi = self.chain.lower, self.chain.upper
        for r in range(6):
            if all(self.J[r, c].is_zero() for c in range(self.n)):
                rows.append(r)
                continue
            vals = [np.abs(np.array(self.jacobian_function(rng.uniform(lo, hi), self.chain.parameter_values))[r]).max()
                    for _ in range(8)]
            if max(vals) < 1e-12:
                rows.append(r)
        return tuple(rows)

    @cached_property
    def task_rows(self) -> tuple[int, ...]:
        """Controlled Jacobian rows (see :meth:`kin.chain.Chain.task_rows`)."""
        return self.chain.task_rows(self.zero_rows)

    def task_jacobian(self) -> ca.SX:
        """The controlled rows of J (m×n)."""
        return self.J[list(self.task_rows), :]

    @cached_property
    def manipulability_function(self) -> ca.Function:
        """manipulability(q, p) → √det(Jt·Jtᵀ) of the task Jacobian (or of Jtᵀ·Jt when m > n).

        Symbolic and differentiable (for optimisation); the fast evaluators compute the same value
        numerically.
        """
        Jt = self.task_jacobian()
        G = Jt @ Jt.T if Jt.shape[0] <= Jt.shape[1] else Jt.T @ Jt
        return ca.Function("manipulability", [self.q, self.p], [ca.sqrt(ca.fmax(ca.det(G), 0))],
                           ["q", "p"], ["w"])
