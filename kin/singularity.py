"""The singular set of a chain, found symbolically, factored and named.

For a square task Jacobian, det J is computed exactly (sympy, polynomial arithmetic in c_i = cos q_i,
s_i = sin q_i and the prismatic q_i, link lengths kept as symbols) and factored into irreducible
factors; each factor is one component of the singular set.  Structure is used where the chain has
it, because det J is the same for every reference point (a change of reference point multiplies J
by a unit-determinant matrix):

* spherical wrist (last three revolute axes meet in one point): at the wrist centre
  J = [[J11, 0], [J21, J22]], so det J = det J11 · det J22 — positioning and wrist factors;
* three prismatic joints (a machine tool's linear axes): the prismatic columns have no angular
  part, so det J = −det Z · det W — linear axes (Z) and rotary head (W);
* otherwise the whole determinant, expressed in a middle link frame to keep it small.

Chains with fewer joints than task rows use det(Jᵀ·J), more joints det(J·Jᵀ).

Each factor is named by geometry, checked numerically on its zero set: *wrist* (two revolute axes
of the wrist become parallel), *elbow*/*boundary* (the arm is stretched or folded: parallel axes
lose the motion along the arm; *boundary* for positioning-only chains), *shoulder* (the wrist
centre or tool point on the axis of joint 1, or on its offset surface), *prismatic* (a prismatic
joint at zero extension), or *other*.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import sympy as sp
from scipy.optimize import brentq
from sympy.polys.matrices import DomainMatrix

from .chain import Chain
from .sympy_model import SympyChain, rational

#: above this many length symbols in a whole-Jacobian determinant, lengths are substituted first
MAX_SYMBOLIC_LENGTHS = 4
KINDS = ("wrist", "elbow", "shoulder", "boundary", "prismatic", "other")
_ROW_NAMES = ("x", "y", "z", "rx", "ry", "rz")


@dataclass
class SingularFactor:
    """One irreducible factor g(q) of det J; its zero set is one component of the singular set.

    ``expr``: g with numbers substituted (``sin(q5)``, ``0.74*cos(q3) - 0.1*sin(q3)``);
    ``symbolic``: the same with link lengths as symbols (``d4*cos(q3) - a3*sin(q3)``);
    ``joints``: 1-based joints it involves; ``solutions``: exact joint values (one-joint factors)
    or a sampled description of the manifold.
    """

    expr: str
    symbolic: str
    kind: str
    joints: tuple[int, ...]
    meaning: str
    multiplicity: int
    block: str
    solutions: dict
    n: int
    fn: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    grad_fn: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    samples: np.ndarray = field(repr=False, default_factory=lambda: np.zeros((0, 0)))

    def __call__(self, Q) -> np.ndarray:
        """g(q) for a batch (N, n) → (N,), or a float for one configuration."""
        arr = np.asarray(Q, dtype=float)
        single = arr.ndim == 1
        out = self.fn(arr.reshape(-1, self.n))
        return float(out[0]) if single else out

    def gradient(self, Q) -> np.ndarray:
        """∂g/∂q for a batch (N, n) → (N, n), or (n,) for one configuration."""
        arr = np.asarray(Q, dtype=float)
        single = arr.ndim == 1
        out = self.grad_fn(arr.reshape(-1, self.n))
        return out[0] if single else out

    @property
    def single_joint(self) -> int | None:
        """The 0-based joint index when the factor depends on one joint only."""
        return self.joints[0] - 1 if len(self.joints) == 1 else None

    def to_dict(self) -> dict:
        return {"expr": self.expr, "symbolic": self.symbolic, "kind": self.kind, "joints": list(self.joints),
                "meaning": self.meaning, "multiplicity": self.multiplicity, "block": self.block,
                "solutions": self.solutions}


@dataclass
class SingularityAnalysis:
    """All factors of a chain's singular set, with the method used."""

    robot: str
    factors: list[SingularFactor]
    method: str
    rows: tuple[str, ...]
    seconds: float
    lengths: dict[str, float]

    def to_dict(self) -> dict:
        return {"robot": self.robot, "method": self.method, "rows": list(self.rows),
                "factors": [f.to_dict() for f in self.factors], "lengths": self.lengths,
                "seconds": self.seconds}

    def by_kind(self, kind: str) -> list[SingularFactor]:
        return [f for f in self.factors if f.kind == kind]

    def values(self, Q) -> np.ndarray:
        """Every factor at a batch (N, n) → (N, k)."""
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        return np.stack([f(Q) for f in self.factors], axis=1) if self.factors else np.zeros((len(Q), 0))


