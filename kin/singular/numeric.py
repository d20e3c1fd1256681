"""The singular set of any chain, found numerically: the answer when the exact factoring does not
finish within its budget.

1. Sobol samples of the joint space (``scipy.stats.qmc``) are projected onto the singular set by
   Gauss–Newton (:mod:`kin.singular.projection`; for a redundant arm the set where J·Jᵀ is
   singular).
2. Each converged point's *support* — the joints whose direction is not tangent to the set, i.e.
   the joints the component depends on — is read off the normal space (the gradient of σ_min on
   the set).  Points are grouped by support; a group is one component, densified by projecting
   more starts within its own joints.
3. Each component is described: its joints; for a one-joint component the joint values of its
   sheets (q_j = r); the lost motion (the left singular vector u in the tool frame: the tool
   direction the arm cannot move in); a name where the geometry says one (wrist: two of the last
   three axes parallel; elbow: the arm stretched or folded — the lost motion comes from parallel
   axes; shoulder: the wrist centre on the axis of joint 1, or joint 1 in the positioning null
   motion; :mod:`kin.singular.kinds`); sample points on the set.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.spatial import cKDTree
from scipy.stats import qmc

from kin.singular.determinant import wrist_centre
from kin.singular.kinds import NUMERIC_MEANINGS, axis_lines, lost_motion, name_point, parallel
from kin.singular.projection import project, residuals, support

#: a group smaller than this share of the converged points is merged into a larger one
MIN_GROUP_SHARE = 0.02
#: how far beyond the joint limits :meth:`SingularComponent.absorb` follows the set (rad or m)
ABSORB_SLACK = 0.5
#: a sample's tangent disc reaches its this-many-th nearest sample
DISC_NEIGHBOURS = 3
KINDS = ("wrist", "elbow", "shoulder", "boundary", "prismatic", "other")

Progress = Callable[[str, float, float], None]


@dataclass
class SingularComponent:
    """One component of the singular set found numerically (SI units).

    ``joints``: 1-based joints it depends on; ``points``: sampled configurations on the set (K, n);
    ``normals``: a unit normal of the set at each point (K, n); ``solutions``: the joint values of a
    one-joint component (``type = "values"``) or a summary of the sampled manifold; ``lost_motion``:
    the tool-frame direction the arm cannot move in; ``resolution``: largest distance from a point
    of the set to its nearest sample (joint space, over the component's joints), estimated on
    fresh projections.
    """

    kind: str
    joints: tuple[int, ...]
    meaning: str
    solutions: dict
    n: int
    points: np.ndarray = field(repr=False)
    normals: np.ndarray = field(repr=False)
    lost_motion: dict = field(default_factory=dict)
    kind_shares: dict = field(default_factory=dict)
    resolution: float = math.nan
    codimension: int = 1
    tolerance: float = 1e-10
    multiplicity: int = 1
    block: str = "numeric"
    _tree: cKDTree | None = field(default=None, repr=False, compare=False)
    _radius: np.ndarray | None = field(default=None, repr=False, compare=False)

    @property
    def expr(self) -> str:
        """For a one-joint component, the polynomial (q_j − r_1)·(q_j − r_2)… of its sheets (in the
        grammar windows files accept); otherwise a label, as the component has no formula."""
        if self.single_joint is not None and self.solutions.get("values"):
            j = self.joints[0]
            return "*".join(f"q{j}" if r == 0 else f"(q{j} {'-' if r > 0 else '+'} {abs(r)!r})"
                            for r in self.solutions["values"])
        return f"sigma_min(J; {', '.join(f'q{j}' for j in self.joints)})"

    @property
    def symbolic(self) -> str:
        return self.expr

    @property
    def samples(self) -> np.ndarray:
        """The sampled configurations on the set (K, n) (the name the exact factors use)."""
        return self.points

    @property
    def single_joint(self) -> int | None:
        """The 0-based joint index when the component depends on one joint only."""
        return self.joints[0] - 1 if len(self.joints) == 1 else None

    @property
    def local_normals(self) -> np.ndarray | None:
        """Unit normals over the component's joints (K, len(joints)) when the set is a hypersurface
        (square task Jacobian), else None (a set of higher codimension has no single normal)."""
        if self.codimension != 1 or len(self.points) == 0:
            return None
        N = self.normals[:, [j - 1 for j in self.joints]]
        return N / np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)

    def _index(self) -> cKDTree:
        """KD-tree of the points over the component's joints (built on first use)."""
        if self._tree is None:
            self._tree = cKDTree(self.points[:, [j - 1 for j in self.joints]])
        return self._tree

    @property
    def radius(self) -> np.ndarray:
        """Radius of the tangent disc each sample stands for (K,): the distance to its
        :data:`DISC_NEIGHBOURS`-th nearest sample, so that neighbouring discs overlap."""
        if len(self.points) < 2:
            return np.zeros(len(self.points))
        k = min(DISC_NEIGHBOURS + 1, len(self.points))
        return self._index().query(self.points[:, [j - 1 for j in self.joints]], k=k)[0][:, -1]

    def distance(self, Q) -> np.ndarray:
        """Joint-space distance (over the component's joints) from configurations (N, n) to the
        sampled set (see :func:`sampled_distance`) → (N,); inf when the component has no point."""
        Q2 = np.asarray(Q, dtype=float).reshape(-1, self.n)
        if len(self.points) == 0:
            return np.full(len(Q2), np.inf)
        if self._radius is None:
            self._radius = self.radius
        return sampled_distance(self._index(), self.local_normals, self._radius,
                                Q2[:, [j - 1 for j in self.joints]])

    def absorb(self, robot, Q, limit: int = 2000) -> int:
        """Project configurations (N, n) onto the singular set and keep, as new points of this
        component, those landing on it (same joints) — filling the sampling gaps near ``Q`` (the
        dexterity windows use it where σ_min is low far from every sample).  Returns how many."""
        Q = np.asarray(Q, dtype=float).reshape(-1, self.n)
        if len(Q) == 0 or len(self.points) == 0:
            return 0
        far = np.argsort(-self.distance(Q))[:limit]
        # the set beyond the joint limits counts too: a configuration near a limit may be nearest to it
        Qp, ok = project(robot, Q[far], tol=self.tolerance, slack=ABSORB_SLACK)
        Qp = Qp[ok]
        if len(Qp) == 0:
            return 0
        _, _, G, _, _ = residuals(robot, Qp)
        supp, nrm = support(G)
        same = np.all(supp == np.isin(np.arange(self.n), [j - 1 for j in self.joints])[None], axis=1)
        if same.any():
            self.points = np.concatenate([self.points, Qp[same]])
            self.normals = np.concatenate([self.normals, nrm[same]])
            self._tree = self._radius = None
        return int(same.sum())

    def normal_at(self, Q) -> np.ndarray:
        """Unit normal of the set (N, n) at the sampled point nearest each configuration (N, n)."""
        Q2 = np.asarray(Q, dtype=float).reshape(-1, self.n)
        if len(self.points) == 0:
            return np.zeros_like(Q2)
        return self.normals[self._index().query(Q2[:, [j - 1 for j in self.joints]])[1]]

    def to_dict(self) -> dict:
        return {"expr": self.expr, "symbolic": self.symbolic, "kind": self.kind, "joints": list(self.joints),
                "meaning": self.meaning, "multiplicity": self.multiplicity, "block": self.block,
                "solutions": self.solutions, "lost_motion": self.lost_motion, "kind_shares": self.kind_shares,
                "resolution": self.resolution, "points": int(len(self.points))}


def sampled_distance(tree: cKDTree, normals: np.ndarray | None, radius: np.ndarray | None, X: np.ndarray,
                     k: int = 16) -> np.ndarray:
    """Distance from points X (N, d) to a sampled set: with ``normals`` (K, d) each sample stands
    for the disc of ``radius`` (K,) around it in its tangent plane (the distance to a disc is
    √((n·Δ)² + max(‖Δ_t‖ − radius, 0)²)), minimised over the ``k`` nearest samples; without
    normals, the distance to the nearest sample."""
    if normals is None or radius is None:
        return tree.query(X)[0]
    k = min(k, tree.n)
    _, idx = tree.query(X, k=k)
    idx = idx.reshape(len(X), k)
    D = X[:, None, :] - tree.data[idx]                  # (N, k, d)
    h = np.einsum("nkd,nkd->nk", D, normals[idx])
    t = np.sqrt(np.maximum(np.einsum("nkd,nkd->nk", D, D) - h * h, 0.0))
    return np.sqrt(h * h + np.maximum(t - radius[idx], 0.0) ** 2).min(axis=1)


def _sheet_values(x: np.ndarray, gap: float = 1e-4) -> list[float]:
    xs = np.sort(x)
    groups = np.split(xs, np.flatnonzero(np.diff(xs) > gap) + 1)
    return [round(float(np.median(g)), 12) + 0.0 for g in groups if len(g)]


# ---- the analysis ---------------------------------------------------------------------------------
def numeric_components(robot, samples: int = 1024, seed: int = 0, time_limit: float = 30.0,
                       points_per_component: int = 4000,
                       progress: Progress | None = None) -> tuple[list[SingularComponent], dict]:
    """Components of the singular set of ``robot`` (see the module docstring) → (components, info).

    ``samples``: Sobol starting points (rounded up to a power of two); ``time_limit``: seconds for
    the projections — 60 % for the starting points, the rest shared by the components'
    densification; the answer is built from what converged by then, and describing the components
    adds at most a few seconds more; ``points_per_component``: target number of sampled points per
    multi-joint component (densified by re-projection).
    """
    t0 = time.perf_counter()
    deadline = t0 + time_limit
    project_deadline = t0 + 0.6 * time_limit     # the rest is shared by the components' densification
    chain = robot.chain
    n = chain.n
    lo, hi = chain.lower, chain.upper
    say = progress or (lambda stage, done, total: None)
    m2 = max(4, math.ceil(math.log2(max(samples, 16))))
    S0 = qmc.Sobol(d=n, scramble=True, seed=seed).random_base2(m2)
    Q0 = qmc.scale(S0, lo, hi)
    # the scale of σ_min, for the tolerance
    sig_scale = float(np.median(robot.sigma_min(Q0[:64]))) or 1.0
    tol = 1e-10 * max(sig_scale, 1e-6)
    found = []
    chunk = 128
    for k in range(0, len(Q0), chunk):
        Qp, ok = project(robot, Q0[k:k + chunk], tol=tol, deadline=project_deadline)
        found.append(Qp[ok])
        say("projecting samples onto the singular set", min(k + chunk, len(Q0)), len(Q0))
        if time.perf_counter() > project_deadline:
            break
    Q = np.concatenate(found) if found else np.zeros((0, n))
    info = {"starts": int(len(Q0)), "converged": int(len(Q)), "tolerance": tol}
    if len(Q) == 0:
        info["seconds"] = time.perf_counter() - t0
        return [], info
    _, _, G, U, second = residuals(robot, Q)
    codim = G.shape[1]
    supp, normal = support(G)
    clean = second > 1e-4 * sig_scale         # a double zero singular value: where components meet
    keys = [tuple(np.flatnonzero(s)) for s in supp]
    counts: dict[tuple, int] = {}
    for key, c in zip(keys, clean):
        if c:
            counts[key] = counts.get(key, 0) + 1
    total = sum(counts.values())
    major = {k for k, c in counts.items() if c >= max(3, MIN_GROUP_SHARE * total)}
    groups: dict[tuple, list[int]] = {k: [] for k in major}
    for i, key in enumerate(keys):
        if key in major:
            groups[key].append(i)
            continue
        # rare pattern (a partial derivative vanishing by chance, or a meeting point): the
        # smallest major support containing it, if any
        sup = [k for k in major if set(key) <= set(k)]
        if sup and key:           # an empty support (a degenerate normal) says nothing: dropped
            groups[min(sup, key=len)].append(i)
    info["groups_dropped"] = int(len(Q) - sum(len(v) for v in groups.values()))
    wc = wrist_centre(robot)
    generic = robot.random_configurations(1, seed=12345)
    Zg = axis_lines(robot, generic)[0][0]
    rev = [i for i in range(n) if chain.joints[i].is_revolute]
    generic_parallel = {(i, j) for a, i in enumerate(rev) for j in rev[a + 1:] if parallel(Zg[i], Zg[j])}
    rng = np.random.default_rng(seed)
    comps = []
    for gi, (key, idx) in enumerate(sorted(groups.items(), key=lambda kv: -len(kv[1]))):
        share = max(deadline - time.perf_counter(), 0.0) / (len(groups) - gi)
        comp_deadline = time.perf_counter() + share
        idx = np.array(idx)
        own = list(key)
        P = Q[idx]
        Nrm = normal[idx]
        # the set's dimension over its own joints: isolated points need no more samples, curves few
        dim = len(own) - codim
        target = 0 if dim <= 0 else min(points_per_component, 1000) if dim == 1 else points_per_component
        if len(own) > 1 and time.perf_counter() < comp_deadline:
            P, Nrm = _densify(robot, P, Nrm, key, target, tol, comp_deadline, rng)
        use = P[rng.choice(len(P), min(len(P), 40), replace=False)]
        votes: dict[str, int] = {}
        for q in use:
            name = name_point(robot, q, own, generic_parallel, wc)
            votes[name] = votes.get(name, 0) + 1
        kind = max(votes, key=lambda k: (votes[k], k != "other"))
        own = [int(j) for j in own]
        names = ", ".join(f"q{j + 1}" for j in own)
        if len(own) == 1:
            j = own[0]
            values = _sheet_values(P[:, j])
            solutions = {"type": "values", "joint": j + 1, "values": values, "exact": [f"{v:.12g}" for v in values],
                         "numeric": True}
        else:
            ranges = {f"q{j + 1}": [float(P[:, j].min()), float(P[:, j].max())] for j in own}
            solutions = {"type": "manifold", "solve_for": None, "count": int(len(P)), "ranges": ranges,
                         "samples": np.round(P[:5], 9).tolist(), "numeric": True}
        Uc = residuals(robot, use)[3]
        comp = SingularComponent(kind=kind, joints=tuple(j + 1 for j in own),
                                 meaning=f"{names}: {NUMERIC_MEANINGS[kind]}", solutions=solutions, n=n,
                                 points=P, normals=Nrm, codimension=codim, tolerance=tol,
                                 lost_motion=lost_motion(robot, use, Uc),
                                 kind_shares={k: v / len(use) for k, v in votes.items()})
        comp.resolution = _resolution(robot, comp, tol, rng, deadline + 5.0) if len(own) > 1 else 0.0
        comps.append(comp)
        say("describing components", gi + 1, len(groups))
    order = {k: i for i, k in enumerate(KINDS)}
    comps.sort(key=lambda c: (order[c.kind], c.joints))
    info["seconds"] = time.perf_counter() - t0
    return comps, info


def _densify(robot, P: np.ndarray, Nrm: np.ndarray, key: tuple, target: int, tol: float, deadline: float,
             rng) -> tuple[np.ndarray, np.ndarray]:
    """More points on one component: its points moved at random within its own joints and
    projected again; those landing on the same support are kept."""
    lo, hi = robot.chain.lower, robot.chain.upper
    cols = list(key)
    rounds = 0
    while len(P) < target and rounds < 12 and time.perf_counter() < deadline:
        rounds += 1
        k = min(target - len(P), 4 * len(P), 1024)
        base = P[rng.integers(len(P), size=k)].copy()
        # half of the starts anywhere in the component's joints (reaching sheets no point is near
        # yet), half next to the points it has (filling the gaps between them)
        half = k // 2
        base[:half][:, cols] = rng.uniform(lo[cols], hi[cols], size=(half, len(cols)))
        spread = 0.5 * (hi[cols] - lo[cols]) / max(len(P), 2) ** (1.0 / max(len(cols) - 1, 1))
        base[half:, cols] += rng.normal(size=(k - half, len(cols))) * spread
        Qp, ok = project(robot, np.clip(base, lo, hi), tol=tol, deadline=deadline)
        Qp = Qp[ok]
        if len(Qp) == 0:
            continue
        _, _, G, _, _ = residuals(robot, Qp)
        supp, nrm = support(G)
        same = np.all(supp == np.isin(np.arange(robot.n), cols)[None], axis=1)
        P = np.concatenate([P, Qp[same]])
        Nrm = np.concatenate([Nrm, nrm[same]])
    return P, Nrm


def _resolution(robot, comp: SingularComponent, tol: float, rng, deadline: float, count: int = 64) -> float:
    """Largest distance from fresh points of the component to its sampled points (a covering
    radius estimate): points moved off the set at random and projected back (for at most 2 s,
    and not after ``deadline``)."""
    if time.perf_counter() > deadline:
        return math.nan
    lo, hi = robot.chain.lower, robot.chain.upper
    cols = [j - 1 for j in comp.joints]
    base = comp.points[rng.integers(len(comp.points), size=count)].copy()
    base[:, cols] += rng.normal(size=(count, len(cols))) * 0.3
    Qp, ok = project(robot, np.clip(base, lo, hi), tol=tol, deadline=min(deadline, time.perf_counter() + 2.0))
    Qp = Qp[ok]
    if len(Qp) == 0:
        return math.nan
    _, _, G, _, _ = residuals(robot, Qp)
    supp, _ = support(G)
    same = np.all(supp == np.isin(np.arange(robot.n), cols)[None], axis=1)
    return float(comp.distance(Qp[same]).max()) if same.any() else math.nan
