"""The signed clearance of a robot's capsules against a cell's obstacles and against each other:
:class:`ClearanceModel`, the compiled kernel ``clearance.c`` beside this module (its first comment
states the method) or, without a C compiler, the same method in numpy (:mod:`kin.geometry.clearance_numpy`).

Clearance is a *signed* distance (m): the gap between a capsule and an obstacle or another capsule,
negative when they overlap — minus the overlap depth: for a sphere or a capsule the radii minus the
distance of the centres' segments; for a box or a cylinder the deepest the capsule's segment reaches
into the solid (the least of the solid's signed distance function along it), plus the capsule's radius,
which is never deeper than the translation that would separate the two (what coal's EPA reports).
Every value the model reports is a **lower bound** of the true clearance and within 1e-7 m of it: it
never says "clear" where the truth is a collision, which is what the collision proofs of the planner
rely on.  Values above ``cap`` are reported as ``cap`` (bounds skip whatever cannot come below it, so
a generous cap costs time).

Obstacles: a sequence of :class:`~kin.geometry.shapes.Obstacle` (its primitives and its sphere set; its
``ignore`` bodies are never checked against it) or bare :class:`~kin.geometry.shapes.Shape` objects (one
obstacle each).  ``other`` in :class:`Contact` is the obstacle's index in that sequence, or −1 − j for
body j of the robot (a self pair); ``body`` is −1 (and ``other`` −1, the points NaN) when nothing
comes below ``cap``.  Sphere sets (meshes, point clouds; up to hundreds of thousands of spheres) go
into a bounding-volume hierarchy (balls and boxes) built here, once, in numpy (~1 s for 200 000).

The library is built on first use by :func:`kin.native.build` (once per process, cached on disk like
the other kernels); ``RMTKIT_CC=none`` — or a compiler that fails — gives the numpy fallback with a
warning.
"""
from __future__ import annotations

import ctypes
import math
import threading
import warnings
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np

from kin.chain import MAX_PRISMATIC
from kin.errors import ArgumentError, CompileError, ConfigurationError, GeometryError
from kin.geometry.frames import dh_rows
from kin.geometry.model import RobotGeometry
from kin.geometry.shapes import Obstacle, Shape
from kin.native import build, default_threads, find_compiler
from kin.validation import is_count, is_real, real_array, type_name

__all__ = ["ClearanceModel", "Contact", "CLEARANCE_SOURCE", "MARGIN", "TOL", "sphere_tree"]

#: the kernel's C source (see its first comment; the data layout is in clearance.h beside it)
CLEARANCE_SOURCE = Path(__file__).resolve().with_name("clearance.c")
#: m: how far the convex minimisations' lower bound may lie below the truth (TOL in clearance.c)
TOL = 1e-7
#: m added to every bounding ball's radius, so that rounding never lets a ball cut off its contents
MARGIN = 1e-9
#: spheres per leaf of a sphere set's hierarchy
LEAF = 8
#: batches smaller than this run on one thread
SMALL_BATCH = 2048
#: most bodies a model may have (the ignore sets are 63-bit masks)
MAX_BODIES = 63
#: primitive kinds as clearance.h numbers them
KIND_CODE = {"sphere": 0, "capsule": 1, "box": 2, "cylinder": 3}
SET_KIND = 4
PRIM_STRIDE = 32
PRIM_AABB = 24
CAP_STRIDE = 12
NODE_STRIDE = 10
MODE_MIN, MODE_NEAREST, MODE_PER_BODY = 0, 1, 2


class Contact(NamedTuple):
    """The nearest pair of each configuration (floats and (3,) arrays for one configuration, arrays for
    a batch): ``clearance`` (m, ≤ cap), ``body`` (−1: nothing below cap), ``other`` (obstacle index ≥ 0,
    or −1 − j for body j), ``point_robot`` and ``point_other`` (world, m: on the capsule's surface and
    on the other party's; |point_robot − point_other| = |clearance|; NaN where body is −1).  Where a
    capsule penetrates a box or a cylinder, ``point_robot`` is its segment's deepest point moved by the
    radius along the solid's normal (inside the capsule when the segment is not square to that normal),
    ``point_other`` the solid's surface point nearest that deepest point."""

    clearance: np.ndarray | float
    body: np.ndarray | int
    other: np.ndarray | int
    point_robot: np.ndarray
    point_other: np.ndarray