# ---- determinant ----------------------------------------------------------------------------------
def _poly_det(M: sp.Matrix) -> sp.Expr:
    dM = DomainMatrix.from_Matrix(M)
    return dM.domain.to_sympy(dM.det())


def _numeric_axes(robot, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Joint axes z (N, n, 3) and points o (N, n, 3) in the base frame, from the CasADi model."""
    sym = robot.symbolic
    import casadi as ca
    f = ca.Function("axes", [sym.q, sym.p], [ca.horzcat(*[z for z, _ in sym.axes]),
                                              ca.horzcat(*[o for _, o in sym.axes])])
    Z, O = [], []
    for q in Q:
        z, o = f(q, robot.chain.parameter_values)
        Z.append(np.array(z).T)
        O.append(np.array(o).T)
    return np.array(Z), np.array(O)


def _closest_point(z1, o1, z2, o2) -> tuple[np.ndarray, float]:
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
    Z, O = _numeric_axes(robot, Q)
    frames = robot.symbolic.frames_function
    local = []
    for q, z, o in zip(Q, Z, O):
        p1, d1 = _closest_point(z[n - 3], o[n - 3], z[n - 2], o[n - 2])
        p2, d2 = _closest_point(z[n - 2], o[n - 2], z[n - 1], o[n - 1])
        if d1 > 1e-9 or d2 > 1e-9 or np.linalg.norm(p1 - p2) > 1e-9:
            return None
        F = np.array(frames(q, chain.parameter_values)[0])
        Tk = F[:, 4 * (n - 3):4 * (n - 2)]
        local.append(np.linalg.solve(Tk, np.append(p1, 1.0)))
    if np.ptp(np.array(local), axis=0).max() > 1e-9:
        return None
    return n - 3, np.mean(local, axis=0)


def _det_and_blocks(robot, model: SympyChain) -> tuple[list[tuple[sp.Expr, str]], str, tuple[int, ...]]:
    """[(determinant polynomial, block name)], method description, task rows."""
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
                    "det J = det J11 · det J22 (spherical wrist: Jacobian split at the wrist centre)", rows)
        pris = [i for i, j in enumerate(chain.joints) if not j.is_revolute]
        rev = [i for i, j in enumerate(chain.joints) if j.is_revolute]
        if len(pris) == 3:
            p0 = sp.zeros(3, 1)
            cols = [model.column(i, p0) for i in range(n)]
            Z = sp.Matrix.hstack(*[cols[i][:3, 0] for i in pris])
            W = sp.Matrix.hstack(*[cols[i][3:, 0] for i in rev])
            return ([(_poly_det(Z), "linear axes"), (_poly_det(W), "rotary axes")],
                    "det J = −det Z · det W (three prismatic joints: linear axes Z, rotary axes W)", rows)
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
        note = ""
        if len(used) > MAX_SYMBOLIC_LENGTHS:
            # factoring in many length symbols is slow; numbers keep it within seconds
            J = J.subs({k: rational(v) for k, v in model.lengths.items()}).applyfunc(sp.expand)
            note = ", lengths numeric"
        return ([(_poly_det(J), "full")],
                f"det J (whole 6×6 Jacobian at the last joint's axis, q1 = q{n} = 0 without loss{note})", rows)
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
        return [(_poly_det(J), "task")], f"det J (task rows {' '.join(_ROW_NAMES[r] for r in rows)})", rows
    G = (J * J.T if m < n else J.T * J).applyfunc(sp.expand)
    which = "J·Jᵀ" if m < n else "Jᵀ·J"
    return [(_poly_det(G), "task")], f"det({which}) (task rows {' '.join(_ROW_NAMES[r] for r in rows)})", rows


def _reduce_factors(model: SympyChain, poly: sp.Expr) -> list[tuple[sp.Expr, int]]:
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


# ---- numeric helpers -------------------------------------------------------------------------------
def _pretty(expr: sp.Expr) -> str:
    """Readable form: floats with up to 6 significant digits, trig combined when it shortens it."""
    e = expr
    if len(sp.Add.make_args(e)) <= 12:
        try:
            t = sp.trigsimp(e)
            if sp.count_ops(t) <= sp.count_ops(e):
                e = t
        except Exception:  # noqa: BLE001 - trigsimp is cosmetic
            pass
    e = e.xreplace({x: sp.Float(float(x), 15) for x in e.atoms(sp.Number) if not x.is_Integer})
    s = sp.sstr(e, full_prec=False)
    return s


def _lambdify(model: SympyChain, expr: sp.Expr, n: int):
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
            from scipy.optimize import minimize_scalar
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


def _single_joint_solutions(model: SympyChain, exact: sp.Expr, j: int, lo: float, hi: float,
                            fn) -> tuple[list[float], list[str]]:
    """Roots of a one-joint factor inside [lo, hi]: numeric values and, where sympy finds them, exact forms."""
    n = model.chain.n

    def g1(x):
        Q = np.zeros((len(np.atleast_1d(x)), n))
        Q[:, j] = x
        return fn(Q)

    values = _roots_1d(g1, lo, hi)
    exact_str: list[str] = []
    try:
        sols = sp.solve(exact, model.q[j])
    except (NotImplementedError, ValueError, TypeError):
        sols = []
    revolute = model.chain.joints[j].is_revolute
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


def _sample_zero_set(fn, joints0: list[int], lower, upper, count: int, rng) -> np.ndarray:
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


def _parallel_pairs(Z: np.ndarray, revolute: list[int], tol: float = 1e-6) -> set[tuple[int, int]]:
    out = set()
    for a in range(len(revolute)):
        for b in range(a + 1, len(revolute)):
            i, j = revolute[a], revolute[b]
            if np.linalg.norm(np.cross(Z[i], Z[j])) < tol:
                out.add((i, j))
    return out


def _classify(robot, factor_joints: tuple[int, ...], block: str, samples: np.ndarray,
              wc: tuple[int, np.ndarray] | None) -> tuple[str, str]:
    """(kind, one-line meaning) of a factor from its zero-set samples."""
    chain = robot.chain
    n = chain.n
    names = ", ".join(f"q{j}" for j in factor_joints)
    revolute = [i for i, j in enumerate(chain.joints) if j.is_revolute]
    positioning_only = set(robot.task_rows) <= {0, 1, 2}
    point = "wrist centre" if wc is not None else "tool point"
    if all(not chain.joints[j - 1].is_revolute for j in factor_joints):
        return "prismatic", (f"prismatic joint{'s' if len(factor_joints) > 1 else ''} {names} at zero extension: "
                             f"the {point} sits on the axes of the joints before it")
    if len(samples) == 0:
        return "other", f"{names}: no configuration inside the joint limits reaches this factor's zero set"
    generic = robot.random_configurations(1, seed=12345)[0]
    Zg, _ = _numeric_axes(robot, generic[None])
    generic_pairs = _parallel_pairs(Zg[0], revolute)
    use = samples[: min(len(samples), 12)]
    Z, O = _numeric_axes(robot, use)
    if block in ("wrist", "rotary axes"):
        pairs = set.intersection(*[_parallel_pairs(z, revolute) - generic_pairs for z in Z]) if len(Z) else set()
        pair = " and ".join(f"{i + 1}" for i in sorted(pairs)[0]) if pairs else "of the wrist"
        what = "the wrist" if block == "wrist" else "the rotary head"
        return "wrist", f"axes of joints {pair} become parallel: {what} loses one rotation ({names} singular)"
    votes: dict[str, int] = {}
    for q, z, o in zip(use, Z, O):
        new_pairs = _parallel_pairs(z, revolute) - generic_pairs
        if block == "full" and any(i >= n - 3 and j >= n - 3 for i, j in new_pairs):
            votes["wrist"] = votes.get("wrist", 0) + 1
            continue
        if block == "positioning" and wc is not None:
            k, w_local = wc
            F = np.array(robot.symbolic.frames_function(q, chain.parameter_values)[0])
            w = (F[:, 4 * k:4 * (k + 1)] @ w_local)[:3]
            cols = [np.cross(z[i], w - o[i]) if chain.joints[i].is_revolute else z[i] for i in range(3)]
            M = np.array(cols).T
            idx = [0, 1, 2]
        else:
            M = robot.jacobian(q)[list(robot.task_rows)]
            idx = list(range(n))
        v = np.linalg.svd(M)[2][-1]
        support = [idx[i] for i in range(len(idx)) if abs(v[i]) > 0.05 * np.abs(v).max()]
        # stretched/folded: the lost motion comes from revolute joints whose axes are all parallel
        # to the factor's own joint axes (joints 2 and 3 of an arm, 1 and 2 of a SCARA)
        own = [j - 1 for j in factor_joints]
        parallel = all(chain.joints[i].is_revolute for i in support + own) and all(
            np.linalg.norm(np.cross(z[own[0]], z[i])) < 1e-6 for i in support + own)
        if parallel and 0 not in [j - 1 for j in factor_joints]:
            kind = "boundary" if positioning_only else "elbow"
        elif 0 in support and chain.joints[0].is_revolute:
            kind = "shoulder"
        else:
            kind = "other"
        votes[kind] = votes.get(kind, 0) + 1
    kind = max(votes, key=lambda k: votes[k])
    meaning = {
        "wrist": f"two wrist axes become parallel: the wrist loses one rotation ({names} singular)",
        "elbow": f"arm stretched or folded ({names}): the {point} is at the boundary of its reach and cannot move along the arm",
        "boundary": f"arm stretched or folded ({names}): the {point} is on the workspace boundary",
        "shoulder": f"the {point} lies on the axis of joint 1 (or on its offset surface): joint 1 cannot move it sideways",
        "other": f"joints {names} lose a direction of motion together",
    }[kind]
    return kind, meaning


def analyse_singularities(robot, samples: int = 200, seed: int = 0) -> SingularityAnalysis:
    """Find, factor and name the singular set of ``robot`` (a :class:`kin.Robot`).

    ``samples``: configurations drawn on each factor's zero set (used to describe multi-joint
    factors and to classify); ``seed`` makes them reproducible.
    """
    t0 = time.perf_counter()
    chain: Chain = robot.chain
    n = chain.n
    model = SympyChain(chain, keep_lengths=True)
    blocks, method, rows = _det_and_blocks(robot, model)
    wc = wrist_centre(robot) if "wrist centre" in method else None
    rng = np.random.default_rng(seed)
    lower, upper = chain.lower, chain.upper
    factors: list[SingularFactor] = []
    for poly, block in blocks:
        for g, mult in _reduce_factors(model, poly):
            sym_trig = model.to_trig(g)
            num_trig = model.numeric(sym_trig)
            if _pretty(num_trig).startswith("-"):      # g and −g have the same zero set
                sym_trig, num_trig = -sym_trig, -num_trig
            joints = tuple(sorted(i + 1 for i in range(n) if model.q[i] in num_trig.free_symbols))
            fn, grad_fn = _lambdify(model, num_trig, n)
            if len(joints) == 1:
                j = joints[0] - 1
                values, exact = _single_joint_solutions(model, num_trig, j, lower[j], upper[j], fn)
                solutions = {"type": "values", "joint": joints[0], "values": values, "exact": exact}
                per = max(1, samples // max(len(values), 1))
                S = []
                for v in values:
                    Q = rng.uniform(lower, upper, size=(per, n))
                    Q[:, j] = v
                    S.append(Q)
                S = np.concatenate(S) if S else np.zeros((0, n))
            else:
                S = _sample_zero_set(fn, [jj - 1 for jj in joints], lower, upper, samples, rng)
                ranges = {f"q{jj}": [float(S[:, jj - 1].min()), float(S[:, jj - 1].max())] if len(S) else None
                          for jj in joints}
                solutions = {"type": "manifold", "solve_for": joints[-1], "count": int(len(S)),
                             "ranges": ranges, "samples": np.round(S[:5], 9).tolist()}
            kind, meaning = _classify(robot, joints, block, S, wc)
            factors.append(SingularFactor(expr=_pretty(num_trig), symbolic=_pretty(sym_trig), kind=kind,
                                          joints=joints, meaning=meaning, multiplicity=int(mult), block=block,
                                          solutions=solutions, n=n, fn=fn, grad_fn=grad_fn, samples=S))
    order = {k: i for i, k in enumerate(KINDS)}
    factors.sort(key=lambda f: (order[f.kind], f.joints))
    return SingularityAnalysis(robot=chain.name, factors=factors, method=method,
                               rows=tuple(_ROW_NAMES[r] for r in rows),
                               seconds=time.perf_counter() - t0,
                               lengths={str(k): v for k, v in model.lengths.items()})
