"""Spheres that provably enclose a triangle mesh's surface or a point cloud's balls.

**Triangles.**  Every point of a triangle is a convex combination of its three corners, and a ball
is convex: a ball that holds the corners of a set of triangles holds the triangles.  The cover is
built in three steps:

1. triangles whose smallest enclosing ball is wider than half the ``tolerance`` are cut in two at
   the midpoint of their longest edge (the two pieces are the triangle exactly), largest first,
   within a budget of :data:`PIECES_PER_SPHERE` pieces per sphere;
2. the pieces are split into clusters, top down: the cluster that stands out most is cut in two at
   the middle of its pieces' centroids along x, y or z (whichever leaves halves that stand out
   less), until every cluster's sphere stands out at most ``tolerance`` or there are
   ``max_spheres`` clusters;
3. each cluster gets the sphere centred on its corners' bounding box that reaches its farthest
   corner (a lone triangle gets its smallest enclosing ball: the circumcircle of an acute triangle,
   the longest edge's midpoint otherwise), its radius rounded up by :data:`PAD`.

How far a sphere of centre c and radius r stands out of the surface S it encloses: a point p of the
sphere is at most |p − c| + dist(c, S) ≤ r + dist(c, S) away from S, and dist(c, S) is computed
exactly, point to triangle, for every sphere's own triangles.  The largest of these bounds is the
cover's :attr:`SphereCover.over_estimate` (m).

The spheres cover the *surface*.  A closed mesh's inside is not filled: a robot moving continuously
from outside cannot reach the inside without crossing the surface, which the collision proofs check
along the whole motion, but a configuration that *starts* inside is not seen.

**Points.**  A point cloud declares the union of balls of ``point_radius`` about its points.  With
``merge``, the points are gathered in cubes of edge ``point_radius`` and each cube's points become one
sphere centred on their bounding box, radius ρ + ``point_radius`` (ρ: the farthest point from the
centre), which holds each of their balls; it stands out of those balls by at most ρ + the distance
from its centre to the nearest of its points.  Without ``merge`` every point is a sphere (standing out
by the rounding :data:`PAD` only).

Everything here is numpy on SI arrays; the readers of :mod:`planning.cell.mesh` and
:mod:`planning.cell.points` bound the sizes before this module sees them.
"""
from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np

__all__ = ["PAD", "SphereCover", "enclose_triangles", "enclose_points", "triangle_balls", "subdivide"]

#: every radius is rounded up by this much (m) plus a relative 1e-12, far above float64 rounding of
#: the distances for coordinates below 10 km: containment holds in floating point, not just on paper
PAD = 1e-9
#: the most pieces subdivision may make, whatever the budget, and how many per sphere it aims at
MAX_PIECES = 400_000
PIECES_PER_SPHERE = 8
#: clusters of at most this many triangles have their bound computed exactly while splitting
EXACT = 64


@dataclass(frozen=True)
class SphereCover:
    """Spheres (K, 4: x, y, z, radius; m) and the largest distance (m) a sphere stands out of what
    it encloses; ``pieces``: the triangles (after subdivision) or points enclosed."""

    spheres: np.ndarray
    over_estimate: float
    pieces: int


def _pad(r: np.ndarray) -> np.ndarray:
    return r * (1.0 + 1e-12) + PAD


