"""Certified distances between convex solids given by their support points (GJK).

A solid here is the convex hull of finitely many points dilated by a radius — a convex polytope (a
link's hull, a box by its 8 corners), a capsule (the two ends of its segment, radius r), a sphere (one
point, radius r) — or a cylinder (its support function in closed form).  :func:`convex_distance`
runs Gilbert–Johnson–Keerthi's algorithm on the Minkowski difference A − B to find its point v
nearest the origin, and returns a *lower bound* of the distance, certified whatever the accuracy of
that search: for any unit vector u, every a ∈ A and b ∈ B satisfy u·(a − b) ≥ min_A u·x − max_B u·x,
so that support gap along u = v/|v| (computed exactly from the two support points) bounds the distance
from below.  GJK makes it tight: at its optimum the gap equals the distance.  Overlapping solids give
a value ≤ 0 — minus the radii — that is not a depth: penetration is not measured, only "not clear".

The search is plain numpy over at most four simplex points (every face of the simplex tried for the
point nearest the origin: at most 15 small least-squares systems), meant for the few pairs that a
cheaper, coarser check could not clear (:mod:`planning.collision` uses it for a body's hull where its
capsules come too close).
"""
from __future__ import annotations

import itertools
import math

import numpy as np

__all__ = ["Solid", "points_solid", "box_solid", "cylinder_solid", "convex_distance"]

#: relative gap at which GJK stops (the bound is certified whatever it is; this only sets tightness)
REL_TOL = 1e-9
ABS_TOL = 1e-12
MAX_ITER = 64


class Solid:
    """A convex solid: ``support(u)`` is a point of it farthest along unit ``u``, before the dilation by
    ``radius`` (m)."""

    def __init__(self, support, radius: float = 0.0):
        self.support = support
        self.radius = float(radius)


def points_solid(P, radius: float = 0.0) -> Solid:
    """The hull of points ``P`` (k, 3), dilated by ``radius``."""
    P = np.asarray(P, dtype=float).reshape(-1, 3)
    if not len(P):
        raise ValueError("a convex solid needs at least one point")
    return Solid(lambda u: P[int(np.argmax(P @ u))], radius)


def box_solid(half, pose) -> Solid:
    """A box of half sizes ``half`` (3,) at ``pose`` (4×4)."""
    h = np.asarray(half, dtype=float)
    R, t = np.asarray(pose, dtype=float)[:3, :3], np.asarray(pose, dtype=float)[:3, 3]
    return Solid(lambda u: t + R @ (np.where(R.T @ u >= 0, h, -h)))


def cylinder_solid(radius: float, half_length: float, pose) -> Solid:
    """A solid cylinder (axis the pose's z, centred at its origin)."""
    R, t = np.asarray(pose, dtype=float)[:3, :3], np.asarray(pose, dtype=float)[:3, 3]

    def support(u):
        w = R.T @ u
        rad = math.hypot(w[0], w[1])
        x = np.array([radius * w[0] / rad, radius * w[1] / rad, 0.0]) if rad > 1e-15 else np.zeros(3)
        x[2] = half_length if w[2] >= 0 else -half_length
        return t + R @ x
    return Solid(support)


def _nearest_on_simplex(W: list[np.ndarray]) -> tuple[np.ndarray, list[np.ndarray]]:
    """The point of conv(W) nearest the origin and the vertices of the face it lies in (1 to 4)."""
    best = None
    n = len(W)
    for k in range(1, n + 1):
        for idx in itertools.combinations(range(n), k):
            S = np.array([W[i] for i in idx])
            if k == 1:
                lam = np.ones(1)
            else:
                # min |Σ λ_i s_i| with Σ λ_i = 1: λ = (1 − Σ μ) e_0 + μ, the normal equations in μ
                E = S[1:] - S[0]
                G = E @ E.T
                try:
                    mu = np.linalg.solve(G, -E @ S[0])
                except np.linalg.LinAlgError:
                    continue
                lam = np.concatenate([[1 - mu.sum()], mu])
                if (lam <= 0).any():
                    continue
            p = lam @ S
            d = float(p @ p)
            if best is None or d < best[0] - 1e-30:
                best = (d, p, [W[i] for i in idx])
    if best is None:                   # degenerate: the nearest vertex
        i = int(np.argmin([w @ w for w in W]))
        return W[i], [W[i]]
    return best[1], best[2]


def convex_distance(A: Solid, B: Solid) -> float:
    """A certified lower bound of the distance between solids ``A`` and ``B`` (m; ≤ 0 when they may
    touch), tight to about :data:`REL_TOL` of it where they are apart."""
    def sup(u):                         # support of A − B along u
        return A.support(u) - B.support(-u)

    v = sup(np.array([1.0, 0.0, 0.0]))
    W: list[np.ndarray] = []
    lower = -math.inf
    for _ in range(MAX_ITER):
        nv = float(np.linalg.norm(v))
        if nv <= ABS_TOL:
            break
        u = v / nv
        w = sup(-u)
        lower = max(lower, float(u @ w))         # the support gap along u: certified
        if nv - u @ w <= REL_TOL * nv + ABS_TOL:
            break
        if any(np.allclose(w, x, rtol=0, atol=1e-15) for x in W):
            break
        W.append(w)
        v, W = _nearest_on_simplex(W)
        if len(W) == 4:                  # the origin inside the tetrahedron: they overlap
            break
    lower = max(lower, 0.0) if lower > -math.inf else 0.0
    return lower - A.radius - B.radius
