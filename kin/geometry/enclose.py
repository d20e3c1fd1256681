"""Capsules that enclose other solids — spheres, boxes, cylinders, point sets and meshes — and how far
they stand out of them.

A robot's links are capsules (:mod:`kin.geometry.shapes`); robot files and URDFs describe links as
boxes, cylinders and meshes.  Each is replaced by capsules that hold it entirely, and the
*over-estimate* — the largest distance from a point of the capsules' surface to the solid they
enclose — says how much room the replacement costs.

* **Along a fixed axis** (:func:`capsule_along`): the points' projections on the plane across the
  axis give the axis line (the centre of their smallest enclosing circle); of the capsules about that
  line holding every point, the one of least volume is taken (a radius R fixes the shortest segment
  that works: a point at axial position t and distance ρ from the line needs a segment end within
  √(R² − ρ²) of t; the volume πR²·length + 4/3·πR³ is minimised over R, a one-dimensional search).
  The radius is then the largest distance of the points from the segment.
* **Box**: its corners, along its longest edge.  **Cylinder**: its two rim circles, along its axis;
  a long cylinder keeps (nearly) its own radius, a flat one becomes nearly a ball.  **Sphere**:
  itself, exactly.
* **Point set** (:func:`enclose_points`): the vertices of its convex hull; the axis is the principal
  axis (PCA) or frame axis that gives the least volume, refined by a local search over directions.
* **Mesh** (:func:`kin.geometry.meshfit.enclose_mesh`): one capsule as for a point set, or
  the mesh cut into two or three slabs by parallel planes, each slab enclosed alone.

The over-estimate is computed, not assumed.  For a box or a cylinder it is the largest distance
from the capsule's end to the solid (the side's is the rim's), a smooth function of two angles
maximised on a dense grid and refined.  For meshes, the capsules' surface (the parts outside the other
capsules) is cut into cells, the distance to the solid is evaluated at each cell's centre, and cells
that could still hold a larger distance (centre value + the cell's half-size: distances are
1-Lipschitz) are subdivided until the cell size is within the tolerance; the stated value is that
upper bound.  Cells that cannot exceed a given ``floor`` are not refined (several meshes of one
robot: only the largest value is stated).  Distances to a mesh are to its triangles (a point of the
capsules' surface lies outside the solid); each point is measured against the triangle that holds
its nearest surface sample, which can only overstate the distance.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

__all__ = ["Capsule", "Enclosure", "capsule_along", "enclose_box", "enclose_cylinder", "enclose_sphere",
           "enclose_points", "over_estimate", "over_bounds", "segment_distance", "surface_samples",
           "thinned", "union_volume"]

#: the over-estimate of a mesh is an upper bound within this fraction of its size (and 1 µm)
OVER_TOL = 1e-4


@dataclass(frozen=True)
class Capsule:
    """Segment ``a``–``b`` and ``radius`` (m), in the frame of the solid it encloses."""

    a: tuple[float, float, float]
    b: tuple[float, float, float]
    radius: float

    @property
    def length(self) -> float:
        return math.dist(self.a, self.b)

    @property
    def volume(self) -> float:
        r = self.radius
        return math.pi * r * r * self.length + 4.0 / 3.0 * math.pi * r ** 3

    def moved(self, T: np.ndarray) -> "Capsule":
        """The same capsule expressed through the rigid transform ``T`` (4×4): points p → T·p."""
        R, p = T[:3, :3], T[:3, 3]
        return Capsule(_tup(R @ self.a + p), _tup(R @ self.b + p), self.radius)


@dataclass(frozen=True)
class Enclosure:
    """Capsules that together hold a solid, and ``over_estimate``: the largest distance (m) from their
    surface to the solid (an upper bound, see the module docstring)."""

    capsules: tuple[Capsule, ...]
    over_estimate: float

    def moved(self, T: np.ndarray) -> "Enclosure":
        return Enclosure(tuple(c.moved(np.asarray(T, dtype=float)) for c in self.capsules), self.over_estimate)


def _tup(v) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


# ---- distances -----------------------------------------------------------------------------------
def segment_distance(P: np.ndarray, a, b) -> np.ndarray:
    """Distance of each point of P (N, 3) from the segment a–b."""
    P = np.asarray(P, dtype=float)
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    d = b - a
    dd = float(d @ d)
    t = np.zeros(len(P)) if dd == 0.0 else np.clip((P - a) @ d / dd, 0.0, 1.0)
    return np.linalg.norm(P - a - t[:, None] * d, axis=1)


# ---- the over-estimate ---------------------------------------------------------------------------
def _axes(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors making a right-handed frame with unit ``u`` (e1 = u × x̂ normalised, or u × ŷ
    when u is near x̂; e2 = u × e1) — in plain floats: numpy's cross costs more than the sums."""
    x, y, z = float(u[0]), float(u[1]), float(u[2])
    a, b, c = (0.0, z, -y) if abs(x) < 0.9 else (-z, 0.0, x)
    n = math.sqrt(a * a + b * b + c * c)
    a, b, c = a / n, b / n, c / n
    return np.array([a, b, c]), np.array([y * c - z * b, z * a - x * c, x * b - y * a])


