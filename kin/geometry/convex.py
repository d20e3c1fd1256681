"""Certified distances between convex solids given by points (GJK).

A solid here is the convex hull of finitely many points (in its own frame, placed by a 4×4 transform)
dilated by a radius — a convex polytope (a link's hull, a box by its 8 corners), a capsule (the two
ends of its segment, radius r), a sphere (one point, radius r); a cylinder is taken as the prism of
:data:`CYLINDER_SIDES` sides around it (which holds it: its distances are never larger).
:func:`convex_distance` runs Gilbert–Johnson–Keerthi's algorithm on the Minkowski difference A − B to
find its point v nearest the origin, and returns a *lower bound* of the distance, certified whatever
the accuracy of that search: for any unit vector u, every a ∈ A and b ∈ B satisfy
u·(a − b) ≥ min_A u·x − max_B u·x, so that support gap along u = v/|v| (computed exactly from the two
support points) bounds the distance from below.  GJK makes it tight: at its optimum the gap equals the
distance.  Overlapping solids give a value ≤ 0 — minus the radii — that is not a depth: penetration
is not measured, only "not clear".

The search runs in C (``convex.c``, built on first use like the clearance kernel; about a microsecond
a pair), else in numpy (the same algorithm: every face of the simplex tried for the point nearest
the origin).  It is meant for the few pairs that a cheaper, coarser check could not clear
(:mod:`kin.geometry.hulls`: a body's hull where its capsules come too close).
"""
from __future__ import annotations

import ctypes
import itertools
import math
import threading
from pathlib import Path

import numpy as np

__all__ = ["Solid", "points_solid", "box_solid", "cylinder_solid", "convex_distance", "convex_distance_numpy",
           "c_distance", "CYLINDER_SIDES"]

#: relative gap at which GJK stops (the bound is certified whatever it is; this only sets tightness)
REL_TOL = 1e-9
ABS_TOL = 1e-12
MAX_ITER = 64
#: a cylinder is taken as the prism of this many sides around it (its distances then at most
#: radius·(1/cos(π/sides) − 1) smaller: 0.5 % of the radius)
CYLINDER_SIDES = 32
SOURCE = Path(__file__).resolve().with_name("convex.c")
_lock = threading.Lock()
_loaded: dict = {}


class Solid:
    """A convex solid: the hull of ``points`` (k, 3, its own frame) placed by ``pose`` (4×4; None:
    identity), dilated by ``radius`` (m)."""

    __slots__ = ("points", "pose", "radius", "ptr", "pose_ptr", "centre", "placed_centre", "reach")

    def __init__(self, points, pose=None, radius: float = 0.0):
        P = np.ascontiguousarray(points, dtype=float).reshape(-1, 3)
        if not len(P):
            raise ValueError("a convex solid needs at least one point")
        self.points = P
        self.pose = None if pose is None else np.ascontiguousarray(pose, dtype=float).reshape(4, 4)
        self.radius = float(radius)
        #: the addresses the C search reads (the arrays are kept alive by this object)
        self.ptr = P.ctypes.data
        self.pose_ptr = None if self.pose is None else self.pose.ctypes.data
        #: a ball that holds the solid: its centre in the points' frame and placed by the pose, its radius (m)
        self.centre = P.mean(axis=0)
        self.placed_centre = self.centre if self.pose is None else self.pose[:3, :3] @ self.centre + self.pose[:3, 3]
        self.reach = float(np.sqrt(((P - self.centre) ** 2).sum(axis=1)).max()) + self.radius

    def support(self, u: np.ndarray) -> np.ndarray:
        """A point of the (undilated) solid farthest along ``u``."""
        if self.pose is None:
            return self.points[int(np.argmax(self.points @ u))]
        R, t = self.pose[:3, :3], self.pose[:3, 3]
        return R @ self.points[int(np.argmax(self.points @ (R.T @ u)))] + t


def points_solid(P, radius: float = 0.0, pose=None) -> Solid:
    """The hull of points ``P`` (k, 3), dilated by ``radius``, placed by ``pose``."""
    return Solid(P, pose, radius)


_CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)


def box_solid(half, pose) -> Solid:
    """A box of half sizes ``half`` (3,) at ``pose`` (4×4)."""
    return Solid(_CORNERS * np.asarray(half, dtype=float), pose)


def cylinder_solid(radius: float, half_length: float, pose) -> Solid:
    """A solid cylinder (axis the pose's z, centred at its origin) — as the prism of
    :data:`CYLINDER_SIDES` sides that holds it."""
    a = 2 * math.pi * np.arange(CYLINDER_SIDES) / CYLINDER_SIDES
    R = radius / math.cos(math.pi / CYLINDER_SIDES)
    ring = np.c_[R * np.cos(a), R * np.sin(a)]
    P = np.vstack([np.c_[ring, np.full(len(a), -half_length)], np.c_[ring, np.full(len(a), half_length)]])
    return Solid(P, pose)


def c_distance():
    """The C search as a ctypes function (points pointer, count, pose pointer or None, radius — for A,
    then for B) → the bound; None without a compiler, or when it fails to build (numpy then).  Built once
    per compiler (``RMTKIT_CC``); callers in a loop keep the function (:class:`kin.geometry.hulls.HullRefiner`)."""
    from kin.native import build, find_compiler
    compiler = find_compiler()
    with _lock:
        if compiler in _loaded:
            return _loaded[compiler]
        fn = None
        if compiler is not None:
            try:
                lib = build("geometry_convex", SOURCE, compiler=compiler, what="the convex distance kernel")
                fn = ctypes.PyDLL(str(lib.path)).rmt_convex_distance
                p, ll, dbl = ctypes.c_void_p, ctypes.c_long, ctypes.c_double
                fn.argtypes = [p, ll, p, dbl, p, ll, p, dbl]
                fn.restype = dbl
            except Exception:           # noqa: BLE001 — any failure to build or load: numpy
                fn = None
        _loaded[compiler] = fn
        return fn


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
    fn = c_distance()
    if fn is not None:
        return fn(A.ptr, len(A.points), A.pose_ptr, A.radius, B.ptr, len(B.points), B.pose_ptr, B.radius)
    return convex_distance_numpy(A, B)


def convex_distance_numpy(A: Solid, B: Solid) -> float:
    """:func:`convex_distance` in numpy (what runs without a C compiler)."""
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
        if any(np.array_equal(w, x) for x in W):
            break
        W.append(w)
        v, W = _nearest_on_simplex(W)
        if len(W) == 4:                  # the origin inside the tetrahedron: they overlap
            break
    lower = max(lower, 0.0) if lower > -math.inf else 0.0
    return lower - A.radius - B.radius
