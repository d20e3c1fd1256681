"""Numeric helpers of the singularity analysis: readable expressions, vectorised factor functions,
roots of one-joint factors and samples of multi-joint zero sets."""
from __future__ import annotations

import math
from typing import Callable

import numpy as np
import sympy as sp
from scipy.optimize import brentq, minimize_scalar


def display_form(expr: sp.Expr) -> sp.Expr:
    """The expression as shown: trig combined when it shortens it (sympy's trigsimp: slow, so the
    budgeted worker does it)."""
    e = expr
    if len(sp.Add.make_args(e)) <= 12:
        try:
            t = sp.trigsimp(e)
            if sp.count_ops(t) <= sp.count_ops(e):
                e = t
        except Exception:  # trigsimp is cosmetic
            pass
    return e


def display_text(e: sp.Expr) -> str:
    """Text of a :func:`display_form`: floats with up to 6 significant digits."""
    e = e.xreplace({x: sp.Float(float(x), 15) for x in e.atoms(sp.Number) if not x.is_Integer})
    return sp.sstr(e, full_prec=False)


def lambdify_factor(expr: sp.Expr, n: int):
    q = sp.symbols(f"q1:{n + 1}", real=True)
    f = sp.lambdify([q], expr, modules="numpy")
    grads = [sp.lambdify([q], sp.diff(expr, qi), modules="numpy") for qi in q]

    def fn(Q: np.ndarray) -> np.ndarray:
        cols = Q.T
        return np.broadcast_to(np.asarray(f(cols), dtype=float), (Q.shape[0],)).copy()

    def grad_fn(Q: np.ndarray) -> np.ndarray:
        cols = Q.T
        return np.stack([np.broadcast_to(np.asarray(g(cols), dtype=float), (Q.shape[0],)) for g in grads], axis=1)

    return fn, grad_fn


def _roots_1d(fun: Callable[[np.ndarray], np.ndarray], lo: float, hi: float, grid: int = 2000) -> list[float]:
    """Roots of a smooth scalar function on [lo, hi]: sign changes refined by Brent's method, plus
    touching zeros (|g| minima at the noise level)."""
    x = np.linspace(lo, hi, grid)
    y = fun(x)
    roots = []
    scale = max(np.abs(y).max(), 1e-300)
    for i in range(grid - 1):
        if y[i] == 0:
            roots.append(x[i])
        elif y[i] * y[i + 1] < 0:
            roots.append(brentq(lambda t: float(fun(np.array([t]))[0]), x[i], x[i + 1], xtol=1e-15, rtol=1e-15))
    if y[-1] == 0:
        roots.append(x[-1])
    # zeros exactly at a limit (sin q at q = ±2π evaluates to ±2.4e-16, not 0, and no sign change
    # follows inside the range): kept when |g| there is at the rounding-noise level
    for k in (0, grid - 1):
        if y[k] != 0 and abs(y[k]) < 1e-12 * scale:
            roots.append(x[k])
    # touching zeros: local minima of |g| that are tiny
    a = np.abs(y)
    for i in range(1, grid - 1):
        if a[i] <= a[i - 1] and a[i] <= a[i + 1] and a[i] < 1e-6 * scale:
            r = minimize_scalar(lambda t: abs(float(fun(np.array([t]))[0])), bounds=(x[i - 1], x[i + 1]),
                                method="bounded", options={"xatol": 1e-14})
            if abs(float(fun(np.array([r.x]))[0])) < 1e-12 * scale:
                roots.append(float(r.x))
    roots.sort()
    out = []
    for r in roots:
        if not out or r - out[-1] > 1e-9:
            out.append(float(r))
    return out


def single_joint_solutions(chain, exact: sp.Expr, j: int, lo: float, hi: float,
                           fn) -> tuple[list[float], list[str]]:
    """Roots of a one-joint factor inside [lo, hi]: numeric values and, where sympy finds them, exact forms."""
    n = chain.n

    def g1(x):
        Q = np.zeros((len(np.atleast_1d(x)), n))
        Q[:, j] = x
        return fn(Q)

    values = _roots_1d(g1, lo, hi)
    exact_str: list[str] = []
    try:
        sols = sp.solve(exact, sp.Symbol(f"q{j + 1}", real=True))
    except (NotImplementedError, ValueError, TypeError):
        sols = []
    revolute = chain.joints[j].is_revolute
    for v in values:
        label = None
        for sol in sols:
            if not sol.is_real:
                continue
            base = float(sol)
            k = round((v - base) / math.pi) if revolute else 0   # trig factors repeat every π or 2π
            if abs(base + math.pi * k - v) < 1e-8:
                label = str(sp.simplify(sol + sp.pi * k))
                break
        exact_str.append(label if label is not None else f"{v:.12g}")
    return values, exact_str


def sample_zero_set(fn, joints0: list[int], lower, upper, count: int, rng) -> np.ndarray:
    """Configurations on {g = 0}: the other joints random, the last factor joint solved in its range."""
    n = len(lower)
    solve = joints0[-1]
    out = []
    for _ in range(count * 4):
        q = rng.uniform(lower, upper)

        def g1(x, q=q):
            Q = np.repeat(q[None], len(np.atleast_1d(x)), axis=0)
            Q[:, solve] = x
            return fn(Q)

        roots = _roots_1d(g1, lower[solve], upper[solve], grid=400)
        if roots:
            q = q.copy()
            q[solve] = roots[rng.integers(len(roots))]
            out.append(q)
        if len(out) >= count:
            break
    return np.array(out).reshape(-1, n)