def _surface_points(c: Capsule, s: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Points of the capsule's surface at meridian arc length ``s`` (from −(L + πR/2) to L + πR/2,
    L the half-length) and azimuth ``psi``."""
    a, b, R = np.asarray(c.a), np.asarray(c.b), c.radius
    d = b - a
    L2 = float(np.linalg.norm(d))
    u = d / L2 if L2 > 0 else np.array([0.0, 0.0, 1.0])
    e1, e2 = _axes(u)
    mid, L = (a + b) / 2, L2 / 2
    over = np.maximum(np.abs(s) - L, 0.0)
    phi = over / R if R > 0 else np.zeros_like(s)
    axial = np.sign(s) * (np.minimum(np.abs(s), L) + R * np.sin(phi))
    radial = R * np.cos(phi)
    return (mid + axial[:, None] * u + (radial * np.cos(psi))[:, None] * e1
            + (radial * np.sin(psi))[:, None] * e2)


def over_estimate(capsules, distance, size: float, tol: float | None = None, floor: float = 0.0) -> float:
    """An upper bound (within ``tol``, default :data:`OVER_TOL`·``size`` and at least 1 µm) of the
    largest distance from the surface of the union of ``capsules`` to a solid; ``distance`` maps
    points (N, 3) to their distances from the solid (0 inside), ``size`` is the solid's size (m).
    With ``floor`` (m) the value is only refined where it could exceed ``floor``: the bound returned
    is then at most the larger of ``floor`` and the largest distance + ``tol``."""
    return over_bounds(capsules, distance, size, tol, floor)[0]


def over_bounds(capsules, distance, size: float, tol: float | None = None,
                floor: float = 0.0) -> tuple[float, float]:
    """(upper, lower) of the over-estimate (m): ``upper`` as :func:`over_estimate` gives it,
    ``lower`` the largest distance found at a point of the union's surface (a lower bound)."""
    caps = list(capsules)
    tol = max(1e-6, OVER_TOL * size) if tol is None else tol
    best_bound = lower = 0.0            # lower: the largest distance at a point of the surface so far
    for i, c in enumerate(caps):
        R = c.radius
        if R <= 0:
            continue
        others = [o for j, o in enumerate(caps) if j != i]
        half = c.length / 2 + math.pi * R / 2
        n_s = max(8, int(math.ceil(2 * half / (R * 2 * math.pi / 48))))
        ds, dpsi = 2 * half / n_s, 2 * math.pi / 48
        s = -half + ds * (np.arange(n_s) + 0.5)
        psi = dpsi * (np.arange(48) + 0.5)
        S, PSI = (g.ravel() for g in np.meshgrid(s, psi, indexing="ij"))
        while True:
            delta = ds / 2 + R * dpsi / 2            # any point of a cell lies this close to its centre
            X = _surface_points(c, S, PSI)
            depth = np.full(len(X), -np.inf)         # how deep inside another capsule
            for o in others:
                depth = np.maximum(depth, o.radius - segment_distance(X, o.a, o.b))
            keep = depth <= delta                    # cells wholly inside another capsule are interior
            S, PSI, X, depth = S[keep], PSI[keep], X[keep], depth[keep]
            if not len(S):
                break
            d = distance(X)
            if np.any(depth <= 0):
                lower = max(lower, float(d[depth <= 0].max()))
            live = d + delta >= max(lower, floor)    # cells that may hold a larger distance
            if delta <= tol or not live.any():
                best_bound = max(best_bound, float((d + delta)[live].max(initial=0.0)))
                break
            S, PSI = S[live], PSI[live]
            ds, dpsi = ds / 2, dpsi / 2
            S = np.concatenate([S - ds / 2, S + ds / 2, S - ds / 2, S + ds / 2])
            PSI = np.concatenate([PSI - dpsi / 2, PSI - dpsi / 2, PSI + dpsi / 2, PSI + dpsi / 2])
            # the search space may grow quickly when the distance is flat: stop refining beyond a budget
            if len(S) > 400_000:
                X = _surface_points(c, S, PSI)
                best_bound = max(best_bound, float((distance(X) + ds / 2 + R * dpsi / 2).max()))
                break
    return max(best_bound, lower, floor), lower


