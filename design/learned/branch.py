"""IK branches for learned inverse kinematics: which class of configurations a model learns, and
the checks and seed streams shared by the learned-IK modules.  See :mod:`design.learned.ik`."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np

import kin
from kin.errors import RmtError
from kin.singular import SingularFactor, SingularityAnalysis, analyse_singularities

_STREAM_TRAIN, _STREAM_HELDOUT, _STREAM_EVAL = 1, 2, 3


class LearnedIKError(RmtError, ValueError):
    """A learned-IK request is invalid (sample counts, seed, branch, network settings, poses)."""


# ---- validation helpers ---------------------------------------------------------------------------
def _check_int(name: str, value: Any, minimum: int = 1) -> int:
    ok = not isinstance(value, (bool, np.bool_)) and isinstance(value, (int, np.integer)) and value >= minimum
    if not ok:
        raise LearnedIKError(f"{name} must be an integer ≥ {minimum}; got {value!r}")
    return int(value)


def _check_seed(seed: Any) -> int:
    ok = not isinstance(seed, (bool, np.bool_)) and isinstance(seed, (int, np.integer)) and 0 <= seed < 2 ** 32
    if not ok:
        raise LearnedIKError(f"seed must be an integer in [0, 2**32); got {seed!r}")
    return int(seed)


def _check_float(name: str, value: Any, lo: float, hi: float, lo_open: bool = False, hi_open: bool = False) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if isinstance(value, (bool, np.bool_)) or not math.isfinite(x) or x < lo or x > hi or (lo_open and x == lo) \
            or (hi_open and x == hi):
        interval = f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"
        raise LearnedIKError(f"{name} must be a number in {interval}; got {value!r}")
    return x


def _rng(seed: int, stream: int, extra: int = 0) -> np.random.Generator:
    return np.random.default_rng([seed, stream, extra])


def _as_robot(robot) -> kin.Robot:
    return kin.load_robot(robot) if isinstance(robot, str) else robot


# ---- branches -------------------------------------------------------------------------------------
@dataclass
class Branch:
    """One class of configurations (an IK branch): a box of joint ranges plus sign conditions.

    ``spec``: the normalised ``{key: sign}`` it was built from; ``lower``/``upper`` (n,): the
    joint ranges (SI) after the branch's restrictions and the 2π cut; ``conditions``: list of
    (key, sign, g) meaning sign·g(q) ≥ 0 for multi-joint factors g.
    """

    spec: dict
    lower: np.ndarray
    upper: np.ndarray
    conditions: list[tuple[str, int, Callable[[np.ndarray], np.ndarray]]] = field(default_factory=list)
    pivots: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return len(self.lower)

    def contains(self, Q: np.ndarray, tol: float = 1e-9) -> np.ndarray:
        """(N,) bool: configurations (N, n) inside the branch (boundaries included)."""
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        inside = np.all((Q >= self.lower - tol) & (Q <= self.upper + tol), axis=1)
        for _, s, g in self.conditions:
            inside &= s * g(Q) >= -tol
        return inside

    def sample(self, N: int, rng: np.random.Generator, max_rounds: int = 50) -> np.ndarray:
        """N configurations uniform in the branch (rejection from the box for the sign conditions)."""
        out, have = [], 0
        for _ in range(max_rounds):
            Q = rng.uniform(self.lower, self.upper, size=(max(2 * (N - have), 64), self.n))
            Q = Q[self.contains(Q, tol=0.0)]
            out.append(Q)
            have += len(Q)
            if have >= N:
                return np.concatenate(out)[:N]
        raise LearnedIKError(f"branch {self.spec_text()} holds too few configurations to sample {N} "
                             "(its sign conditions exclude almost all of the joint box); choose another branch")

    def spec_text(self) -> str:
        return "{" + ", ".join(f"{k!r}: {s:+d}" for k, s in self.spec.items()) + "}"

    def to_dict(self) -> dict:
        return {"spec": {str(k): int(s) for k, s in self.spec.items()},
                "ranges": {f"q{j + 1}": [float(self.lower[j]), float(self.upper[j])] for j in range(self.n)},
                "conditions": [f"{s:+d}·({key}) ≥ 0" for key, s, _ in self.conditions],
                "pivots": {f"q{j + 1}": float(p) for j, p in self.pivots.items()}}


def _factor_keys(factors: list[SingularFactor]) -> dict[str, SingularFactor]:
    """Keys of the multi-joint factors: the kind when unique among them, else the expression."""
    multi = [f for f in factors if f.single_joint is None]
    kinds = [f.kind for f in multi]
    return {(f.kind if kinds.count(f.kind) == 1 else f.expr): f for f in multi}


def _roots_by_joint(factors: list[SingularFactor], n: int) -> dict[int, list[float]]:
    roots: dict[int, list[float]] = {}
    for f in factors:
        j = f.single_joint
        if j is not None and f.solutions.get("values"):
            roots.setdefault(j, []).extend(float(v) for v in f.solutions["values"])
    return {j: sorted(set(v)) for j, v in roots.items()}


def _check_branch_spec(branch: Any, n: int, keys: dict[str, SingularFactor]) -> dict:
    allowed = f"joints 1–{n} (1-based)" + (f" or the multi-joint factors {', '.join(map(repr, keys))}" if keys else "")
    if not isinstance(branch, Mapping):
        raise LearnedIKError(f"branch must be a dict {{joint (1-based) or factor kind: sign ±1}}; got {branch!r}")
    spec: dict = {}
    for key, sign in branch.items():
        if isinstance(key, (int, np.integer)) and not isinstance(key, (bool, np.bool_)):
            if not 1 <= key <= n:
                raise LearnedIKError(f"branch: joint {key!r} unknown; allowed: {allowed}")
            key = int(key)
        elif isinstance(key, str):
            if key not in keys:
                raise LearnedIKError(f"branch: key {key!r} unknown; allowed: {allowed}")
        else:
            raise LearnedIKError(f"branch: key {key!r} unknown; allowed: {allowed}")
        if isinstance(sign, (bool, np.bool_)) or not isinstance(sign, (int, float, np.integer, np.floating)) \
                or sign not in (1, -1):
            raise LearnedIKError(f"branch[{key!r}] = {sign!r}: the sign must be +1 or -1")
        spec[key] = int(sign)
    return spec


def _side(lo: float, hi: float, pivot: float, roots: list[float], sign: int) -> tuple[float, float]:
    if sign > 0:
        nxt = [r for r in roots if r > pivot + 1e-12]
        return pivot, min(nxt[0], hi) if nxt else hi
    prv = [r for r in roots if r < pivot - 1e-12]
    return max(prv[-1], lo) if prv else lo, pivot


def resolve_branch(robot, branch: Mapping | None = None, analysis: SingularityAnalysis | None = None) -> Branch:
    """The :class:`Branch` of ``robot`` described by ``branch`` (see the module docstring;
    ``None`` → the default branch).  ``analysis`` defaults to ``analyse_singularities(robot)``."""
    robot = _as_robot(robot)
    chain = robot.chain
    n = chain.n
    analysis = analysis if analysis is not None else analyse_singularities(robot)
    factors = analysis.factors
    keys = _factor_keys(factors)
    roots = _roots_by_joint(factors, n)
    lo0, hi0 = np.array(chain.lower, float), np.array(chain.upper, float)
    revolute = [chain.joints[j].is_revolute for j in range(n)]

    def pivot_of(j: int) -> float:
        rs = roots.get(j)
        mid = 0.5 * (lo0[j] + hi0[j])
        if rs:
            return min(rs, key=lambda r: (abs(r - mid), r))
        return 0.0 if lo0[j] <= 0.0 <= hi0[j] else mid

    if branch is None:
        spec: dict = {}
        for j in sorted(roots):
            p = pivot_of(j)
            up = _side(lo0[j], hi0[j], p, roots[j], +1)
            dn = _side(lo0[j], hi0[j], p, roots[j], -1)
            if up[1] - up[0] <= 0 and dn[1] - dn[0] <= 0:
                continue
            spec[j + 1] = +1 if up[1] - up[0] >= dn[1] - dn[0] else -1
    else:
        spec = _check_branch_spec(branch, n, keys)

    lower, upper = lo0.copy(), hi0.copy()
    pivots: dict[int, float] = {}
    for key, s in spec.items():
        if isinstance(key, str):
            continue
        j = key - 1
        p = pivot_of(j)
        a, b = _side(lo0[j], hi0[j], p, roots.get(j, []), s)
        if not b - a > 1e-9:
            raise LearnedIKError(f"branch[{key}] = {s:+d} leaves joint {key} no range: its pivot {p:.6g} is at the "
                                 f"{'upper' if s > 0 else 'lower'} limit; use {-s:+d}")
        lower[j], upper[j] = a, b
        pivots[j] = p
    for j in range(n):
        if revolute[j] and upper[j] - lower[j] > 2 * math.pi:
            if j in pivots and spec.get(j + 1, 0) > 0:
                upper[j] = lower[j] + 2 * math.pi
            elif j in pivots:
                lower[j] = upper[j] - 2 * math.pi
            else:
                c = 0.5 * (lower[j] + upper[j])
                lower[j], upper[j] = c - math.pi, c + math.pi

    conditions: list = []
    if branch is None:
        # multi-joint factors: the majority sign inside the box (a fixed draw: the default branch is a
        # property of the robot, not of the seed)
        probe = np.random.default_rng(0).uniform(lower, upper, size=(4000, n))
        for key, f in keys.items():
            if len(f.samples) == 0:
                continue
            g = f(probe)
            s = +1 if np.mean(g >= 0) >= 0.5 else -1
            spec[key] = s
            conditions.append((key, s, f.fn))
            probe = probe[s * g >= 0]
            if len(probe) < 100:
                raise LearnedIKError(f"default branch of {robot.name}: the sign conditions leave too few "
                                     "configurations; give branch explicitly")
    else:
        for key, s in spec.items():
            if isinstance(key, str):
                conditions.append((key, s, keys[key].fn))
    return Branch(spec=spec, lower=lower, upper=upper, conditions=conditions, pivots=pivots)