class _Model(ctypes.Structure):
    """``rmt_clear_model`` of clearance.h, field by field."""

    _fields_ = [(name, ctypes.c_longlong) for name in
                ("n", "modified", "nbody", "last", "ncap", "nprim", "npair", "nnode", "nsphere", "nprim4",
                 "nset")] + \
               [(name, ctypes.c_void_p) for name in
                ("dh", "base", "tool", "cap", "body_cap", "body_sphere", "prim_int", "prim", "prim_soa",
                 "prim_ignore", "pair", "node", "link", "sphere")]


# ---- validation ---------------------------------------------------------------------------------------
def _finite_array(x, shape_text: str, what: str) -> np.ndarray:
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as e:
        raise GeometryError(f"{what} is not an array of numbers ({e})") from None
    if not np.all(np.isfinite(a)):
        raise GeometryError(f"{what} holds a non-finite value; expected {shape_text} of finite numbers")
    return a


def _pose(T, what: str) -> np.ndarray:
    """A 4×4 rigid transform (rigidity defect ≤ 1e-6, as chain placements); the rotation is replaced by
    the nearest exact one, so that the shape is exactly what the pose says."""
    from kin.transforms import rigidity_defect
    T = _finite_array(T, "a 4×4 matrix", what)
    if T.shape != (4, 4):
        raise GeometryError(f"{what} has shape {T.shape}; expected (4, 4)")
    defect = rigidity_defect(T)
    if defect > 1e-6:
        raise GeometryError(f"{what} is not a rigid transform (defect {defect:.3g} > 1e-6: the rotation must be "
                            "orthonormal with determinant 1, the last row 0 0 0 1)")
    U, _, Vt = np.linalg.svd(T[:3, :3])
    out = np.eye(4)
    out[:3, :3] = U @ Vt
    out[:3, 3] = T[:3, 3]
    return out


def _columns(T: np.ndarray) -> np.ndarray:
    """A rigid transform as its columns x, y, z, origin (12,)."""
    return np.ascontiguousarray(np.concatenate([T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3]]))


def _threads_arg(threads) -> int | None:
    if threads is None:
        return None
    if not is_count(threads) or not 1 <= int(threads) <= 256:
        raise ArgumentError(f"threads must be None or an integer 1..256, got {type_name(threads)} {threads!r}")
    return int(threads)