# ---- fitting along an axis -----------------------------------------------------------------------
def _circle2(p, q) -> tuple[float, float, float]:
    cx, cy = (p[0] + q[0]) / 2, (p[1] + q[1]) / 2
    return cx, cy, math.hypot(p[0] - cx, p[1] - cy)


def _circle3(p, q, r) -> tuple[float, float, float]:
    ax, ay = p
    bx, by = q
    cx, cy = r
    d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
    if abs(d) < 1e-300:         # collinear: the widest pair
        return max((_circle2(p, q), _circle2(p, r), _circle2(q, r)), key=lambda t: t[2])
    a2, b2, c2 = ax * ax + ay * ay, bx * bx + by * by, cx * cx + cy * cy
    ux = (a2 * (by - cy) + b2 * (cy - ay) + c2 * (ay - by)) / d
    uy = (a2 * (cx - bx) + b2 * (ax - cx) + c2 * (bx - ax)) / d
    return ux, uy, math.hypot(ax - ux, ay - uy)


@lru_cache(maxsize=None)
def _permutation(n: int) -> np.ndarray:
    """A fixed pseudo-random order of n points (seed 0), drawn once per n."""
    p = np.random.default_rng(0).permutation(n)
    p.flags.writeable = False
    return p


def _min_circle(Q: np.ndarray) -> tuple[np.ndarray, float]:
    """The smallest circle holding the 2-D points Q (Welzl's algorithm, iterative, on their hull):
    its centre and radius."""
    if len(Q) > 3:
        try:
            from scipy.spatial import ConvexHull
            Q = Q[ConvexHull(Q).vertices]
        except Exception:       # collinear or coincident points: keep them all
            pass
    P = [tuple(p) for p in Q[_permutation(len(Q))].tolist()]
    hypot, grow = math.hypot, 1 + 1e-12
    c = (P[0][0], P[0][1], 0.0)
    for i in range(1, len(P)):        # a point is outside c when farther than its radius · (1 + 1e-12)
        if hypot(P[i][0] - c[0], P[i][1] - c[1]) > c[2] * grow:
            c = (P[i][0], P[i][1], 0.0)
            for j in range(i):
                if hypot(P[j][0] - c[0], P[j][1] - c[1]) > c[2] * grow:
                    c = _circle2(P[i], P[j])
                    for k in range(j):
                        if hypot(P[k][0] - c[0], P[k][1] - c[1]) > c[2] * grow:
                            c = _circle3(P[i], P[j], P[k])
    return np.array(c[:2]), c[2]


