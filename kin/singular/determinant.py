"""The determinant of a chain's task Jacobian as an exact polynomial, split by structure.

See :mod:`kin.singular` for why the splits are exact (det J does not depend on the reference
point, nor on q1 and qn).
"""
from __future__ import annotations

import math

import numpy as np
import sympy as sp
from sympy.polys.matrices import DomainMatrix

from kin.singular.sympy_model import SympyChain, rational

#: above this many length symbols in a whole-Jacobian determinant, lengths are substituted first
MAX_SYMBOLIC_LENGTHS = 4
ROW_NAMES = ("x", "y", "z", "rx", "ry", "rz")


def _poly_det(M: sp.Matrix) -> sp.Expr:
    dM = DomainMatrix.from_Matrix(M)
    return dM.domain.to_sympy(dM.det())


def numeric_axes(robot, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Joint axes z (N, n, 3) and points o (N, n, 3) in the base frame, from the CasADi model."""
    sym = robot.symbolic
    import casadi as ca
    f = ca.Function("axes", [sym.q, sym.p], [ca.horzcat(*[z for z, _ in sym.axes]),
                                              ca.horzcat(*[o for _, o in sym.axes])])
    Z, origins = [], []
    for q in Q:
        z, o = f(q, robot.chain.parameter_values)
        Z.append(np.array(z).T)
        origins.append(np.array(o).T)
    return np.array(Z), np.array(origins)


def closest_point(z1, o1, z2, o2) -> tuple[np.ndarray, float]:
    """Midpoint of the closest points of two lines and their distance (inf when parallel)."""
    w = o1 - o2
    a, b, c = z1 @ z1, z1 @ z2, z2 @ z2
    d, e = z1 @ w, z2 @ w
    den = a * c - b * b
    if den < 1e-12:
        return o1, math.inf
    s = (b * e - c * d) / den
    t = (a * e - b * d) / den
    p1, p2 = o1 + s * z1, o2 + t * z2
    return (p1 + p2) / 2, float(np.linalg.norm(p1 - p2))


def wrist_centre(robot, seed: int = 0) -> tuple[int, np.ndarray] | None:
    """If the last three joints form a spherical wrist: (k, w) with the wrist centre w fixed in
    frame k = n − 3 (homogeneous, SI); else None."""
    chain = robot.chain
    n = chain.n
    if n < 6 or not all(j.is_revolute for j in chain.joints[-3:]):
        return None
    rng = np.random.default_rng(seed)
    Q = rng.uniform(chain.lower, chain.upper, size=(4, n))
    Z, origins = numeric_axes(robot, Q)
    frames = robot.symbolic.frames_function
    local = []
    for q, z, o in zip(Q, Z, origins):
        p1, d1 = closest_point(z[n - 3], o[n - 3], z[n - 2], o[n - 2])
        p2, d2 = closest_point(z[n - 2], o[n - 2], z[n - 1], o[n - 1])
        if d1 > 1e-9 or d2 > 1e-9 or np.linalg.norm(p1 - p2) > 1e-9:
            return None
        F = np.array(frames(q, chain.parameter_values)[0])
        Tk = F[:, 4 * (n - 3):4 * (n - 2)]
        local.append(np.linalg.solve(Tk, np.append(p1, 1.0)))
    if np.ptp(np.array(local), axis=0).max() > 1e-9:
        return None
    return n - 3, np.mean(local, axis=0)


#: the ways det J is split (see :func:`derivation_text`)
SPLITS = ("wrist", "linear", "full", "task")
#: the block names of the determinant's parts
BLOCKS = ("positioning", "wrist", "linear axes", "rotary axes", "full", "task")


def derivation_text(split: str, n: int, rows: tuple[int, ...], lengths_numeric: bool = False) -> str:
    """One line saying how det J was computed, from the ``split`` key of :func:`det_and_blocks`."""
    names = " ".join(ROW_NAMES[r] for r in rows)
    if split == "wrist":
        return "det J = det J11 · det J22 (spherical wrist: Jacobian split at the wrist centre)"
    if split == "linear":
        return "det J = −det Z · det W (three prismatic joints: linear axes Z, rotary axes W)"
    if split == "full":
        note = ", lengths numeric" if lengths_numeric else ""
        return f"det J (whole 6×6 Jacobian at the last joint's axis, q1 = q{n} = 0 without loss{note})"
    m = len(rows)
    if m == n:
        return f"det J (task rows {names})"
    return f"det({'J·Jᵀ' if m < n else 'Jᵀ·J'}) (task rows {names})"


def det_and_blocks(robot, model: SympyChain) -> tuple[list[tuple[sp.Expr, str]], str, tuple[int, ...], bool]:
    """[(determinant polynomial, block name)], split key (:data:`SPLITS`), task rows, and whether
    the lengths were substituted by numbers before the determinant (see :func:`derivation_text`)."""
    chain = robot.chain
    n = chain.n
    rows = tuple(robot.task_rows)
    m = len(rows)
    if m == 6 and n == 6:
        wc = wrist_centre(robot)
        if wc is not None:
            k, w_local = wc
            Tk = model.frames[k]
            # the wrist centre as a frame origin when one sits there (keeps the lengths symbolic)
            pw = None
            for kk in range(k, n + 1):
                F = np.array(robot.symbolic.frames_function(np.zeros(n), chain.parameter_values)[0])
                Fk = F[:, 4 * k:4 * (k + 1)]
                Fkk = F[:, 4 * kk:4 * (kk + 1)]
                if np.allclose(np.linalg.solve(Fk, Fkk[:, 3]), w_local, atol=1e-12):
                    pw = model.frames[kk][:3, 3]
                    if not any(model.c[i] in pw.free_symbols or model.s[i] in pw.free_symbols for i in range(k, n)):
                        break
                    pw = None
            if pw is None:
                pw = (Tk * sp.Matrix([rational(x) for x in w_local]))[:3, 0]
            cols = [model.column(i, pw) for i in range(n)]
            J11 = sp.Matrix.hstack(*[c[:3, 0] for c in cols[:3]])
            J22 = sp.Matrix.hstack(*[c[3:, 0] for c in cols[3:]])
            return ([(_poly_det(J11.applyfunc(sp.expand)), "positioning"), (_poly_det(J22), "wrist")],
                    "wrist", rows, False)
        pris = [i for i, j in enumerate(chain.joints) if not j.is_revolute]
        rev = [i for i, j in enumerate(chain.joints) if j.is_revolute]
        if len(pris) == 3:
            p0 = sp.zeros(3, 1)
            cols = [model.column(i, p0) for i in range(n)]
            Z = sp.Matrix.hstack(*[cols[i][:3, 0] for i in pris])
            W = sp.Matrix.hstack(*[cols[i][3:, 0] for i in rev])
            return [(_poly_det(Z), "linear axes"), (_poly_det(W), "rotary axes")], "linear", rows, False
        # Whole determinant.  det J depends neither on q1 (turning joint 1 turns the whole Jacobian)
        # nor on qn (take the reference point on the last joint's axis), so both are set to zero.
        sub = {}
        for i in (0, n - 1):
            if chain.joints[i].is_revolute:
                sub.update({model.c[i]: 1, model.s[i]: 0})
            else:
                sub[model.q[i]] = 0
        ref = model.axes[n - 1][1].subs(sub)
        J = sp.Matrix.hstack(*[model.column(i, ref) for i in range(n)]).subs(sub).applyfunc(sp.expand)
        used = J.free_symbols & set(model.lengths)
        numeric = len(used) > MAX_SYMBOLIC_LENGTHS
        if numeric:
            # factoring in many length symbols is slow; numbers keep it within seconds
            J = J.subs({k: rational(v) for k, v in model.lengths.items()}).applyfunc(sp.expand)
        return [(_poly_det(J), "full")], "full", rows, numeric
    # fewer task rows: base frame matters for which rows are kept
    R0 = sp.Matrix(np.round(chain.base.matrix[:3, :3], 15).tolist()).applyfunc(rational)
    tool = chain.tool.matrix
    pe_local = sp.Matrix([rational(x) for x in tool[:3, 3]] + [1])
    pe = (model.frames[-1] * pe_local)[:3, 0]
    cols = []
    for i in range(n):
        c = model.column(i, pe)
        cols.append(sp.Matrix.vstack(R0 * c[:3, 0], R0 * c[3:, 0]).applyfunc(sp.expand))
    J = sp.Matrix.hstack(*cols).extract(list(rows), list(range(n)))
    if m == n:
        return [(_poly_det(J), "task")], "task", rows, False
    G = (J * J.T if m < n else J.T * J).applyfunc(sp.expand)
    return [(_poly_det(G), "task")], "task", rows, False


def reduce_factors(model: SympyChain, poly: sp.Expr) -> list[tuple[sp.Expr, int]]:
    """Irreducible factors of ``poly`` that involve joint variables, reduced by c² + s² = 1."""
    joint_vars = set(model.variables)
    ids = model.trig_identities()
    gens = list(model.c) + list(model.s) + list(model.q) + sorted(model.lengths, key=str)
    out: list[tuple[sp.Expr, int]] = []
    _, facs = sp.factor_list(sp.expand(poly))
    for f, mult in facs:
        if not (f.free_symbols & joint_vars):
            continue
        r = sp.reduced(f, ids, *gens, order="lex")[1] if ids else f
        r = sp.expand(r)
        if r == 0:
            out.append((sp.Integer(0), mult))      # identically singular
            continue
        if not (r.free_symbols & joint_vars):
            continue                                # a constant on the torus, e.g. c1² + s1²
        _, sub = sp.factor_list(r)
        for g, m2 in sub:
            if g.free_symbols & joint_vars:
                out.append((g, mult * m2))
    # merge equal factors (up to sign)
    merged: list[tuple[sp.Expr, int]] = []
    for g, mult in out:
        for i, (h, m0) in enumerate(merged):
            if sp.expand(g - h) == 0 or sp.expand(g + h) == 0:
                merged[i] = (h, m0 + mult)
                break
        else:
            merged.append((g, mult))
    return merged