def _distance(T: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Distances (m,) from point(s) p ((3,) or (m, 3)) to the triangles T (m, 3, 3)."""
    # the package's vectorised point-triangle distance (imported here: importing planning stays light)
    import trimesh.triangles
    p = np.broadcast_to(p, (len(T), 3))
    near = trimesh.triangles.closest_point(T, p)
    return np.sqrt(np.einsum("ij,ij->i", near - p, near - p))


def triangle_balls(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The smallest enclosing ball of each triangle of T (m, 3, 3): centres (m, 3), radii (m,).

    An acute triangle's is its circumcircle; a right, obtuse or degenerate one's is centred on its
    longest edge's midpoint.  The radius is measured from the centre found to the corners (so it holds
    them whatever the rounding of the centre), not rounded up.
    """
    A, B, C = T[:, 0], T[:, 1], T[:, 2]
    # the longest edge and the corner opposite it
    e = np.stack([np.einsum("ij,ij->i", B - C, B - C), np.einsum("ij,ij->i", C - A, C - A),
                  np.einsum("ij,ij->i", A - B, A - B)], axis=1)             # opposite A, B, C
    k = np.argmax(e, axis=1)
    idx = np.arange(len(T))
    P0 = T[idx, (k + 1) % 3]
    P1 = T[idx, (k + 2) % 3]
    Q = T[idx, k]
    mid = 0.5 * (P0 + P1)
    # the angle at Q is ≥ 90° exactly when Q lies in the ball on the longest edge
    obtuse = np.einsum("ij,ij->i", P0 - Q, P1 - Q) <= 0.0
    centres = mid.copy()
    acute = ~obtuse
    if acute.any():
        a = A[acute] - C[acute]
        b = B[acute] - C[acute]
        axb = np.cross(a, b)
        den = 2.0 * np.einsum("ij,ij->i", axb, axb)
        num = np.cross(np.einsum("ij,ij->i", a, a)[:, None] * b - np.einsum("ij,ij->i", b, b)[:, None] * a, axb)
        ok = den > 0
        cc = mid[acute].copy()
        cc[ok] = C[acute][ok] + num[ok] / den[ok, None]
        centres[acute] = cc
    r = np.sqrt(np.max(np.einsum("ijk,ijk->ij", T - centres[:, None], T - centres[:, None]), axis=1))
    return centres, r


def subdivide(T: np.ndarray, size: float, budget: int) -> np.ndarray:
    """Cut the triangles of T (m, 3, 3) at the midpoint of their longest edge, largest first, until
    every piece's smallest enclosing ball has a radius ≤ ``size`` or there are ``budget`` pieces.

    The two halves of a triangle tile it exactly, so the pieces tile the surface of T.
    """
    while len(T) < budget:
        _, r = triangle_balls(T)
        top = float(r.max())
        if top <= size:
            break
        big = np.flatnonzero(r > max(size, 0.7 * top))       # the largest first: sizes even out
        room = budget - len(T)
        if len(big) > room:                     # the budget runs out: cut the largest only
            big = big[np.argsort(r[big])[::-1][:room]]
        S = T[big]
        e = np.stack([np.einsum("ij,ij->i", S[:, 1] - S[:, 2], S[:, 1] - S[:, 2]),
                      np.einsum("ij,ij->i", S[:, 2] - S[:, 0], S[:, 2] - S[:, 0]),
                      np.einsum("ij,ij->i", S[:, 0] - S[:, 1], S[:, 0] - S[:, 1])], axis=1)
        k = np.argmax(e, axis=1)                 # the corner opposite the longest edge
        idx = np.arange(len(S))
        Q, P0, P1 = S[idx, k], S[idx, (k + 1) % 3], S[idx, (k + 2) % 3]
        M = 0.5 * (P0 + P1)
        keep = np.ones(len(T), bool)
        keep[big] = False
        T = np.concatenate([T[keep], np.stack([Q, P0, M], axis=1), np.stack([Q, M, P1], axis=1)])
    return T


class _Cluster:
    __slots__ = ("idx", "centre", "radius", "bound")

    def __init__(self, idx: np.ndarray, T: np.ndarray, balls):
        self.idx = idx
        if len(idx) == 1:
            c, r = balls[0][idx[0]], balls[1][idx[0]]
            self.centre, self.radius, self.bound = c, r, r          # the centre lies on the triangle
            return
        V = T[idx].reshape(-1, 3)
        c = 0.5 * (V.min(axis=0) + V.max(axis=0))
        d = np.sqrt(np.einsum("ij,ij->i", V - c, V - c))
        self.centre, self.radius = c, float(d.max())
        if len(idx) <= EXACT:
            self.bound = self.radius + float(_distance(T[idx], c).min())
        else:       # r + the distance to the nearest corner ≥ r + dist(c, S)
            self.bound = self.radius + float(d.min())


def _rough_bound(V: np.ndarray) -> float:
    """r + the distance to the nearest corner, for the sphere of the corners V (k, 3) centred on
    their bounding box: an upper bound of how far it stands out of their triangles."""
    c = 0.5 * (V.min(axis=0) + V.max(axis=0))
    d = np.sqrt(np.einsum("ij,ij->i", V - c, V - c))
    return float(d.max() + d.min())


def _split(idx: np.ndarray, T: np.ndarray, centroids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cut a cluster in two halves at the median of its centroids along x, y or z: the axis whose
    halves stand out less (by :func:`_rough_bound`: the worse half, then the sum)."""
    X = centroids[idx]
    half = len(idx) // 2
    best = None
    lo, hi = X.min(axis=0), X.max(axis=0)
    for axis in range(3):
        left = X[:, axis] <= 0.5 * (lo[axis] + hi[axis])
        if left.all() or not left.any():
            order = np.argpartition(X[:, axis], half)
            parts = (idx[order[:half]], idx[order[half:]])
        else:
            parts = (idx[left], idx[~left])
        b = [_rough_bound(T[part].reshape(-1, 3)) for part in parts]
        key = (max(b), sum(b))
        if best is None or key < best[0]:
            best = (key, parts)
    return best[1]


def enclose_triangles(T: np.ndarray, tolerance: float, max_spheres: int) -> SphereCover:
    """Spheres enclosing every triangle of T (m, 3, 3; m) — see the module docstring.

    ``tolerance``: the over-estimate wanted (m); ``max_spheres``: at most this many spheres.  When the
    budget stops the splitting first, the cover stands out by more than ``tolerance``, and says by how
    much in :attr:`SphereCover.over_estimate`.
    """
    T = np.asarray(T, dtype=float).reshape(-1, 3, 3)
    if not len(T):
        raise ValueError("no triangles to enclose")
    if not (tolerance > 0 and max_spheres >= 1):
        raise ValueError("tolerance must be > 0 and max_spheres ≥ 1")
    # 1. cut large triangles, within a budget of pieces a few times the spheres'
    T = subdivide(T, 0.5 * tolerance, min(MAX_PIECES, max(len(T), PIECES_PER_SPHERE * max_spheres)))
    balls = triangle_balls(T)
    # 2. split the worst cluster until all are within tolerance or the budget is spent
    centroids = T.mean(axis=1)
    heap: list = []
    tick = 0

    def push(c: _Cluster):
        nonlocal tick
        heapq.heappush(heap, (-c.bound, tick, c))
        tick += 1

    push(_Cluster(np.arange(len(T)), T, balls))
    while len(heap) < max_spheres:
        neg, _, worst = heap[0]
        if -neg <= tolerance or len(worst.idx) == 1:
            break
        heapq.heappop(heap)
        a, b = _split(worst.idx, T, centroids)
        push(_Cluster(a, T, balls))
        push(_Cluster(b, T, balls))
    clusters = [c for _, _, c in heap]
    # 3. spheres, and the exact bound r + dist(centre, own triangles)
    centres = np.array([c.centre for c in clusters], dtype=float)
    radii = _pad(np.array([c.radius for c in clusters], dtype=float))
    owner = np.empty(len(T), dtype=int)
    for k, c in enumerate(clusters):
        owner[c.idx] = k
    dist = _distance(T, centres[owner])
    corner = np.sqrt(np.min(np.einsum("ijk,ijk->ij", T - centres[owner][:, None], T - centres[owner][:, None]), axis=1))
    dist = np.where(np.isfinite(dist), np.minimum(dist, corner), corner)    # never above a corner's distance
    dmin = np.full(len(clusters), np.inf)
    np.minimum.at(dmin, owner, dist)
    over = float(np.max(radii + dmin))
    return SphereCover(np.column_stack([centres, radii]), over, len(T))


def enclose_points(P: np.ndarray, point_radius: float, merge: bool = True) -> SphereCover:
    """Spheres enclosing the balls of ``point_radius`` (m) about the points P (N, 3; m)."""
    P = np.asarray(P, dtype=float).reshape(-1, 3)
    if not len(P):
        raise ValueError("no points to enclose")
    if not point_radius > 0:
        raise ValueError("point_radius must be > 0")
    if not merge:
        U = np.unique(P, axis=0)
        r = float(_pad(np.float64(point_radius)))
        return SphereCover(np.column_stack([U, np.full(len(U), r)]), r - point_radius, len(P))
    keys = np.floor(P / point_radius).astype(np.int64)
    _, inv = np.unique(keys, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    K = int(inv.max()) + 1
    lo = np.full((K, 3), np.inf)
    hi = np.full((K, 3), -np.inf)
    np.minimum.at(lo, inv, P)
    np.maximum.at(hi, inv, P)
    c = 0.5 * (lo + hi)
    d = np.sqrt(np.einsum("ij,ij->i", P - c[inv], P - c[inv]))
    rho = np.zeros(K)
    near = np.full(K, np.inf)
    np.maximum.at(rho, inv, d)
    np.minimum.at(near, inv, d)
    radii = _pad(rho + point_radius)
    over = float(np.max(radii - point_radius + near))
    return SphereCover(np.column_stack([c, radii]), over, len(P))
