"""Capsules enclosing a triangle mesh (:func:`fit_mesh`, :func:`enclose_mesh`): one capsule, or the
mesh cut by one plane into two slabs or by two parallel planes into three, each slab enclosed by its
own capsule.

* **Slabs.** The part of the solid between two planes lies in the convex hull of the surface there,
  whose extreme points are corners of the mesh between the planes and points where its edges cross
  them (:class:`Surface`); a slab's capsule is fitted to those points, so it holds the slab, and the
  slabs' capsules together hold the solid.
* **Candidate cuts.** Normals along the principal axes of the mesh's hull, the frame's axes and
  their diagonals (at most 12; the first 6 for three slabs); one plane at 8 positions from 15 to 85 %
  of the extent, or two planes at 7 positions from 10 to 90 %, at least two positions apart.
* **Scoring** a cut: the union volume (sampled) of quick capsules of its slabs (17 radii along the
  principal axes, :func:`kin.geometry.enclose.capsule_along`).  ``search="exhaustive"`` scores every
  candidate so (how the bundled arms' capsules were fitted); ``search="fast"`` (the default) first
  scores all candidates at once with batched proxies of the same capsules on at most
  :data:`PROXY_POINTS` of the surface's points (:func:`_proxy_capsules`: each subset's principal
  axes, the centre of a circle through its extreme points across the axis), then scores its
  :data:`TOP` best exactly, and compares directions in the final fits on at most
  :data:`kin.geometry.enclose.SEARCH_POINTS` hull vertices (:func:`kin.geometry.enclose._fit`).
* **Choice.** The best cut into two and into three slabs are fitted carefully (PCA and frame axes,
  then a pattern search over directions); the one of least union volume is taken when it is at
  least ``gain`` per extra capsule smaller than the single capsule and stands out of the mesh no
  more than it does (or at most 5 % more while a fifth smaller).  The over-estimates compared are
  bounded coarsely first (:func:`kin.geometry.enclose.over_bounds`) and made precise only when the
  bounds do not decide.
* **Over-estimate** of the chosen capsules: :meth:`MeshFit.over_estimate`, within 1/500 of the
  mesh's size, refined only above a ``floor`` (the largest value of a robot's other elements).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kin.geometry.enclose import (
    Capsule,
    Enclosure,
    _fit,
    _hull_points,
    _mesh_distance,
    _pca_axes,
    over_bounds,
    thinned,
    union_volume,
    unit_samples,
)

SEARCHES = ("fast", "exhaustive")
#: the fast search's proxies look at most at about this many corners of the mesh, and as many points
#: where its edges cross each plane
PROXY_POINTS = 600
CROSSING_POINTS = 24
#: the fast search scores this many of the best-scored candidates as the exhaustive one does
TOP = 8
#: ... on at most about this many points of each slab
RESCORE_POINTS = 2000
#: the fast search fits a cut carefully only when its quick union volume is within this factor of
#: what it must reach (careful fits shrink a union by a few per cent)
REFINE_SLACK = 1.25
#: the decisions' over-estimates are first bounded within this fraction of the mesh's size
COARSE_TOL = 1 / 100
#: the stated over-estimate is within this fraction of the mesh's size
FINE_TOL = 1 / 500


class Surface:
    """A triangle mesh (``tris`` (M, 3, 3)) as the points that matter to enclosing its slabs: its
    distinct corners ``V`` (K, 3), a triangle of each (``triangle_of`` (K,)) and its edges ``E``
    (L, 2) (indices into V)."""

    def __init__(self, tris: np.ndarray):
        self.V, first, inv = np.unique(tris.reshape(-1, 3), axis=0, return_index=True, return_inverse=True)
        self.triangle_of = first // 3          # a triangle of each corner
        F = inv.reshape(-1, 3)
        E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        real = np.flatnonzero(E[:, 0] != E[:, 1])
        key, first = np.unique(E[real, 0] * len(self.V) + E[real, 1], return_index=True)
        self.E = np.column_stack([key // len(self.V), key % len(self.V)])
        self.edge_triangle = real[first] % len(F)      # a triangle of each edge
        self.tris = tris

    def samples(self, spacing: float) -> tuple[np.ndarray, np.ndarray]:
        """Points of the surface (N, 3) and a triangle holding each (N,): every corner once, points
        along every edge and a barycentric grid inside the triangles whose inradius exceeds
        ``spacing``/2, at most 16 steps along an edge as :func:`kin.geometry.enclose.surface_samples`
        — every point of the surface lies within max(``spacing``, longest edge / 16) of one (a thin
        triangle's points lie within its inradius of its edges).  Unlike a grid in every triangle, a
        fine mesh's many thin triangles add few points."""
        pts, ids = [self.V], [self.triangle_of]
        a, b = self.V[self.E[:, 0]], self.V[self.E[:, 1]]
        m = np.minimum(np.ceil(np.linalg.norm(b - a, axis=1) / spacing), 16).astype(np.int64) - 1   # inside each edge
        if m.max(initial=0) > 0:
            e = np.repeat(np.arange(len(m)), m)
            j = np.arange(len(e)) - np.repeat(np.cumsum(m) - m, m) + 1
            t = (j / (m[e] + 1))[:, None]
            pts.append(a[e] + t * (b[e] - a[e]))
            ids.append(self.edge_triangle[e])
        T = self.tris
        A, B, C = T[:, 0], T[:, 1], T[:, 2]
        la, lb, lc = (np.linalg.norm(B - C, axis=1), np.linalg.norm(C - A, axis=1), np.linalg.norm(A - B, axis=1))
        area = 0.5 * np.linalg.norm(np.cross(B - A, C - A), axis=1)
        inradius = 2 * area / np.maximum(la + lb + lc, 1e-300)
        big = np.flatnonzero(inradius > spacing / 2)
        if len(big):
            kk = np.clip(np.ceil(np.maximum(np.maximum(la, lb), lc)[big] / spacing), 3, 16).astype(np.int64)
            for k in np.unique(kk):
                sel = big[kk == k]
                i, j = np.meshgrid(np.arange(1, k), np.arange(1, k), indexing="ij")
                keep = (i + j) < k
                w1, w2 = i[keep] / k, j[keep] / k
                w0 = 1.0 - w1 - w2
                P = w0[None, :, None] * T[sel, None, 0] + w1[None, :, None] * T[sel, None, 1] \
                    + w2[None, :, None] * T[sel, None, 2]
                pts.append(P.reshape(-1, 3))
                ids.append(np.repeat(sel, len(w0)))
        return np.concatenate(pts), np.concatenate(ids)

    def crossings(self, s: np.ndarray, off: float) -> np.ndarray:
        """Where the edges cross the plane n·x = ``off`` (``s`` = V·n, (K,)): (C, 3)."""
        sa, sb = s[self.E[:, 0]] - off, s[self.E[:, 1]] - off
        m = ((sa < 0) & (sb > 0)) | ((sa > 0) & (sb < 0))
        a, b, sa, sb = self.E[m, 0], self.E[m, 1], sa[m], sb[m]
        return self.V[a] + (sa / (sa - sb))[:, None] * (self.V[b] - self.V[a])

    def slab(self, s: np.ndarray, lo: float, hi: float, cross) -> np.ndarray:
        """The points of the surface with lo ≤ n·x ≤ hi (either may be infinite): corners between
        the planes and ``cross(offset)`` on each finite one."""
        parts = [self.V[(s >= lo) & (s <= hi)]]
        parts += [cross(o) for o in (lo, hi) if math.isfinite(o)]
        return np.concatenate(parts)


def _directions(H: np.ndarray) -> list[np.ndarray]:
    """Cut normals: the principal axes, the frame's axes and their diagonals, without repeats."""
    frame = list(np.eye(3))
    diagonals = [(e + sgn * f) / math.sqrt(2) for i, e in enumerate(frame) for f in frame[i + 1:] for sgn in (1, -1)]
    uniq: list[np.ndarray] = []
    for v in _pca_axes(H) + frame + diagonals:
        v = v / np.linalg.norm(v)
        if all(abs(v @ w) < 0.999 for w in uniq):
            uniq.append(v)
    return uniq


def _candidates(H: np.ndarray, k: int, directions: int = 12):
    """The candidate cuts into ``k`` slabs: (normal, plane offsets, cuts — tuples of k − 1 offsets)
    per direction (at most ``directions``, and 6 for three slabs)."""
    fractions = np.linspace(0.15, 0.85, 8) if k == 2 else np.linspace(0.1, 0.9, 7)
    for i, n in enumerate(_directions(H)):
        if i >= (6 if k == 3 else directions):      # three slabs: along the principal and frame axes only
            break
        proj = H @ n
        offs = proj.min() + fractions * (proj.max() - proj.min())
        cuts = [(o,) for o in offs] if k == 2 else [(o1, o2) for j, o1 in enumerate(offs) for o2 in offs[j + 2:]]
        yield n, offs, cuts


def _slabs_of(cut) -> list[tuple[float, float]]:
    bounds = (-math.inf, *cut, math.inf)
    return list(zip(bounds[:-1], bounds[1:]))


def _exact_slabs(surface: Surface, n: np.ndarray):
    """A function (lo, hi) → the points of that slab along ``n``, crossings computed once per plane."""
    s = surface.V @ n
    memo: dict[float, np.ndarray] = {}

    def cross(o):
        if o not in memo:
            memo[o] = surface.crossings(s, o)
        return memo[o]
    return lambda lo, hi: surface.slab(s, lo, hi, cross)


def _clip(tris: np.ndarray, n: np.ndarray, off: float) -> np.ndarray:
    """The parts of triangles (M, 3, 3) with n·x ≤ off, as triangles."""
    if not len(tris):
        return tris
    s = tris @ n - off                                   # (M, 3)
    inside = s <= 0
    k = inside.sum(axis=1)
    out = [tris[k == 3]]
    for count in (1, 2):
        sel = k == count
        if not sel.any():
            continue
        T, S, ins = tris[sel], s[sel], inside[sel]
        # roll each triangle so that vertex 0 is the odd one (the lone inside vertex for count 1,
        # the lone outside vertex for count 2)
        odd = np.argmax(ins if count == 1 else ~ins, axis=1)
        idx = (odd[:, None] + np.arange(3)[None, :]) % 3
        T = np.take_along_axis(T, idx[:, :, None], axis=1)
        S = np.take_along_axis(S, idx, axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = np.where(S[:, 0] != S[:, 1], S[:, 0] / (S[:, 0] - S[:, 1]), 0.0)
            t2 = np.where(S[:, 0] != S[:, 2], S[:, 0] / (S[:, 0] - S[:, 2]), 0.0)
        p1 = T[:, 0] + t1[:, None] * (T[:, 1] - T[:, 0])
        p2 = T[:, 0] + t2[:, None] * (T[:, 2] - T[:, 0])
        if count == 1:
            out.append(np.stack([T[:, 0], p1, p2], axis=1))
        else:
            out.append(np.stack([p1, T[:, 1], T[:, 2]], axis=1))
            out.append(np.stack([p1, T[:, 2], p2], axis=1))
    return np.concatenate(out, axis=0)


def _pieces(tris: np.ndarray, n: np.ndarray, offsets) -> list[np.ndarray]:
    """The triangle soup cut by the parallel planes n·x = offset (ascending): the slabs, low to high."""
    out, rest = [], tris
    for off in offsets:
        out.append(_clip(rest, n, off))
        rest = _clip(rest, -n, -off)
    return out + [rest]


def _exhaustive_cut(tris: np.ndarray, k: int):
    """(score, slabs' points) of the candidate cut whose quick capsules have the least union volume,
    every candidate scored; None when no cut leaves k non-empty slabs.  The slabs are the triangles
    clipped to them (as the bundled arms' capsules were fitted, point for point)."""
    H = _hull_points(tris.reshape(-1, 3))
    best = None
    for n, _, cuts in _candidates(H, k):
        for cut in cuts:
            pieces = _pieces(tris, n, cut)
            if any(len(p) == 0 for p in pieces):
                continue
            v = union_volume([_fit(p.reshape(-1, 3), refine=False) for p in pieces], 5000)
            if best is None or v < best[0]:
                best = (v, [p.reshape(-1, 3) for p in pieces])
    return best


def _fast_cut(surface: Surface, H: np.ndarray, k: int):
    """As :func:`_exhaustive_cut`, but every candidate scored by batched proxies on at most about
    :data:`PROXY_POINTS` points and only the :data:`TOP` best scored exactly."""
    Vs = thinned(surface.V, PROXY_POINTS)
    scored = []
    for n, offs, cuts in _candidates(H, k, FAST_DIRECTIONS):
        s_all = surface.V @ n
        cross = [thinned(surface.crossings(s_all, o), CROSSING_POINTS) for o in offs]
        P = np.concatenate([Vs, *cross])
        s = Vs @ n
        plane = np.concatenate([np.full(len(c), j) for j, c in enumerate(cross)])
        index = {o: j for j, o in enumerate(offs)}
        slabs = sorted({sl for cut in cuts for sl in _slabs_of(cut)})
        M = np.zeros((len(slabs), len(P)), dtype=bool)
        for j, (lo, hi) in enumerate(slabs):
            M[j, :len(Vs)] = (s >= lo) & (s <= hi)
            for o in (lo, hi):
                if o in index:
                    M[j, len(Vs):] |= plane == index[o]
        A, B, R = _proxy_capsules(P, M)
        filled = M.any(axis=1)
        row = {sl: j for j, sl in enumerate(slabs)}
        for cut in cuts:
            js = [row[sl] for sl in _slabs_of(cut)]
            if filled[js].all():
                scored.append((n, cut, A[js], B[js], R[js]))
    if not scored:
        return None
    vols = _union_volumes(np.array([x[2] for x in scored]), np.array([x[3] for x in scored]),
                          np.array([x[4] for x in scored]))
    best, fits = None, {}
    for i in np.argsort(vols, kind="stable")[:TOP]:
        n, cut = scored[i][:2]
        slab = _exact_slabs(surface, n)
        for sl in _slabs_of(cut):          # a slab shared by several of the best cuts is fitted once
            key = (n.tobytes(), sl)
            if key not in fits:
                P = slab(*sl)
                fits[key] = (P, _fit(thinned(P, RESCORE_POINTS), refine=False, fast=True) if len(P) else None)
        pieces = [fits[n.tobytes(), sl] for sl in _slabs_of(cut)]
        if any(c is None for _, c in pieces):
            continue
        v = union_volume([c for _, c in pieces], 5000)
        if best is None or v < best[0]:
            best = (v, [P for P, _ in pieces])
    return best


# ---- batched proxies ---------------------------------------------------------------------------------
_CIRCLE_DIRS = np.array([[math.cos(a), math.sin(a)] for a in np.arange(6) * math.pi / 6], dtype=np.float32)
_PAIRS = np.array([(i, j) for i in range(12) for j in range(i + 1, 12)])
_G9 = (np.linspace(0.0, 1.0, 9) ** 2).astype(np.float32)
PROXY_AXES = (0, 1, 2)
FAST_DIRECTIONS = 12


def _circle_centres(Q: np.ndarray) -> np.ndarray:
    """Centres (B, 2) of about the smallest circles holding each set of 2-D points Q (B, m, 2): of the
    midpoints of every two points and the centre of their bounding box, the one nearest to its
    farthest point (exact when two of the points span the smallest circle)."""
    mid = (Q[:, _PAIRS[:, 0]] + Q[:, _PAIRS[:, 1]]) / 2
    box = ((Q.max(axis=1) + Q.min(axis=1)) / 2)[:, None, :]
    cent = np.concatenate([mid, box], axis=1)                                         # (B, K, 2)
    r = np.linalg.norm(Q[:, None, :, :] - cent[:, :, None, :], axis=-1).max(axis=2)   # (B, K)
    return cent[np.arange(len(Q)), np.argmin(r, axis=1)]


def _proxy_capsules(P: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Capsules holding the subsets of the points P (N, 3) that the rows of M (S, N) mark, made as a
    quick fit makes them but all at once: along each of the subset's principal axes (of the points,
    not of their hull), through the centre of a circle holding its extreme points in six directions
    across the axis (:func:`_circle_centres`, in the other two principal axes), the least volume of
    9 radii; the least of the three axes.  Ends a, b (S, 3) and radii (S,); every marked point lies
    inside its capsule."""
    S, inf = len(M), np.inf
    W = M.astype(np.float32)
    P = P.astype(np.float32)                 # a ranking: single precision is plenty, and faster
    mean = (W @ P) / np.maximum(W.sum(axis=1), 1.0)[:, None]
    X = P[None, :, :] - mean[:, None, :]
    _, vecs = np.linalg.eigh(np.einsum("sn,sni,snj->sij", W, X, X))          # columns: the axes
    Y = np.einsum("sni,sij->sjn", X, vecs)                                   # (S, 3, N)
    Mb, ix = M[:, None, :], np.arange(S)
    best = None
    for ax in PROXY_AXES:
        t, q = Y[:, ax], Y[:, [(ax + 1) % 3, (ax + 2) % 3]]
        proj = np.einsum("dk,skn->sdn", _CIRCLE_DIRS, q)                       # (S, 6, N)
        ext = np.concatenate([np.where(Mb, proj, -inf).argmax(axis=2), np.where(Mb, proj, inf).argmin(axis=2)], axis=1)
        cen = _circle_centres(np.take_along_axis(q, ext[:, None, :], axis=2).transpose(0, 2, 1))
        rho = np.where(M, np.hypot(q[:, 0] - cen[:, 0, None], q[:, 1] - cen[:, 1, None]), 0.0)
        rmax = rho.max(axis=1)
        tm = (np.where(M, t, inf).min(axis=1) + np.where(M, t, -inf).max(axis=1)) / 2
        rball = np.sqrt(np.where(M, (t - tm[:, None]) ** 2 + rho ** 2, 0.0).max(axis=1))
        R = rmax[:, None] + (rball - rmax)[:, None] * _G9[None, :]                # (S, 9)
        sq = np.sqrt(np.maximum(R[:, :, None] ** 2 - rho[:, None, :] ** 2, 0.0))
        lo = np.where(Mb, t[:, None, :] + sq, inf).min(axis=2)
        hi = np.where(Mb, t[:, None, :] - sq, -inf).max(axis=2)
        vol = math.pi * R * R * np.maximum(hi - lo, 0.0) + 4.0 / 3.0 * math.pi * R ** 3
        g = np.argmin(vol, axis=1)
        lo, hi = lo[ix, g], np.maximum(hi[ix, g], lo[ix, g])
        u = vecs[:, :, ax]
        base = mean + cen[:, 0, None] * vecs[:, :, (ax + 1) % 3] + cen[:, 1, None] * vecs[:, :, (ax + 2) % 3]
        cand = (vol[ix, g], base + lo[:, None] * u, base + hi[:, None] * u, R[ix, g])
        if best is None:
            best = cand
        else:
            take = cand[0] < best[0]
            best = tuple(np.where(take[:, None] if c.ndim == 2 else take, c, b) for c, b in zip(cand, best))
    return tuple(np.asarray(x, dtype=float) for x in best[1:])


def _union_volumes(A: np.ndarray, B: np.ndarray, R: np.ndarray, n: int = 1000) -> np.ndarray:
    """Volumes of C unions of K capsules each (ends A, B (C, K, 3), radii R (C, K)), sampled by n
    fixed pseudo-random points in each union's bounding box."""
    lo = (np.minimum(A, B) - R[..., None]).min(axis=1)
    hi = (np.maximum(A, B) + R[..., None]).max(axis=1)
    X = lo[:, None, :] + (hi - lo)[:, None, :] * unit_samples(n)[None]       # (C, n, 3)
    inside = np.zeros(X.shape[:2], dtype=bool)
    for j in range(A.shape[1]):
        a, d = A[:, j], B[:, j] - A[:, j]
        Xa = X - a[:, None, :]
        dd = np.einsum("ci,ci->c", d, d)
        t = np.clip(np.einsum("cni,ci->cn", Xa, d) / np.where(dd > 0, dd, 1.0)[:, None], 0.0, 1.0)
        Xa -= t[..., None] * d[:, None, :]
        inside |= np.einsum("cni,cni->cn", Xa, Xa) <= (R[:, j] ** 2)[:, None]
    return inside.mean(axis=1) * np.prod(hi - lo, axis=1)


# ---- the fit -----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class MeshFit:
    """The capsules chosen for a mesh and what it takes to state their over-estimate:
    ``lower`` (m) is the largest distance from their surface to the mesh found so far."""

    capsules: tuple[Capsule, ...]
    lower: float
    tris: np.ndarray
    distance: object
    size: float

    def over_estimate(self, floor: float = 0.0) -> float:
        """The over-estimate (m): an upper bound within 1/500 of the mesh's size of the largest
        distance from the capsules' surface to the mesh — refined only where it could exceed
        ``floor`` (then at most ``floor``)."""
        return over_bounds(self.capsules, self.distance, self.size, tol=max(self.size * FINE_TOL, 1e-6),
                           floor=floor)[0]


def fit_mesh(vertices, faces, max_capsules: int = 3, gain: float = 0.05, search: str = "fast") -> MeshFit:
    """Capsules (at most ``max_capsules``, 1 to 3) that together hold the solid bounded by the
    triangle mesh (``vertices`` (V, 3), ``faces`` (F, 3) indices): see the module docstring."""
    V = np.asarray(vertices, dtype=float).reshape(-1, 3)
    F = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if not len(F):
        raise ValueError("the mesh has no triangles")
    if not np.all(np.isfinite(V)):
        raise ValueError("the mesh has NaN or infinite vertices")
    if not 1 <= max_capsules <= 3:
        raise ValueError(f"max_capsules = {max_capsules} must be 1, 2 or 3")
    if search not in SEARCHES:
        raise ValueError(f"search {search!r} unknown; allowed: {', '.join(SEARCHES)}")
    fast = search == "fast"
    tris = V[F]
    size = float(np.linalg.norm(np.ptp(tris.reshape(-1, 3), axis=0)))
    frame = np.eye(3)
    if fast:
        surface = Surface(tris)
        H = _hull_points(surface.V)
        distance = _mesh_distance(tris, samples=surface.samples(max(size / 100, 1e-9)))
        single = (_fit(surface.V, extra=frame, fast=True),)
    else:
        distance = _mesh_distance(tris, k=4)
        single = (_fit(tris.reshape(-1, 3), extra=frame),)
    v_single = union_volume(single)
    cands = []
    for k in range(2, max_capsules + 1):
        found = _fast_cut(surface, H, k) if fast else _exhaustive_cut(tris, k)
        if fast and found is not None and found[0] > REFINE_SLACK * (1 - gain * (k - 1)) * v_single:
            continue
        if found is not None:
            caps = tuple(_fit(p, extra=frame, fast=fast) for p in found[1])
            vol = union_volume(caps)
            if vol <= (1 - gain * (k - 1)) * v_single:
                cands.append((vol, caps))

    def bounds(caps, tol):
        return over_bounds(caps, distance, size, tol=max(size * tol, 1e-6))

    single_bounds = None
    for vol, caps in sorted(cands, key=lambda c: c[0]):     # the smallest union that is no worse
        if single_bounds is None:
            single_bounds = bounds(single, COARSE_TOL)
        mine = bounds(caps, COARSE_TOL)
        if mine[0] <= single_bounds[1] * (1 + 1e-6):       # surely no worse
            return MeshFit(caps, mine[1], tris, distance, size)
        if mine[1] > 1.05 * single_bounds[0]:               # surely worse
            continue
        if len(single_bounds) == 2:
            single_bounds = (*bounds(single, FINE_TOL), "fine")
        over = bounds(caps, FINE_TOL)[0]
        if over <= single_bounds[0] * (1 + 1e-6) or (over <= 1.05 * single_bounds[0] and vol < 0.8 * v_single):
            return MeshFit(caps, mine[1], tris, distance, size)
    return MeshFit(single, 0.0 if single_bounds is None else single_bounds[1], tris, distance, size)


def enclose_mesh(vertices, faces, max_capsules: int = 3, gain: float = 0.05, search: str = "fast") -> Enclosure:
    """Capsules (at most ``max_capsules``, 1 to 3) that together hold the solid bounded by the
    triangle mesh (``vertices`` (V, 3), ``faces`` (F, 3) indices), and their over-estimate with respect
    to the mesh (:func:`fit_mesh`, its over-estimate made precise)."""
    fit = fit_mesh(vertices, faces, max_capsules, gain, search)
    return Enclosure(fit.capsules, fit.over_estimate())