# ---- sphere hierarchy ----------------------------------------------------------------------------------
def _segments(starts: np.ndarray, ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The element indices of ranges [starts, ends) concatenated, and each range's offset in them."""
    counts = ends - starts
    offsets = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    idx = np.repeat(starts - offsets, counts) + np.arange(int(counts.sum()))
    return idx, offsets


def sphere_tree(spheres, leaf: int = LEAF) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A balanced bounding-sphere hierarchy of spheres (K, 4), built level by level in numpy: each node's
    range is sorted along its widest axis and split at its middle.  Returns ``node`` (M, 10): a ball
    (centre, radius) and a box (centre, half sizes) per node, each holding every sphere below it (plus
    :data:`MARGIN`); ``link`` (M, 2): children (left, right), or (first sphere, −count) for a leaf; the
    spheres (K, 4) in leaf order; ``rep`` (M,): one sphere of each node (the one nearest its centre: an
    upper bound for the numpy walk).  Node 0 is the root; children come after their parents."""
    S = np.ascontiguousarray(spheres, dtype=float).reshape(-1, 4)
    K = len(S)
    perm = np.arange(K)
    levels = []                                      # per level: (starts, ends)
    starts, ends = np.array([0], np.int64), np.array([K], np.int64)
    while len(starts):
        levels.append((starts, ends))
        split = (ends - starts) > leaf
        s, e = starts[split], ends[split]
        if not len(s):
            break
        idx, off = _segments(s, e)
        C = S[perm[idx], :3]
        lo = np.minimum.reduceat(C, off, axis=0)
        hi = np.maximum.reduceat(C, off, axis=0)
        axis = np.argmax(hi - lo, axis=1)
        seg = np.repeat(np.arange(len(s)), e - s)
        key = C[np.arange(len(idx)), axis[seg]]
        order = np.lexsort((key, seg))
        perm[idx] = perm[idx[order]]
        mid = (s + e) // 2
        starts = np.stack([s, mid], axis=1).ravel()
        ends = np.stack([mid, e], axis=1).ravel()
    S = S[perm]
    # node numbers: level by level; the children of a level's j-th split node are the next level's 2j, 2j + 1
    sizes = [len(st) for st, _ in levels]
    first = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    M = int(first[-1])
    node = np.empty((M, NODE_STRIDE))
    link = np.empty((M, 2), np.int64)
    rep = np.empty(M, np.int64)
    for L, (st, en) in enumerate(levels):
        ids = first[L] + np.arange(len(st))
        idx, off = _segments(st, en)
        C, R = S[idx, :3], S[idx, 3]
        lo = np.minimum.reduceat(C - R[:, None], off, axis=0)
        hi = np.maximum.reduceat(C + R[:, None], off, axis=0)
        centre = 0.5 * (lo + hi)
        counts = en - st
        gap = np.linalg.norm(C - np.repeat(centre, counts, axis=0), axis=1)
        node[ids, :3] = centre
        node[ids, 3] = np.maximum.reduceat(gap + R, off) * (1 + 1e-12) + MARGIN
        node[ids, 4:7], node[ids, 7:10] = centre, 0.5 * (hi - lo) + MARGIN
        # the sphere nearest the centre: the first where the gap is its range's minimum
        gmin = np.repeat(np.minimum.reduceat(gap, off), counts)
        at = np.flatnonzero(gap == gmin)
        seg_of = np.repeat(np.arange(len(st)), counts)[at]
        keep = np.concatenate([[True], seg_of[1:] != seg_of[:-1]])
        rep[ids[seg_of[keep]]] = idx[at[keep]]
        is_split = counts > leaf
        link[ids[~is_split], 0] = st[~is_split]
        link[ids[~is_split], 1] = -counts[~is_split]
        if is_split.any():
            j = np.arange(int(is_split.sum()))
            link[ids[is_split], 0] = first[L + 1] + 2 * j
            link[ids[is_split], 1] = first[L + 1] + 2 * j + 1
    return node, link, S, rep


def _aabb(sh: Shape) -> np.ndarray:
    """A world-axis-aligned box holding shape ``sh``: centre (3), half sizes (3, plus :data:`MARGIN`)."""
    T, (r, h, z) = sh.pose, sh.size
    R, c = T[:3, :3], T[:3, 3]
    if sh.kind == "sphere":
        half = np.full(3, r)
    elif sh.kind == "capsule":
        half = np.abs(R[:, 2]) * h + r
    elif sh.kind == "box":
        half = np.abs(R) @ np.array([r, h, z])
    else:   # cylinder: the disc of radius r about axis u reaches r·√(1 − u_i²) along axis i
        u = R[:, 2]
        half = np.abs(u) * h + r * np.sqrt(np.maximum(0.0, 1.0 - u * u))
    return np.concatenate([c, half * (1 + 1e-12) + MARGIN])


# ---- the flat model ------------------------------------------------------------------------------------
class _Flat:
    """The arrays of clearance.h for one chain, geometry and cell (both back ends read them)."""

    def __init__(self, chain, geometry: RobotGeometry, obstacles: list[Obstacle], base: np.ndarray,
                 pairs: list[tuple[int, int]]):
        n = chain.n
        B = n + 2
        self.n, self.nbody = n, B
        self.modified = chain.convention == "modified"
        rows = dh_rows(chain)
        dh = np.zeros((n, 8))
        dh[:, 0], dh[:, 1], dh[:, 2], dh[:, 3], dh[:, 4], dh[:, 5] = (
            rows[:, 0], np.cos(rows[:, 1]), np.sin(rows[:, 1]), rows[:, 2], rows[:, 3], rows[:, 4])
        dh[:, 6] = np.where(rows[:, 4] != 0, MAX_PRISMATIC, np.finfo(float).max)    # (refuses inf too)
        self.dh = dh
        self.world_base = base
        self.base = _columns(base @ chain.base.matrix)
        self.tool = _columns(np.asarray(chain.tool.matrix, dtype=float))
        caps = sorted(range(len(geometry.capsules)), key=lambda i: geometry.capsules[i].body)
        self.capsule_index = np.array(caps, np.int64)        # kernel order → geometry.capsules
        cap = np.zeros((len(caps), CAP_STRIDE))
        body = np.zeros(len(caps), np.int64)
        for k, i in enumerate(caps):
            c = geometry.capsules[i]
            d = np.subtract(c.b, c.a)
            dd = float(d @ d)
            cap[k, :3], cap[k, 3:6], cap[k, 6], cap[k, 7] = c.a, c.b, c.radius, dd
            cap[k, 8] = 1.0 / dd if dd > 0 else 0.0
            cap[k, 9] = 0.5 * math.sqrt(dd) + c.radius + 1e-12
            body[k] = c.body
        self.cap, self.cap_body = np.ascontiguousarray(cap), body
        self.body_cap = np.searchsorted(body, np.arange(B + 1)).astype(np.int64)
        bs = np.zeros((B, 4))
        for b in range(B):
            c0, c1 = self.body_cap[b], self.body_cap[b + 1]
            if c0 == c1:
                continue
            P = np.vstack([cap[c0:c1, :3], cap[c0:c1, 3:6]])
            centre = 0.5 * (P.min(axis=0) + P.max(axis=0))
            r = np.concatenate([cap[c0:c1, 6], cap[c0:c1, 6]])
            bs[b, :3] = centre
            bs[b, 3] = float((np.linalg.norm(P - centre, axis=1) + r).max()) * (1 + 1e-12) + MARGIN
        self.body_sphere = bs
        held = np.flatnonzero(np.diff(self.body_cap) > 0)
        self.last = int(held.max()) if len(held) else 0
        self.pair = np.array(pairs, np.int64).reshape(-1, 2)
        # obstacles: primitives, then one primitive per sphere set
        prim_int, prim = [], []
        nodes, links, spheres, reps = [], [], [], []
        n_nodes = n_spheres = 0
        self.obstacle_names = [o.name for o in obstacles]
        for oi, ob in enumerate(obstacles):
            mask = 0
            for b in ob.ignore:
                mask |= 1 << b
            for sh in ob.shapes:
                row = np.zeros(PRIM_STRIDE)
                T = sh.pose
                size = sh.size
                kind = KIND_CODE[sh.kind]
                row[:3] = T[:3, 3]
                row[3] = sh.bounding_radius * (1 + 1e-12) + MARGIN
                if sh.kind == "sphere":
                    row[4:7], row[10] = T[:3, 3], size[0]
                elif sh.kind == "capsule":
                    row[4:7] = T[:3, 3] - size[1] * T[:3, 2]
                    row[7:10] = T[:3, 3] + size[1] * T[:3, 2]
                    row[10] = size[0]
                else:
                    row[4:7] = size
                    row[12:24] = _columns(T)
                row[PRIM_AABB:PRIM_AABB + 6] = _aabb(sh)
                prim_int.append((kind, oi, 0, mask))
                prim.append(row)
            if ob.spheres is not None and len(ob.spheres):
                node, link, S, rep = sphere_tree(ob.spheres)
                link = link.copy()
                internal = link[:, 1] >= 0
                link[internal] += n_nodes
                link[~internal, 0] += n_spheres
                row = np.zeros(PRIM_STRIDE)
                row[:4] = node[0, :4]
                lo, hi = (S[:, :3] - S[:, 3:]).min(axis=0), (S[:, :3] + S[:, 3:]).max(axis=0)
                row[PRIM_AABB:PRIM_AABB + 3] = 0.5 * (lo + hi)
                row[PRIM_AABB + 3:PRIM_AABB + 6] = 0.5 * (hi - lo) + MARGIN
                prim_int.append((SET_KIND, oi, n_nodes, mask))
                prim.append(row)
                nodes.append(node)
                links.append(link)
                spheres.append(S)
                reps.append(rep + n_spheres)
                n_nodes += len(node)
                n_spheres += len(S)
        self.prim_int = np.array(prim_int, np.int64).reshape(-1, 4)
        self.prim = np.array(prim, float).reshape(-1, PRIM_STRIDE)
        P = len(self.prim)
        self.nprim4 = -(-P // 4) * 4
        self.prim_soa = np.zeros((10, self.nprim4))
        self.prim_soa[:4, :P] = self.prim[:, :4].T
        self.prim_soa[4:, :P] = self.prim[:, PRIM_AABB:PRIM_AABB + 6].T
        self.prim_ignore = np.full(self.nprim4, -1, np.int64)
        self.prim_ignore[:P] = self.prim_int[:, 3]
        self.node = np.concatenate(nodes) if nodes else np.zeros((0, NODE_STRIDE))
        self.link = np.concatenate(links) if links else np.zeros((0, 2), np.int64)
        self.sphere = np.concatenate(spheres) if spheres else np.zeros((0, 4))
        self.rep = np.concatenate(reps) if reps else np.zeros(0, np.int64)

    def struct(self) -> _Model:
        arrays = {k: np.ascontiguousarray(getattr(self, k)) for k in
                  ("dh", "base", "tool", "cap", "body_cap", "body_sphere", "prim_int", "prim", "prim_soa",
                   "prim_ignore", "pair", "node", "link", "sphere")}
        # C never reads an empty array, but every pointer should point somewhere
        arrays = {k: (a if a.size else np.zeros(1, a.dtype)) for k, a in arrays.items()}
        self._keep = arrays
        m = _Model(self.n, int(self.modified), self.nbody, self.last, len(self.cap), len(self.prim), len(self.pair),
                   len(self.node), len(self.sphere), self.nprim4, int((self.prim_int[:, 0] == SET_KIND).sum()))
        for k, a in arrays.items():
            setattr(m, k, a.ctypes.data)
        return m


# ---- the library ---------------------------------------------------------------------------------------
_lock = threading.Lock()
_loaded: dict[str, object] = {}


def _load():
    """(rmt_clearance, rmt_clear_one, rmt_prove_motion) of the built library, or None without a working compiler (a
    warning, once per compiler)."""
    compiler = find_compiler()
    if compiler is None:
        with _lock:
            if "none" not in _loaded:
                _loaded["none"] = None
                warnings.warn("rmtkit: no C compiler (RMTKIT_CC=none or none found): the clearance kernel runs "
                              "in numpy, far slower", RuntimeWarning, stacklevel=3)
        return None
    with _lock:
        if compiler in _loaded:
            return _loaded[compiler]
        try:
            lib = build("geometry_clearance", CLEARANCE_SOURCE, compiler=compiler, what="the clearance kernel")
            batch = ctypes.CDLL(str(lib.path)).rmt_clearance      # CDLL: the batch call releases the GIL
            one = ctypes.PyDLL(str(lib.path)).rmt_clear_one       # PyDLL: cheaper for one configuration
            prove = ctypes.PyDLL(str(lib.path)).rmt_prove_motion
        except (CompileError, OSError) as e:
            warnings.warn(f"rmtkit: compiling the clearance kernel failed, using numpy instead ({e})",
                          RuntimeWarning, stacklevel=3)
            _loaded[compiler] = None
            return None
        p, ll = ctypes.c_void_p, ctypes.c_longlong
        batch.argtypes = [p, p, ll, ctypes.c_int, ctypes.c_double, ctypes.c_int] + [p] * 7
        batch.restype = ctypes.c_int
        one.argtypes = [p, p, ctypes.c_double]
        one.restype = ctypes.c_double
        prove.argtypes = [p, p, p, ctypes.c_double, p, p, ctypes.c_double, ctypes.c_int, ll, p]
        prove.restype = ctypes.c_int
        _loaded[compiler] = (batch, one, prove)
        return _loaded[compiler]


# ---- the model ------------------------------------------------------------------------------------------
class ClearanceModel:
    """The clearance of ``chain``'s capsules (``geometry``; None: the chain's own or the default along
    its DH offsets) placed at ``base`` (4×4, where the cell puts the robot; default identity) against
    ``obstacles`` (:class:`~kin.geometry.shapes.Obstacle` or :class:`~kin.geometry.shapes.Shape`
    objects, world coordinates) and, for ``self_pairs`` (body pairs (i, j); None:
    ``geometry.checked_pairs(n)``, () none), against each other.  ``cap`` (m, > 0 or inf): values above
    it are reported as ``cap``.  ``threads``: threads of a large batch (default ``RMTKIT_THREADS`` or
    the CPUs this process may use; batches under 2048 configurations run on one).  ``chain`` may be a
    :class:`kin.Robot` (its chain and geometry are used).
    """

    def __init__(self, chain, geometry: RobotGeometry | None = None, obstacles: Iterable = (),
                 base=None, self_pairs=None, cap: float = 1.0, threads: int | None = None):
        if hasattr(chain, "chain") and hasattr(chain, "geometry"):      # a Robot
            if geometry is None:
                geometry = chain.geometry
            chain = chain.chain
        if not (hasattr(chain, "n") and hasattr(chain, "dh_table") and hasattr(chain, "as_batch")):
            raise ArgumentError(f"chain must be a kin.Chain or a kin.Robot, got {type_name(chain)}")
        self.chain = chain
        n = chain.n
        B = n + 2
        if B > MAX_BODIES:
            raise GeometryError(f"{chain.name} has {n} joints; the clearance kernel handles at most "
                                f"{MAX_BODIES - 2} (bodies 0 … n + 1 in a 63-bit mask)")
        if geometry is None:
            from kin.geometry.default import default_geometry
            geometry = chain.geometry if getattr(chain, "geometry", None) is not None else default_geometry(chain)
        if not isinstance(geometry, RobotGeometry):
            raise ArgumentError(f"geometry must be a kin.geometry.RobotGeometry or None, got {type_name(geometry)}")
        self.geometry = geometry
        for i, c in enumerate(geometry.capsules):
            what = f"capsule {i} ({c.name or 'unnamed'})"
            if not is_count(c.body) or not 0 <= c.body < B:
                raise GeometryError(f"{what} is on body {c.body!r}; {chain.name} has bodies 0 … {B - 1}")
            if not all(math.isfinite(v) for v in (*c.a, *c.b)):
                raise GeometryError(f"{what} has a non-finite end point: a = {c.a}, b = {c.b}")
            if not (math.isfinite(c.radius) and c.radius >= 0):
                raise GeometryError(f"{what} has radius {c.radius!r}; expected a finite number ≥ 0 (m)")
        if not (is_real(cap) and (math.isfinite(cap) or cap == math.inf) and cap > 0):
            raise ArgumentError(f"cap must be a number > 0 (m) or inf, got {type_name(cap)} {cap!r}")
        self.cap = float(cap)
        self.threads = _threads_arg(threads)
        self.base = np.eye(4) if base is None else _pose(base, "base")
        self.obstacles = self._obstacles(obstacles, B)
        self.self_pairs = self._pairs(self_pairs, geometry, n)
        self._flat = _Flat(chain, geometry, self.obstacles, self.base, self.self_pairs)
        self._numpy_model = None
        #: threads the last compiled batch ran on
        self.last_threads = 0
        fns = _load()
        if fns is None:
            self.backend = "numpy"
            self._batch = self._one = self._prove = None
        else:
            self.backend = "compiled"
            self._batch, self._one, self._prove = fns
            self._struct = self._flat.struct()
            self._mp = ctypes.addressof(self._struct)
            self._q1 = (ctypes.c_double * n)()
            self._q1p = ctypes.addressof(self._q1)
            self.clear_one = self._fast_one()

    def __repr__(self) -> str:
        return (f"ClearanceModel({self.chain.name!r}, {len(self.geometry.capsules)} capsules, {len(self.obstacles)} "
                f"obstacles, {len(self.self_pairs)} body pairs, cap={self.cap:g}, {self.backend})")

    @staticmethod
    def _obstacles(obstacles, B: int) -> tuple[Obstacle, ...]:
        if isinstance(obstacles, (Obstacle, Shape)):
            obstacles = [obstacles]
        try:
            items = list(obstacles)
        except TypeError:
            raise ArgumentError(f"obstacles must be a sequence of kin.geometry Obstacle or Shape objects, got "
                                f"{type_name(obstacles)}") from None
        out = []
        for i, ob in enumerate(items):
            if isinstance(ob, Shape):
                ob = Obstacle(f"obstacle {i}", (ob,))
            if not isinstance(ob, Obstacle):
                raise ArgumentError(f"obstacles[{i}] must be a kin.geometry Obstacle or Shape, got {type_name(ob)}")
            what = f"obstacle {i} ({ob.name})"
            bad = sorted(b for b in ob.ignore if not 0 <= b < B)
            if bad:
                raise GeometryError(f"{what} ignores body {bad[0]}; the robot has bodies 0 … {B - 1}")
            shapes = []
            for k, sh in enumerate(ob.shapes):
                if not isinstance(sh, Shape):
                    raise ArgumentError(f"{what}: shape {k} must be a kin.geometry Shape, got {type_name(sh)}")
                size = sh.size
                if not all(math.isfinite(v) and v >= 0 for v in size):
                    raise GeometryError(f"{what}: {sh.kind} {k} has size {size}; expected finite numbers ≥ 0 (m)")
                shapes.append(Shape(sh.kind, size, _pose(sh.pose, f"{what}: the pose of {sh.kind} {k}")))
            spheres = ob.spheres
            if spheres is not None:
                S = _finite_array(spheres, "(K, 4) x, y, z, radius", f"{what}: spheres")
                if S.ndim != 2 or S.shape[1] != 4:
                    raise GeometryError(f"{what}: spheres have shape {np.shape(spheres)}; expected (K, 4) "
                                        "x, y, z, radius")
                if (S[:, 3] < 0).any():
                    k = int(np.argmax(S[:, 3] < 0))
                    raise GeometryError(f"{what}: sphere {k} has radius {S[k, 3]!r}; expected ≥ 0 (m)")
                spheres = S
            out.append(Obstacle(ob.name, tuple(shapes), spheres, ob.ignore, ob.over_estimate, ob.kind))
        return tuple(out)

    @staticmethod
    def _pairs(self_pairs, geometry: RobotGeometry, n: int) -> tuple[tuple[int, int], ...]:
        if self_pairs is None:
            return tuple(geometry.checked_pairs(n))
        held = set(geometry.bodies())
        out = set()
        try:
            items = list(self_pairs)
        except TypeError:
            raise ArgumentError(f"self_pairs must be None or a sequence of body pairs (i, j), got "
                                f"{type_name(self_pairs)}") from None
        for p in items:
            try:
                i, j = p
            except (TypeError, ValueError):
                raise ArgumentError(f"self_pairs: {p!r} is not a body pair (i, j)") from None
            if not (is_count(i) and is_count(j) and 0 <= i < n + 2 and 0 <= j < n + 2 and i != j):
                raise GeometryError(f"self_pairs: {p!r} must be two different bodies in 0 … {n + 1}")
            if i in held and j in held:      # a body without capsules touches nothing
                out.add((min(int(i), int(j)), max(int(i), int(j))))
        return tuple(sorted(out))

    # ---- calls ------------------------------------------------------------------------------------------
    def _Q(self, Q) -> tuple[np.ndarray, bool]:
        """Q as a validated batch (``chain.as_batch``) of real numbers (:func:`kin.validation.real_array`)."""
        return self.chain.as_batch(real_array(Q, "q", ConfigurationError))

    def _threads(self, N: int, threads) -> int:
        threads = _threads_arg(threads)
        if threads is not None:
            return threads
        if N < SMALL_BATCH:
            return 1
        return self.threads if self.threads is not None else default_threads()

    def _numpy(self):
        if self._numpy_model is None:
            from kin.geometry.clearance_numpy import NumpyClearance
            self._numpy_model = NumpyClearance(self.chain, self._flat)
        return self._numpy_model

    def _run(self, Q: np.ndarray, mode: int, threads) -> dict[str, np.ndarray]:
        N = len(Q)
        if self._batch is None:
            return self._numpy().evaluate(Q, mode, self.cap)
        B = self._flat.nbody
        out: dict[str, np.ndarray] = {}
        if mode == MODE_PER_BODY:
            out["obstacle"], out["self"] = np.empty((N, B)), np.empty((N, B))
        else:
            out["clearance"] = np.empty(N)
        if mode == MODE_NEAREST:
            out["body"], out["other"] = np.empty(N, np.int64), np.empty(N, np.int64)
            out["point_robot"], out["point_other"] = np.empty((N, 3)), np.empty((N, 3))
        if N == 0:
            return out
        ptr = lambda k: out[k].ctypes.data if k in out else None
        ran = self._batch(self._mp, Q.ctypes.data, N, mode, self.cap, self._threads(N, threads), ptr("clearance"),
                          ptr("body"), ptr("other"), ptr("point_robot"), ptr("point_other"), ptr("obstacle"),
                          ptr("self"))
        if ran < 0:
            raise MemoryError("the clearance kernel could not allocate its scratch space")
        self.last_threads = ran
        return out

    def move_base(self, base) -> None:
        """Place the robot at ``base`` (4×4, world frame) without rebuilding the model: the obstacles
        stay where they are.  A reach or placement study evaluates many placements with one model."""
        T = _pose(base, "base")
        self.base = T
        self._flat.world_base = T
        self._flat.base[:] = _columns(T @ self.chain.base.matrix)
        if self._batch is not None:          # the C struct points at _flat.base; refresh the pointers anyway
            self._struct = self._flat.struct()
            self._mp = ctypes.addressof(self._struct)
            self.clear_one = self._fast_one()

    def clearance(self, Q, threads: int | None = None) -> np.ndarray | float:
        """The minimum clearance (m, ≤ cap) of each configuration: (N,) for Q (N, n), a float for (n,)."""
        Q, single = self._Q(Q)
        d = self._run(Q, MODE_MIN, threads)["clearance"]
        return float(d[0]) if single else d

    def nearest(self, Q, threads: int | None = None) -> Contact:
        """The nearest pair of each configuration (:class:`Contact`)."""
        Q, single = self._Q(Q)
        r = self._run(Q, MODE_NEAREST, threads)
        if single:
            return Contact(float(r["clearance"][0]), int(r["body"][0]), int(r["other"][0]), r["point_robot"][0],
                           r["point_other"][0])
        return Contact(r["clearance"], r["body"], r["other"], r["point_robot"], r["point_other"])

    def per_body(self, Q, threads: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Per configuration and body (0 … n + 1): the minimum clearance against obstacles and, apart,
        against other bodies (a self pair counts for both), each capped: two (N, n + 2) arrays ((n + 2,)
        for one configuration).  Bodies without capsules, or checked against nothing, get ``cap``."""
        Q, single = self._Q(Q)
        r = self._run(Q, MODE_PER_BODY, threads)
        if single:
            return r["obstacle"][0], r["self"][0]
        return r["obstacle"], r["self"]

    def clear_one(self, q: Sequence[float]) -> float:
        """The minimum clearance (m, ≤ cap) of one configuration: n floats (a list, as OMPL's validity
        checker passes it, or an array).  With the compiled kernel this is a closure over preallocated
        buffers (about 1–2 µs a call); without it, the numpy batch path."""
        Q, _ = self._Q(q)
        if Q.shape[0] != 1:
            raise ConfigurationError(f"clear_one takes one configuration ({self.chain.n},), got shape {Q.shape}")
        return float(self._run(Q, MODE_MIN, 1)["clearance"][0])

    def prove_motion(self, a, b, d_obs, d_self, margin: float, max_depth: int, max_evals: int
                     ) -> tuple[int, float] | None:
        """The collision proof of :mod:`planning.certify.collision` for one straight motion ``a`` → ``b``
        (n each, SI) in C, stopping at the first answer: ``(1, nan)`` proven clear, ``(0, t)`` a state
        with clearance ≤ ``margin`` at parameter t, ``(-1, nan)`` not settled within ``max_depth``
        halvings and ``max_evals`` states.  ``d_obs``, ``d_self`` (n + 2,): how far each body's points
        can move over the whole motion (m), against obstacles and against other bodies.  None without
        the compiled kernel, or for a configuration the C refuses (the caller then takes the batch path)."""
        if self._prove is None:
            return None
        n, B = self.chain.n, self.chain.n + 2
        A = np.ascontiguousarray(a, dtype=float)
        Bq = np.ascontiguousarray(b, dtype=float)
        do = np.ascontiguousarray(d_obs, dtype=float)
        ds = np.ascontiguousarray(d_self, dtype=float)
        if A.shape != (n,) or Bq.shape != (n,) or do.shape != (B,) or ds.shape != (B,):
            raise ArgumentError(f"prove_motion: a, b must be ({n},) and the bounds ({B},)")
        t = ctypes.c_double(math.nan)
        r = self._prove(self._mp, A.ctypes.data, Bq.ctypes.data, self.cap, do.ctypes.data, ds.ctypes.data,
                        float(margin), int(max_depth), int(max_evals), ctypes.addressof(t))
        return None if r == -2 else (int(r), float(t.value))

    def _fast_one(self):
        """:meth:`clear_one` through the kernel's single-configuration entry: q goes into a ctypes buffer
        (a lock keeps threads from sharing it), the C checks it (NaN back when it is not finite or a
        prismatic value is out of bounds), and anything it refuses takes the validating path."""
        one, mp, qp, buf, cap, lock = self._one, self._mp, self._q1p, self._q1, self.cap, threading.Lock()
        slow = self._slow_one = ClearanceModel.clear_one.__get__(self)

        def clear_one(q: Sequence[float]) -> float:
            with lock:
                try:
                    buf[:] = q
                except (TypeError, ValueError):
                    v = math.nan
                else:
                    v = one(mp, qp, cap)
            return v if v == v else slow(q)

        clear_one.__doc__ = ClearanceModel.clear_one.__doc__
        return clear_one
