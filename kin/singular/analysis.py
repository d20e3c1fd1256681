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

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from kin.chain import Chain
from kin.singular.determinant import ROW_NAMES, det_and_blocks, reduce_factors, wrist_centre
from kin.singular.kinds import classify
from kin.singular.solve import lambdify_factor, pretty, sample_zero_set, single_joint_solutions
from kin.singular.sympy_model import SympyChain

#: above this many length symbols in a whole-Jacobian determinant, lengths are substituted first
KINDS = ("wrist", "elbow", "shoulder", "boundary", "prismatic", "other")


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


def analyse_singularities(robot, samples: int = 200, seed: int = 0) -> SingularityAnalysis:
    """Find, factor and name the singular set of ``robot`` (a :class:`kin.Robot`).

    ``samples``: configurations drawn on each factor's zero set (used to describe multi-joint
    factors and to classify); ``seed`` makes them reproducible.
    """
    t0 = time.perf_counter()
    chain: Chain = robot.chain
    n = chain.n
    model = SympyChain(chain, keep_lengths=True)
    blocks, method, rows = det_and_blocks(robot, model)
    wc = wrist_centre(robot) if "wrist centre" in method else None
    rng = np.random.default_rng(seed)
    lower, upper = chain.lower, chain.upper
    factors: list[SingularFactor] = []
    for poly, block in blocks:
        for g, mult in reduce_factors(model, poly):
            sym_trig = model.to_trig(g)
            num_trig = model.numeric(sym_trig)
            if pretty(num_trig).startswith("-"):      # g and −g have the same zero set
                sym_trig, num_trig = -sym_trig, -num_trig
            joints = tuple(sorted(i + 1 for i in range(n) if model.q[i] in num_trig.free_symbols))
            fn, grad_fn = lambdify_factor(model, num_trig, n)
            if len(joints) == 1:
                j = joints[0] - 1
                values, exact = single_joint_solutions(model, num_trig, j, lower[j], upper[j], fn)
                solutions = {"type": "values", "joint": joints[0], "values": values, "exact": exact}
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
            factors.append(SingularFactor(expr=pretty(num_trig), symbolic=pretty(sym_trig), kind=kind,
                                          joints=joints, meaning=meaning, multiplicity=int(mult), block=block,
                                          solutions=solutions, n=n, fn=fn, grad_fn=grad_fn, samples=S))
    order = {k: i for i, k in enumerate(KINDS)}
    factors.sort(key=lambda f: (order[f.kind], f.joints))
    return SingularityAnalysis(robot=chain.name, factors=factors, method=method,
                               rows=tuple(ROW_NAMES[r] for r in rows),
                               seconds=time.perf_counter() - t0,
                               lengths={str(k): v for k, v in model.lengths.items()})
