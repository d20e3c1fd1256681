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

The exact path runs in a forked worker under a time and memory budget (:mod:`kin.singular.budget`);
its answer is cached on disk per chain (:mod:`kin.singular.cache`).  When it does not finish, the
numeric analysis of :mod:`kin.singular.numeric` answers instead (``method = "numeric"``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import sympy as sp

from kin.chain import Chain
from kin.singular import cache
from kin.singular.budget import DEFAULT_MEMORY, BudgetError, check_budget, run_with_budget
from kin.singular.component import SingularSet
from kin.singular.determinant import ROW_NAMES, derivation_text, wrist_centre
from kin.singular.exact import (
    StructureError,
    content_key,
    exact_structure,
    from_tree,
    numeric_form,
    rebuild,
    trig_form,
    validate_structure,
)
from kin.singular.kinds import classify
from kin.singular.numeric import KINDS, Progress, numeric_components
from kin.singular.solve import display_text, lambdify_factor, sample_zero_set
from kin.validation import is_real

#: default budget of the exact path (s); the bundled robots need 0.1–2.5 s on one core
DEFAULT_EXACT_TIMEOUT = 8.0
#: default budget of the numeric path (s)
DEFAULT_NUMERIC_TIME = 20.0


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
    """All components of a chain's singular set.

    ``method``: ``"exact"`` (``factors`` are :class:`SingularFactor`) or ``"numeric"`` (``factors``
    are :class:`~kin.singular.numeric.SingularComponent`); ``derivation``: how det J was split
    (exact) or how the set was sampled (numeric); ``budget``: the exact path's time budget, what it
    did (``done``, ``cached``, ``timeout``, ``memory``, ``error``) and the seconds each path took.
    """

    robot: str
    factors: list[SingularSet]
    method: str
    rows: tuple[str, ...]
    seconds: float
    lengths: dict[str, float]
    derivation: str = ""
    budget: dict = field(default_factory=dict)
    #: the seed and the per-factor sample count the zero-set samples (and a numeric analysis) came from
    seed: int = 0
    samples: int = 200
    #: the robot's content key (:func:`kin.singular.exact.content_key`): which robot this analysis is of
    content: str = ""

    def to_dict(self) -> dict:
        return {"robot": self.robot, "method": self.method, "derivation": self.derivation, "rows": list(self.rows),
                "factors": [f.to_dict() for f in self.factors], "lengths": self.lengths,
                "seconds": self.seconds, "budget": self.budget}

    def by_kind(self, kind: str) -> list[SingularFactor]:
        return [f for f in self.factors if f.kind == kind]

    def values(self, Q) -> np.ndarray:
        """Every factor at a batch (N, n) → (N, k) (exact analyses only: a numeric component has no formula)."""
        if self.method != "exact":
            raise StructureError(f"the singular set of {self.robot} was found numerically: its components have "
                                 "no formula to evaluate (use their distance())")
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        return np.stack([f(Q) for f in self.factors], axis=1) if self.factors else np.zeros((len(Q), 0))


def _exact_structure(robot, exact_timeout: float, exact_memory: int, use_cache: bool,
                     say: Progress, read_cache: bool = True) -> tuple[dict | None, dict]:
    """The factored determinant as data (from the cache or a budgeted worker) and what it cost."""
    key = content_key(robot)
    if use_cache and read_cache:
        cached = cache.load_cached(robot, key)
        if cached is not None:
            return cached, {"exact_status": "cached", "exact_seconds": 0.0}
    res = run_with_budget(exact_structure, (robot,), exact_timeout, exact_memory,
                          on_wait=lambda t: say("exact analysis (sympy)", min(t, exact_timeout), exact_timeout))
    info = {"exact_status": res.status, "exact_seconds": res.seconds}
    if res.detail:
        info["exact_detail"] = res.detail
    if res.status != "done":
        return None, info
    try:
        structure = validate_structure(res.value, robot.n, tuple(robot.task_rows))
    except StructureError as e:
        return None, {**info, "exact_status": "error", "exact_detail": str(e)}
    if use_cache:
        cache.store(robot, key, structure)
    return structure, info


def _consistent(fn, display: sp.Expr, n: int, lower, upper, rng) -> bool:
    """Whether a stored display expression equals the factor (evaluated at random configurations)."""
    fd, _ = lambdify_factor(display, n)
    Q = rng.uniform(lower, upper, size=(8, n))
    a, b = fn(Q), fd(Q)
    return bool(np.all(np.isfinite(b)) and np.allclose(a, b, rtol=1e-6, atol=1e-9 * (1 + np.abs(a).max())))


def _roots_hold(fn, values: list[float], j: int, n: int, lo: float, hi: float) -> bool:
    """Whether stored roots of a one-joint factor lie inside [lo, hi] and are zeros of it."""
    grid = np.zeros((200, n))
    grid[:, j] = np.linspace(lo, hi, 200)
    scale = max(float(np.abs(fn(grid)).max()), 1e-300)
    Q = np.zeros((len(values), n))
    Q[:, j] = values
    return bool(all(lo - 1e-9 <= v <= hi + 1e-9 for v in values)
                and (len(values) == 0 or np.abs(fn(Q)).max() <= 1e-7 * scale))


def _exact_factors(robot, structure: dict, samples: int, rng) -> tuple[list[SingularFactor], dict]:
    """The factors of a validated structure; raises :class:`StructureError` when its stored display
    forms or roots do not agree with its polynomials (a foreign or damaged cache file)."""
    chain: Chain = robot.chain
    n = chain.n
    polys, lengths, qsyms = rebuild(structure)
    wc = wrist_centre(robot) if structure["split"] == "wrist" else None
    lower, upper = chain.lower, chain.upper
    check = np.random.default_rng(99)
    factors: list[SingularFactor] = []
    for (g, mult, block), stored in zip(polys, structure["factors"]):
        sym_trig = trig_form(g, n)
        num_trig = numeric_form(sym_trig, lengths)
        if stored["negated"]:                    # g and −g have the same zero set
            sym_trig, num_trig = -sym_trig, -num_trig
        joints = tuple(sorted(i + 1 for i in range(n) if qsyms[i] in num_trig.free_symbols))
        fn, grad_fn = lambdify_factor(num_trig, n)
        shown = from_tree(stored["display"]["num"], n)
        shown_sym = from_tree(stored["display"]["sym"], n)
        if not _consistent(fn, shown, n, lower, upper, check) or \
                not _consistent(fn, numeric_form(shown_sym, lengths), n, lower, upper, check):
            raise StructureError("a stored display form does not match its factor")
        if len(joints) == 1:
            j = joints[0] - 1
            roots = stored["roots"]
            if roots is None or not _roots_hold(fn, roots["values"], j, n, lower[j], upper[j]):
                raise StructureError("stored roots are missing or are not zeros of their factor")
            values = [float(v) for v in roots["values"]]
            solutions = {"type": "values", "joint": joints[0], "values": values, "exact": list(roots["labels"])}
            per = max(1, samples // max(len(values), 1))
            S = []
            for v in values:
                Q = rng.uniform(lower, upper, size=(per, n))
                Q[:, j] = v
                S.append(Q)
            S = np.concatenate(S) if S else np.zeros((0, n))
        else:
            S = sample_zero_set(fn, [jj - 1 for jj in joints], lower, upper, samples, rng)
            ranges = {f"q{jj}": [float(S[:, jj - 1].min()), float(S[:, jj - 1].max())] if len(S) else None
                      for jj in joints}
            solutions = {"type": "manifold", "solve_for": joints[-1], "count": int(len(S)),
                         "ranges": ranges, "samples": np.round(S[:5], 9).tolist()}
        kind, meaning = classify(robot, joints, block, S, wc)
        factors.append(SingularFactor(expr=display_text(shown), symbolic=display_text(shown_sym), kind=kind,
                                      joints=joints, meaning=meaning, multiplicity=int(mult), block=block,
                                      solutions=solutions, n=n, fn=fn, grad_fn=grad_fn, samples=S))
    return factors, {str(k): v for k, v in lengths.items()}


def analyse_singularities(robot, samples: int = 200, seed: int = 0, exact_timeout: float = DEFAULT_EXACT_TIMEOUT,
                          exact_memory: int = DEFAULT_MEMORY, numeric_time: float = DEFAULT_NUMERIC_TIME,
                          use_cache: bool = True, progress: Progress | None = None) -> SingularityAnalysis:
    """Find, factor and name the singular set of ``robot`` (a :class:`kin.Robot`).

    ``samples``: configurations drawn on each factor's zero set (used to describe multi-joint
    factors and to classify); ``seed`` makes them reproducible.  ``exact_timeout`` (s) and
    ``exact_memory`` (bytes beyond this process's size) bound the exact factoring, which runs in a
    worker process; its answer is cached on disk (``use_cache``).  When it does not finish, the
    numeric analysis answers (``method = "numeric"``), its projections bounded by ``numeric_time``
    seconds.  ``progress(stage, done, total)`` is called as the work goes on (kin never prints).
    """
    check_budget(exact_timeout, exact_memory)
    if not (is_real(numeric_time) and 0 < numeric_time <= 3600):
        raise BudgetError(f"numeric_time {numeric_time!r} must be a number of seconds in (0, 3600]")
    say = progress or (lambda stage, done, total: None)
    t0 = time.perf_counter()
    chain: Chain = robot.chain
    rows = tuple(robot.task_rows)
    structure, budget = _exact_structure(robot, float(exact_timeout), exact_memory, use_cache, say)
    budget["exact_timeout"] = float(exact_timeout)
    rng = np.random.default_rng(seed)
    factors = None
    if structure is not None:
        try:
            factors, lengths = _exact_factors(robot, structure, samples, rng)
        except StructureError as e:
            if budget["exact_status"] != "cached":
                budget.update({"exact_status": "error", "exact_detail": str(e)})
            else:        # a cache file that passed the schema but not the checks: recompute once
                structure, budget = _exact_structure(robot, float(exact_timeout), exact_memory, use_cache, say,
                                                     read_cache=False)
                budget["exact_timeout"] = float(exact_timeout)
                if structure is not None:
                    try:
                        factors, lengths = _exact_factors(robot, structure, samples, rng)
                    except StructureError as e2:
                        budget.update({"exact_status": "error", "exact_detail": str(e2)})
    if factors is not None:
        order = {k: i for i, k in enumerate(KINDS)}
        factors.sort(key=lambda f: (order[f.kind], f.joints))
        return SingularityAnalysis(robot=chain.name, factors=factors, method="exact",
                                   rows=tuple(ROW_NAMES[r] for r in rows), seconds=time.perf_counter() - t0,
                                   lengths=lengths, budget=budget,
                                   derivation=derivation_text(structure["split"], chain.n, rows,
                                                              structure["lengths_numeric"]),
                                   seed=seed, samples=samples, content=content_key(robot))
    t1 = time.perf_counter()
    comps, info = numeric_components(robot, seed=seed, time_limit=float(numeric_time), progress=progress)
    budget.update({"numeric_seconds": time.perf_counter() - t1, **{f"numeric_{k}": v for k, v in info.items()
                                                                    if k != "seconds"}})
    derivation = (f"{info['starts']} Sobol samples projected onto σ_min = 0 by Gauss–Newton "
                  f"({info['converged']} converged), grouped by the joints the set depends on "
                  f"(the exact path: {budget['exact_status']} after {budget['exact_seconds']:.1f} s)")
    return SingularityAnalysis(robot=chain.name, factors=comps, method="numeric",
                               rows=tuple(ROW_NAMES[r] for r in rows), seconds=time.perf_counter() - t0,
                               lengths={}, derivation=derivation, budget=budget, seed=seed, samples=samples,
                               content=content_key(robot))
