"""Proofs that no joint path exists under a σ_min floor: a singular factor changes sign.

The exact singular analysis writes det J as a product of factors f(q) (:mod:`kin.singular`); where a
factor is zero, σ_min is zero.  A joint path is continuous, so along any path from a configuration
with f > 0 to one with f < 0 some state has f = 0, hence σ_min = 0 — below every positive floor.
With a floor, the sign of every exact factor is therefore the same all along any valid path, and a
start and a goal with opposite signs of one factor are proven apart, whatever the windows (none may
be given at all: the floor alone splits the joint space this way).

Only factors of an exact analysis are used, and each only after σ_min is checked to vanish at the
points the analysis found on its zero set (a numeric analysis, or a factor that does not pass,
proves nothing here and is left out; leaving one out only weakens the verdicts, never falsifies them).

:class:`Separator` joins this with :class:`planning.certify.cells.FreeCells` (the windows' slabs and
cells): the one question the planner asks, "is there a reason no path joins these two?".
"""
from __future__ import annotations

import weakref

import numpy as np

from planning.certify.cells import FreeCells, Separation

__all__ = ["Separator", "floor_factors", "sign_changes", "sign_separation"]

#: points sampled on each factor's zero set to confirm σ_min vanishes there
_SAMPLES = 20
#: σ_min below this (SI) counts as zero at a factor's zero-set points
_ZERO = 1e-9

_CACHE: dict[int, tuple[weakref.ref, tuple]] = {}


def floor_factors(robot) -> tuple:
    """The exact singular factors of ``robot`` whose zero sets are singular (σ_min = 0 at the points
    the analysis samples on them); () when the Jacobian is not square (no det J) or the analysis is not
    exact.  Computed once per robot object."""
    hit = _CACHE.get(id(robot))
    if hit is not None and hit[0]() is robot:
        return hit[1]
    factors = ()
    # det J exists only for a square Jacobian (a redundant arm's exact analysis would run into its budget);
    # the numeric fallback proves nothing here, so it gets no time
    analysis = None
    if robot.chain.n == len(robot.task_rows):
        from kin.singular import analyse_singularities
        analysis = analyse_singularities(robot, samples=_SAMPLES, numeric_time=0.1)
    if getattr(analysis, "method", None) == "exact":
        keep = []
        for f in analysis.factors:
            S = np.asarray(f.samples, dtype=float)
            if S.ndim == 2 and len(S) and float(np.max(robot.sigma_min(S))) < _ZERO:
                keep.append(f)
        factors = tuple(keep)
    for k in [k for k, (ref, _) in _CACHE.items() if ref() is None]:
        del _CACHE[k]
    try:
        _CACHE[id(robot)] = (weakref.ref(robot), factors)
    except TypeError:                   # an object without weak references: not cached
        pass
    return factors


def sign_changes(factors, Q):
    """Each (factor, i, values) where a factor has opposite signs at consecutive configurations
    ``Q[i]`` and ``Q[i + 1]`` (SI, (M, n)); ``values`` are the factor's values at every row.  In the
    order of ``factors``, then of ``i``."""
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    for f in factors:
        g = np.asarray(f(Q), dtype=float).ravel()
        for i in np.flatnonzero(g[:-1] * g[1:] < 0):
            yield f, int(i), g


def sign_separation(factors, start, goal) -> Separation | None:
    """The first factor with opposite signs at ``start`` and ``goal`` (SI), as a :class:`Separation`
    of kind ``"sign"``; None when every factor keeps its sign (or is zero at one end)."""
    for f, _, (fa, fb) in sign_changes(factors, np.stack([np.asarray(start, float), np.asarray(goal, float)])):
        joints = ", ".join(f"q{j}" for j in f.joints)
        return Separation(tuple(f.joints), (), "sign",
                          f"the {f.kind} factor {f.expr} ({joints}) is {fa:+.3g} at the start and {fb:+.3g} at the "
                          f"goal: every joint path between them passes through its zero set, where σ_min = 0, below "
                          f"the σ_min floor")
    return None


class Separator:
    """Why no joint path joins two configurations: the windows' free cells (``cells``) and, under a
    positive σ_min floor, the signs of the exact singular factors of ``robot`` (looked up only when a
    question needs them)."""

    def __init__(self, cells: FreeCells, robot=None, floor: float | None = None):
        self.cells = cells
        self._robot = robot if floor is not None and floor > 0 else None
        self._factors = None

    @property
    def factors(self) -> tuple:
        if self._factors is None:
            self._factors = () if self._robot is None else floor_factors(self._robot)
        return self._factors

    @property
    def factors_ready(self) -> bool:
        """True when :attr:`factors` needs no analysis (already looked up, or no floor)."""
        return self._factors is not None or self._robot is None

    def separation(self, start, goal, chain=None) -> Separation | None:
        """The windows' verdict (:meth:`FreeCells.separation`) first, then the factors' signs."""
        sep = self.cells.separation(start, goal, chain=chain)
        if sep is None and self._robot is not None:
            sep = sign_separation(self.factors, start, goal)
        return sep

    def same_cell(self, start, goal) -> bool:
        """False when a path between them is proven impossible."""
        return self.separation(start, goal) is None
