"""Placements evaluated by the reach study, many at a time: quasi-random and grid candidates, and the
global cross-check by differential evolution (scipy.optimize.differential_evolution).

The value of a placement is the reach study's: targets reached plus the mean score (in [0, 1)), so
that coverage decides first and the score breaks ties.  A placement whose base origin stands in a
keep-out rectangle has value −1.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import differential_evolution
from scipy.stats import qmc

from design.place.region import PlacementRegion, placement_transform
from design.reach.study import ReachProblem

__all__ = ["Evaluated", "evaluate_placements", "halton_placements", "grid_placements", "de_search", "SearchResult"]


@dataclass
class Evaluated:
    """Placements U (M, 6) with their value, coverage (0..1), mean score and per-target solutions."""

    U: np.ndarray
    value: np.ndarray
    coverage: np.ndarray
    score: np.ndarray
    q: list
    time_s: float

    def best(self) -> int:
        return int(np.argmax(self.value))


def evaluate_placements(problem: ReachProblem, U: np.ndarray, region: PlacementRegion | None = None,
                        keep_q: bool = False, progress: Callable[[int, int], None] | None = None,
                        deadline: float | None = None) -> Evaluated:
    """The reach value of each placement row of U (M, 6); ``deadline`` (perf_counter s): placements
    not reached by then get value −inf (the caller states the budget ran out)."""
    t0 = time.perf_counter()
    U = np.atleast_2d(np.asarray(U, float))
    M = len(U)
    value, cov, score = np.full(M, -np.inf), np.zeros(M), np.zeros(M)
    qs: list = [None] * M
    ok = np.ones(M, bool) if region is None else region.allowed(U)
    for i in range(M):
        if deadline is not None and time.perf_counter() > deadline:
            break
        if not ok[i]:
            value[i] = -1.0
        else:
            d = problem.run(placement_transform(U[i]))
            cov[i], score[i] = d["reached"].mean(), d["score"].mean()
            value[i] = d["reached"].sum() + score[i]
            if keep_q:
                qs[i] = d["q"]
        if progress is not None:
            progress(i + 1, M)
    return Evaluated(U, value, cov, score, qs, time.perf_counter() - t0)


def halton_placements(region: PlacementRegion, count: int) -> np.ndarray:
    """``count`` placements (count, 6) of an unscrambled Halton sequence over the free coordinates
    (no seed: the same region gives the same candidates), keep-out rectangles skipped."""
    k = int(region.free.sum())
    b = region.bounds[region.free]
    out = np.empty((0, 6))
    m = count
    while len(out) < count and m < 64 * count:
        H = qmc.Halton(d=k, scramble=False).random(m + 1)[1:]
        U = region.full(b[:, 0] + H * (b[:, 1] - b[:, 0]))
        out = U[region.allowed(U)][:count]
        m *= 2
    return out


def grid_placements(region: PlacementRegion, per_axis: int) -> np.ndarray:
    """The full grid of ``per_axis`` values (ends included) on each free coordinate (M, 6), keep-out
    placements dropped; a yaw range of a full turn omits its duplicate end."""
    b = region.bounds[region.free]
    names = region.names()
    axes = []
    for (lo, hi), name in zip(b, names):
        full_turn = name == "yaw" and hi - lo >= 2 * np.pi - 1e-12
        axes.append(np.linspace(lo, hi, per_axis, endpoint=not full_turn))
    G = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(axes))
    U = region.full(G)
    return U[region.allowed(U)]


@dataclass
class SearchResult:
    """The best placement of a global search, its value, evaluations, generations and time (s)."""

    u: np.ndarray
    value: float
    evaluations: int
    generations: int
    time_s: float
    message: str


def de_search(problem: ReachProblem, region: PlacementRegion, seed: int = 0, maxiter: int = 30, popsize: int = 10,
              progress: Callable[[str], None] | None = None, max_time: float = 600.0,
              x0: np.ndarray | None = None) -> SearchResult:
    """Differential evolution over the free coordinates, maximising the reach value (scipy's
    ``differential_evolution``: seeded, deferred updating, no gradient polish).  ``x0``: a full
    placement (6,) inside the region made a member of the first population (the current one)."""
    t0 = time.perf_counter()
    b = region.bounds[region.free]
    evals = [0]
    best = [-np.inf, None]
    deadline = t0 + max_time

    def f(X):
        X = np.atleast_2d(X.T) if X.ndim == 2 else X[None]
        ev = evaluate_placements(problem, region.full(X), region, deadline=deadline)
        evals[0] += len(X)
        i = ev.best()
        if ev.value[i] > best[0]:
            best[0], best[1] = float(ev.value[i]), ev.U[i]
        return -ev.value

    def cb(intermediate_result=None):
        if progress:
            progress(f"differential evolution: {evals[0]} placements, best value {best[0]:.4f}")
        return time.perf_counter() > deadline

    start = None if x0 is None else np.clip(np.asarray(x0, float)[region.free], b[:, 0], b[:, 1])
    res = differential_evolution(f, b, seed=seed, maxiter=maxiter, popsize=popsize, vectorized=True,
                                 updating="deferred", polish=False, tol=0, atol=0, callback=cb, init="sobol",
                                 x0=start)
    u = best[1] if best[1] is not None else region.full(res.x)
    return SearchResult(np.asarray(u, float), float(best[0]), evals[0], int(res.nit), time.perf_counter() - t0,
                        str(res.message))