def _ends(t: np.ndarray, rho: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lowest and highest segment ends (axial positions) for radii R (G,) holding the points."""
    s = np.sqrt(np.maximum(R[:, None] ** 2 - rho[None, :] ** 2, 0.0))
    return (t[None, :] + s).min(axis=1), (t[None, :] - s).max(axis=1)


def _volume(R, lo, hi):
    return math.pi * R * R * np.maximum(hi - lo, 0.0) + 4.0 / 3.0 * math.pi * R ** 3


#: the radii a capsule along an axis tries, as fractions from the smallest (the farthest point's
#: distance from the axis) to the ball's: 49, or 17 when quick (squared: denser near the smallest)
RADIUS_GRID = {False: np.linspace(0.0, 1.0, 49) ** 2, True: np.linspace(0.0, 1.0, 17) ** 2}


def capsule_along(P: np.ndarray, u, point=None, quick: bool = False) -> Capsule:
    """The capsule of least volume about an axis of direction ``u`` that holds the points P (N, 3).

    The axis passes through ``point`` when given, else through the centre of the smallest circle
    holding the points' projections across it; the radius is the largest distance of the points from
    the chosen segment.  ``quick``: the best of a coarse set of radii, without refinement (for
    comparing cuts).
    """
    P = np.asarray(P, dtype=float)
    u = np.asarray(u, dtype=float)
    u = u / np.linalg.norm(u)
    e1, e2 = _axes(u)
    Q = np.column_stack([P @ e1, P @ e2])
    if point is None:
        c2, _ = _min_circle(Q)
    else:
        point = np.asarray(point, dtype=float)
        c2 = np.array([point @ e1, point @ e2])
    t = P @ u
    rho = np.linalg.norm(Q - c2, axis=1)
    rmax = float(rho.max())
    tm = (t.min() + t.max()) / 2
    r_ball = float(np.sqrt(((t - tm) ** 2 + rho ** 2).max()))
    if r_ball - rmax <= 1e-15 * max(1.0, r_ball):
        R_best = rmax
    else:
        g = RADIUS_GRID[quick]
        Rg = rmax + (r_ball - rmax) * g
        lo, hi = _ends(t, rho, Rg)
        V = _volume(Rg, lo, hi)
        k = int(np.argmin(V))
        x0, x1 = Rg[max(k - 1, 0)], Rg[min(k + 1, len(Rg) - 1)]
        if quick:
            x0 = x1 = Rg[k]
        ratio = (math.sqrt(5) - 1) / 2
        for _ in range(0 if quick else 40):        # golden section on the bracket
            m0, m1 = x1 - ratio * (x1 - x0), x0 + ratio * (x1 - x0)
            lo2, hi2 = _ends(t, rho, np.array([m0, m1]))
            v = _volume(np.array([m0, m1]), lo2, hi2)
            if v[0] <= v[1]:
                x1 = m1
            else:
                x0 = m0
        cand = np.array([Rg[k], (x0 + x1) / 2])
        lo2, hi2 = _ends(t, rho, cand)
        R_best = float(cand[int(np.argmin(_volume(cand, lo2, hi2)))])
    lo, hi = _ends(t, rho, np.array([R_best]))
    lo, hi = float(lo[0]), float(hi[0])
    if hi < lo:                                     # a ball will do
        lo = hi = (lo + hi) / 2
    base = c2[0] * e1 + c2[1] * e2
    a, b = base + lo * u, base + hi * u
    radius = float(segment_distance(P, a, b).max())
    return Capsule(_tup(a), _tup(b), radius)


# ---- primitives ------------------------------------------------------------------------------------
def _pose(pose) -> np.ndarray:
    return np.eye(4) if pose is None else np.asarray(pose, dtype=float)


def enclose_sphere(center, radius: float) -> Enclosure:
    """A sphere is a capsule with a point segment: exact."""
    c = _tup(np.asarray(center, dtype=float))
    return Enclosure((Capsule(c, c, float(radius)),), 0.0)


def _cap_over(dist, R: float, L: float, grid: int = 241) -> float:
    """The largest ``dist(φ, ψ)`` over the quarter of a capsule's end, φ from the rim (0) to the tip
    (π/2), ψ about the axis (0 … π/2) — a dense grid, then a bounded local search from its best
    point (the distance of a capsule's end to a box or a cylinder is smooth and has one summit per
    quarter; the side is the rim's φ = 0)."""
    from scipy.optimize import minimize
    phi, psi = np.meshgrid(np.linspace(0, math.pi / 2, grid), np.linspace(0, math.pi / 2, grid), indexing="ij")
    D = dist(phi.ravel(), psi.ravel())
    k = int(np.argmax(D))
    x0 = np.array([phi.ravel()[k], psi.ravel()[k]])
    res = minimize(lambda x: -dist(np.array([x[0]]), np.array([x[1]]))[0], x0, method="L-BFGS-B",
                   bounds=[(0, math.pi / 2), (0, math.pi / 2)], options={"ftol": 1e-15, "gtol": 1e-12})
    return float(max(D[k], -res.fun))


def enclose_box(size, pose=None) -> Enclosure:
    """A box of full edge lengths ``size`` (3,), centred on its frame ``pose`` (4×4, default identity):
    the least-volume capsule along its longest edge, in the pose's parent frame.  Its over-estimate is
    the largest distance from the capsule's end (the side is its rim) to the box, found on a dense grid
    and refined (to about 1e-12 m)."""
    half = np.asarray(size, dtype=float) / 2
    return _enclose_box(tuple(float(h) for h in half)).moved(_pose(pose))


@lru_cache(maxsize=4096)
def _enclose_box(half: tuple[float, float, float]) -> Enclosure:
    h = np.array(half)
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h
    axis = int(np.argmax(h))
    cap = capsule_along(corners, np.eye(3)[axis], point=np.zeros(3))
    h1, (h2, h3) = h[axis], np.delete(h, axis)
    R, L = cap.radius, cap.length / 2

    def dist(phi, psi):
        rho = R * np.cos(phi)
        across = np.hypot(np.maximum(np.abs(rho * np.cos(psi)) - h2, 0), np.maximum(np.abs(rho * np.sin(psi)) - h3, 0))
        return np.hypot(np.maximum(L + R * np.sin(phi) - h1, 0), across)

    return Enclosure((cap,), _cap_over(dist, R, L))


def enclose_cylinder(radius: float, length: float, pose=None) -> Enclosure:
    """A cylinder of ``radius`` and ``length`` along the z axis of its frame ``pose`` (4×4), centred on
    it: the least-volume capsule along its axis, in the pose's parent frame; its over-estimate as for a
    box."""
    return _enclose_cylinder(float(radius), float(length)).moved(_pose(pose))


@lru_cache(maxsize=4096)
def _enclose_cylinder(radius: float, length: float) -> Enclosure:
    # every rim point lies at the same distance from the axis and the same height: four per rim do
    rims = np.array([[x, y, z] for z in (-length / 2, length / 2)
                     for x, y in ((radius, 0.0), (-radius, 0.0), (0.0, radius), (0.0, -radius))])
    cap = capsule_along(rims, (0.0, 0.0, 1.0), point=np.zeros(3))
    R, L, h = cap.radius, cap.length / 2, length / 2

    def dist(phi, psi):
        return np.hypot(np.maximum(L + R * np.sin(phi) - h, 0), np.maximum(R * np.cos(phi) - radius, 0))

    return Enclosure((cap,), _cap_over(dist, R, L))


# ---- point sets and meshes -------------------------------------------------------------------------
def _hull_points(P: np.ndarray) -> np.ndarray:
    if len(P) <= 4:
        return P
    try:
        from scipy.spatial import ConvexHull
        return P[ConvexHull(P).vertices]
    except Exception:       # flat or degenerate: every point
        return P


def _hull_triangles(P: np.ndarray) -> np.ndarray | None:
    try:
        from scipy.spatial import ConvexHull
        h = ConvexHull(P)
        return P[h.simplices]
    except Exception:
        return None


def _pca_axes(P: np.ndarray) -> list[np.ndarray]:
    X = P - P.mean(axis=0)
    _, _, Vt = np.linalg.svd(X, full_matrices=False)
    return [Vt[i] for i in range(min(3, len(Vt)))]


def _rotate(u: np.ndarray, axis: np.ndarray, ang: float) -> np.ndarray:
    return u * math.cos(ang) + np.cross(axis, u) * math.sin(ang) + axis * (axis @ u) * (1 - math.cos(ang))


def _fit(P: np.ndarray, extra=(), refine: bool = True, fast: bool = False) -> Capsule:
    """The least-volume capsule over PCA (and ``extra``) directions, refined by a pattern search.

    ``fast``: the directions are compared by quick capsules (17 radii) of at most
    :data:`SEARCH_POINTS` of the hull's vertices (:func:`thinned`), the search stops at steps of
    0.01 rad (else 0.004), and only the capsule along the best direction is fitted to all the points
    — it holds every point either way."""
    H = _hull_points(P)
    if len(H) == 1 or float(np.ptp(H, axis=0).max()) == 0.0:
        c = _tup(H[0])
        return Capsule(c, c, 0.0)
    cands = _pca_axes(H) + [np.asarray(e, dtype=float) for e in extra]
    quick = fast or not refine
    G = thinned(H, SEARCH_POINTS) if fast else H
    best = min((capsule_along(G, u, quick=quick) for u in cands), key=lambda c: c.volume)

    def direction(c: Capsule, fallback: np.ndarray) -> np.ndarray:
        d = np.subtract(c.b, c.a)
        n = np.linalg.norm(d)
        return d / n if n > 0 else fallback

    u = direction(best, cands[0])
    step, stop = 0.2, (0.01 if fast else 0.004)
    while refine and step > stop:
        e1, e2 = _axes(u)
        moved = False
        for ax in (e1, e2):
            for sgn in (1.0, -1.0):
                v = _rotate(u, ax, sgn * step)
                c = capsule_along(G, v, quick=quick)
                if c.volume < best.volume * (1 - 1e-9):
                    best, u, moved = c, v, True
        if not moved:
            step /= 2
    if not fast or (G is H and not refine):        # best is already the capsule along u of every point
        return best
    return capsule_along(H, u, quick=not refine)


#: the fast direction search of :func:`_fit` looks at most at about this many hull vertices
SEARCH_POINTS = 400


def thinned(P: np.ndarray, budget: int) -> np.ndarray:
    """About at most ``budget`` of the points P (N, 3): the first in each cell of a cubic grid over
    them, the grid coarsened until few enough remain (every point lies within a cell of one kept)."""
    if len(P) <= budget:
        return P
    lo, span = P.min(axis=0), float(np.ptp(P, axis=0).max())
    cells = max(2, int(round(math.sqrt(budget))))
    while True:
        key = np.floor((P - lo) / span * cells).astype(np.int64)
        key = (key[:, 0] * (cells + 1) + key[:, 1]) * (cells + 1) + key[:, 2]
        _, first = np.unique(key, return_index=True)
        if len(first) <= budget or cells <= 2:
            return P[np.sort(first)]
        cells = max(2, int(cells * 0.8))


def surface_samples(tris: np.ndarray, spacing: float, max_per_edge: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """Points on the triangles (M, 3, 3) about ``spacing`` apart (a barycentric grid per triangle, at
    most ``max_per_edge`` steps along an edge), and the index of the triangle each lies on."""
    tris = np.asarray(tris, dtype=float)
    edge = np.linalg.norm(tris - np.roll(tris, 1, axis=1), axis=2).max(axis=1)
    k = np.clip(np.ceil(edge / spacing), 1, max_per_edge).astype(int)
    pts, ids = [], []
    for kk in np.unique(k):
        sel = np.flatnonzero(k == kk)
        i, j = np.meshgrid(np.arange(kk + 1), np.arange(kk + 1), indexing="ij")
        m = (i + j) <= kk
        w1, w2 = i[m] / kk, j[m] / kk
        w0 = 1.0 - w1 - w2
        T = tris[sel]
        pts.append((w0[None, :, None] * T[:, None, 0] + w1[None, :, None] * T[:, None, 1]
                    + w2[None, :, None] * T[:, None, 2]).reshape(-1, 3))
        ids.append(np.repeat(sel, len(w0)))
    return np.concatenate(pts, axis=0), np.concatenate(ids)


def point_triangle_distance(P: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Distance of points P (..., 3) from triangles T (..., 3, 3), pairwise over the leading axes
    (Ericson's closest point on a triangle, vectorised)."""
    A, B, C = T[..., 0, :], T[..., 1, :], T[..., 2, :]
    AB, AC, BC = B - A, C - A, C - B
    AP, BP, CP = P - A, P - B, P - C
    d1, d2 = (AB * AP).sum(-1), (AC * AP).sum(-1)
    d3, d4 = (AB * BP).sum(-1), (AC * BP).sum(-1)
    d5, d6 = (AB * CP).sum(-1), (AC * CP).sum(-1)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    den = va + vb + vc
    inside = (va >= 0) & (vb >= 0) & (vc >= 0) & (den > 0)
    safe = np.where(den > 0, den, 1.0)
    face = A + (vb / safe)[..., None] * AB + (vc / safe)[..., None] * AC
    best = np.where(inside, np.linalg.norm(P - face, axis=-1), np.inf)
    for S0, E in ((A, AB), (A, AC), (B, BC)):           # the three edges
        ee = (E * E).sum(-1)
        t = np.clip(((P - S0) * E).sum(-1) / np.where(ee > 0, ee, 1.0), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(P - S0 - t[..., None] * E, axis=-1))
    return best


def _mesh_distance(tris: np.ndarray, k: int = 1, samples=None):
    """A distance function to the triangles: the exact distance to the nearest of the triangles that
    hold the ``k`` samples nearest to the point — never below the distance to the mesh, and equal to
    it unless the nearest triangle holds none of those samples.  ``samples``: the points (N, 3) and a
    triangle of each (N,) to use instead of :func:`surface_samples` at 1/100 of the mesh's size."""
    from scipy.spatial import cKDTree
    if samples is None:
        size = float(np.linalg.norm(np.ptp(tris.reshape(-1, 3), axis=0)))
        samples = surface_samples(tris, max(size / 100, 1e-9))
    pts, ids = samples
    tree = cKDTree(pts)
    k = min(k, len(pts))

    def dist(X):
        X = np.asarray(X, dtype=float)
        out = np.empty(len(X))
        for s in range(0, len(X), 20000):
            x = X[s:s + 20000]
            _, nn = tree.query(x, k=k)
            nn = nn.reshape(len(x), k)
            out[s:s + 20000] = point_triangle_distance(x[:, None, :], tris[ids[nn]]).min(axis=1)
        return out
    return dist


@lru_cache(maxsize=8)
def unit_samples(n: int) -> np.ndarray:
    """n fixed pseudo-random points of the unit cube (seed 1), (n, 3), drawn once per n."""
    X = np.random.default_rng(1).random((n, 3))
    X.flags.writeable = False
    return X


def union_volume(capsules, n: int = 20000) -> float:
    """The volume of a union of capsules, estimated with ``n`` pseudo-random points (fixed seed) in
    its bounding box (a few per cent)."""
    caps = list(capsules)
    if len(caps) == 1:
        return caps[0].volume
    lo = np.min([np.minimum(c.a, c.b) - c.radius for c in caps], axis=0)
    hi = np.max([np.maximum(c.a, c.b) + c.radius for c in caps], axis=0)
    X = lo + (hi - lo) * unit_samples(n)
    inside = np.zeros(n, dtype=bool)
    for c in caps:
        inside |= segment_distance(X, c.a, c.b) <= c.radius
    return float(inside.mean() * np.prod(hi - lo))


def enclose_points(points) -> Enclosure:
    """One capsule holding every point of ``points`` (N, 3); the over-estimate is with respect to the
    points' convex hull."""
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    cap = _fit(P, extra=np.eye(3))
    tris = _hull_triangles(P)
    if tris is None:            # flat: the points themselves (a subset of the hull) bound the distance
        from scipy.spatial import cKDTree
        tree = cKDTree(P)
        size = float(np.linalg.norm(np.ptp(P, axis=0)))
        return Enclosure((cap,), over_estimate([cap], lambda X: tree.query(X)[0], size))
    size = float(np.linalg.norm(np.ptp(tris.reshape(-1, 3), axis=0)))
    return Enclosure((cap,), over_estimate([cap], _mesh_distance(tris, k=4), size, tol=max(size / 500, 1e-6)))
