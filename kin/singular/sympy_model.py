"""An exact sympy model of a chain, for factoring the singular set (CasADi stays the numeric engine).

Joint variables become polynomial symbols: c_i = cos q_i, s_i = sin q_i for a revolute joint and
q_i itself for a prismatic one.  Non-zero lengths (a, d) are kept as symbols (a2, d4, …) so that the
factors come out in their physical form (d4·c3 − a3·s3) and are substituted afterwards; twists and
fixed angles that are multiples of π/2 are exact, other numbers become exact rationals of their
12-significant-digit decimal form.
"""
from __future__ import annotations

import sympy as sp

from kin.chain import Chain
from kin.symbolic import exact_cos_sin


def rational(x: float) -> sp.Rational:
    """Exact rational of a float's 12-significant-digit decimal form (0.15 → 3/20)."""
    return sp.Integer(0) if x == 0 else sp.Rational(f"{x:.12g}")


class SympyChain:
    """Polynomial sympy model of a chain (parameters frozen at their nominal values).

    ``var[i]``: (c_i, s_i) for revolute joints, q_i for prismatic ones; ``lengths``: length symbol →
    value (SI); ``frames[k]``: 4×4 pose of frame k in the base-less world (frame 0 = identity);
    ``axes[i]``: (z, o) of joint i.
    """

    def __init__(self, chain: Chain, keep_lengths: bool = True):
        chain = chain.frozen()
        self.chain = chain
        n = chain.n
        self.c = sp.symbols(f"c1:{n + 1}", real=True)
        self.s = sp.symbols(f"s1:{n + 1}", real=True)
        self.q = sp.symbols(f"q1:{n + 1}", real=True)
        self.lengths: dict[sp.Symbol, float] = {}
        tab = chain.dh_table()
        T = sp.eye(4)
        frames, axes = [T], []
        for i, j in enumerate(chain.joints):
            a, alpha, d, theta = (float(x) for x in tab[i])
            ca, sa = (rational(v) for v in exact_cos_sin(alpha))
            A = self._length("a", i, a, keep_lengths)
            D = self._length("d", i, d, keep_lengths)
            if j.is_revolute:
                co, so = (rational(v) for v in exact_cos_sin(theta))
                ct, st = self.c[i] * co - self.s[i] * so, self.s[i] * co + self.c[i] * so
            else:
                ct, st = (rational(v) for v in exact_cos_sin(theta))
                D = self.q[i] + D
            rz_tz = sp.Matrix([[ct, -st, 0, 0], [st, ct, 0, 0], [0, 0, 1, D], [0, 0, 0, 1]])
            tx_rx = sp.Matrix([[1, 0, 0, A], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1]])
            if chain.convention == "modified":
                T = T * tx_rx
                axes.append((T[:3, 2], T[:3, 3]))
                T = T * rz_tz
            else:
                axes.append((T[:3, 2], T[:3, 3]))
                T = T * rz_tz * tx_rx
            T = T.applyfunc(sp.expand)
            frames.append(T)
        self.frames = frames
        self.axes = axes

    def _length(self, name: str, i: int, value: float, keep: bool):
        if value == 0:
            return sp.Integer(0)
        if not keep:
            return rational(value)
        sym = sp.Symbol(f"{name}{i + 1}", real=True)
        self.lengths[sym] = value
        return sym

    @property
    def variables(self) -> list[sp.Symbol]:
        """The polynomial variables actually used: c_i, s_i (revolute), q_i (prismatic)."""
        out = []
        for i, j in enumerate(self.chain.joints):
            out += [self.c[i], self.s[i]] if j.is_revolute else [self.q[i]]
        return out

    def trig_identities(self) -> list[sp.Expr]:
        """c_i² + s_i² − 1 for every revolute joint."""
        return [self.c[i] ** 2 + self.s[i] ** 2 - 1 for i, j in enumerate(self.chain.joints) if j.is_revolute]

    def column(self, i: int, point: sp.Matrix) -> sp.Matrix:
        """Geometric Jacobian column of joint i at ``point`` (6×1)."""
        z, o = self.axes[i]
        if self.chain.joints[i].is_revolute:
            return sp.Matrix.vstack(z.cross(point - o), z).applyfunc(sp.expand)
        return sp.Matrix.vstack(z, sp.zeros(3, 1))

    def to_trig(self, expr: sp.Expr) -> sp.Expr:
        """Polynomial in c_i, s_i, q_i → expression in cos(q_i), sin(q_i), q_i."""
        sub = {}
        for i, j in enumerate(self.chain.joints):
            if j.is_revolute:
                sub[self.c[i]] = sp.cos(self.q[i])
                sub[self.s[i]] = sp.sin(self.q[i])
        return expr.subs(sub)

    def numeric(self, expr: sp.Expr) -> sp.Expr:
        """Substitute the length symbols by their values (SI)."""
        return expr.subs({k: rational(v) for k, v in self.lengths.items()})
