"""Proofs that no joint path exists: start and goal in different free cells of the joint space.

The windows split the joints into independent groups: two joints are in one group when some window
involves both.  The free space (inside the limits, outside every window) is then the product of one
free set per group, so a joint path exists only if, in every group, the start's and the goal's
projections lie in one connected piece of that group's free set.

* A window that is an interval of one joint (a single-joint factor, e.g. the wrist window
  q5 ∈ [−m, m], or UR's elbow window q3 ∈ [180° − m, 180° + m] + 360°k) is a slab across the whole
  joint space — it separates every configuration on one side from every one on the other, whatever
  other windows share its joint.  Every such slab, of every group, is checked first, exactly; a
  group of one joint with only such windows is then fully decided.
* A group of two or three joints is covered by a grid of cells over its joint limits.  A cell is
  *blocked* only when interval arithmetic proves it lies wholly inside one window
  (:mod:`planning.certify.intervals`); the grid's edges along a joint are also split at the bounds
  of that joint's slabs, so that a slab narrower than a cell still blocks whole cells and joins the
  other windows in cutting the group; the unblocked cells, joined through faces, edges and corners
  (labelled by :func:`label_cells`), hold the whole free set.  If the start's and the goal's cells
  are in different components of the unblocked cells, no joint path exists — a proof, whatever the
  grid's resolution (a coarser grid only proves less).
* Larger groups, windows whose expression interval arithmetic does not support, and point-set
  windows (numeric components, :class:`planning.windows.PointSetWindow`; left out before the joints
  are grouped, so that they do not join the groups of the others) are left out — leaving a window
  out only enlarges the set searched, so every verdict stays sound.

Keep-out boxes and σ_min floors only shrink the free space further; they are not needed for a
verdict of impossibility, which is all this module gives ("no path" is proven; "maybe a path" is
left to the planner).
"""
from __future__ import annotations

import itertools
import weakref
from dataclasses import dataclass

import numpy as np

from kin.display import joint_interval, joint_value
from planning.certify.intervals import IntervalError, compile_interval
from planning.certify.segments import window_expression

__all__ = ["FreeCells", "Separation", "GRID_CELLS", "free_cells", "joint_groups", "label_cells"]

#: cells per axis of the grid for a group of 1, 2 or 3 joints
GRID_CELLS = {1: 4096, 2: 256, 3: 48}


@dataclass(frozen=True)
class Separation:
    """Why no joint path joins two configurations: ``joints`` (1-based) of the group that separates
    them, ``windows`` (names) of that group, ``kind`` (``"slab"``: exact, one joint; ``"cells"``:
    the proven-blocked cells of a 2- or 3-joint group), and ``reason``, one sentence (the robot
    file's units when the query gave the chain, else SI)."""

    joints: tuple[int, ...]
    windows: tuple[str, ...]
    kind: str
    reason: str


def joint_groups(windows) -> list[list[int]]:
    """The 0-based joints the windows depend on, grouped: two joints are in one group when some
    window involves both (union–find).  Joints in no window are in no group."""
    parent: dict[int, int] = {}

    def find(j: int) -> int:
        while parent[j] != j:
            parent[j] = parent[parent[j]]
            j = parent[j]
        return j
    for w in windows:
        js = [j - 1 for j in w.joints]
        for j in js:
            parent.setdefault(j, j)
        for j in js[1:]:
            parent[find(j)] = find(js[0])
    groups: dict[int, list[int]] = {}
    for j in sorted(parent):
        groups.setdefault(find(j), []).append(j)
    return sorted(groups.values())


def label_cells(free: np.ndarray) -> np.ndarray:
    """The connected components of the True cells of a boolean grid (any dimension), cells joined
    through faces, edges and corners → int array of the grid's shape: 0 for a False cell, else the
    component's number, 1, 2, … in the order of each component's first cell (C order) — the labels
    of ``scipy.ndimage.label`` with a full 3×…×3 structure, without importing scipy.

    Each line along the last axis is cut into runs of True cells (a run is connected); runs in
    neighbouring lines are joined by union–find, vectorised: roots are hooked to the smallest root
    they touch and paths compressed, until no pair is left (a few rounds).  Two runs touch exactly
    when a cell next to one run's first cell belongs to the other, so only those pairs are looked at.
    """
    free = np.asarray(free, dtype=bool)
    shape, d = free.shape, free.ndim
    idx = np.arange(free.size).reshape(shape)
    prev = np.zeros(shape, bool)
    prev[..., 1:] = free[..., :-1]
    start = free & ~prev
    run = np.maximum.accumulate(np.where(start, idx, -1), axis=-1)      # each True cell's run start
    us, vs = [np.zeros(0, int)], [np.zeros(0, int)]
    for o in itertools.product((-1, 0, 1), repeat=d):
        if o[:-1] <= (0,) * (d - 1):          # the other lines only, each pair of lines once
            continue
        a = tuple(slice(0, s - k) if k >= 0 else slice(-k, s) for k, s in zip(o, shape))
        b = tuple(slice(k, s) if k >= 0 else slice(0, s + k) for k, s in zip(o, shape))
        hit = free[a] & free[b] & (start[a] | start[b])
        us.append(run[a][hit])
        vs.append(run[b][hit])
    u, v = np.concatenate(us), np.concatenate(vs)
    parent = np.arange(free.size)
    while len(u):
        pu, pv = parent[u], parent[v]
        keep = pu != pv
        u, v, pu, pv = u[keep], v[keep], pu[keep], pv[keep]
        if not len(u):
            break
        np.minimum.at(parent, np.maximum(pu, pv), np.minimum(pu, pv))     # hook roots: parent ≤ index
        while True:
            up = parent[parent]
            if np.array_equal(up, parent):
                break
            parent = up
    root = parent[run[free]]
    out = np.zeros(shape, np.int32)
    out[free] = np.searchsorted(np.unique(root), root) + 1
    return out


def _fmt(v: float) -> str:
    return f"{v:.4g}"


def _value(chain, j: int, v: float) -> str:
    """Joint ``j``'s value in the chain's file units with the unit (SI, unit-less, without a chain)."""
    return _fmt(v) if chain is None else joint_value(chain, j, v, digits=4)


def _interval(chain, j: int, lo: float, hi: float) -> str:
    return f"[{_fmt(lo)}, {_fmt(hi)}]" if chain is None else joint_interval(chain, j, lo, hi, digits=4)


class FreeCells:
    """The free-cell structure of one robot's windows (computed once; queries are cheap).

    ``lower``, ``upper``: the joint limits (SI, (n,)); ``windows``: a WindowSet (or None).
    """

    def __init__(self, lower, upper, windows, grid_cells: dict[int, int] | None = None):
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)
        self.n = len(self.lower)
        # point-set windows (numeric components) are left out: leaving a window out only enlarges the free
        # set, so every verdict stays sound, and they no longer tie their joints to the other windows'
        # groups (the iiwa's elbow slab q4 ∈ [−m, m] shares q4 with two of them)
        self.windows = [] if windows is None else [w for w in windows.windows if not getattr(w, "is_point_set", False)]
        self.grid_cells = dict(GRID_CELLS if grid_cells is None else grid_cells)
        self.groups = [(tuple(js), [w for w in self.windows if (w.joints[0] - 1) in js])
                       for js in joint_groups(self.windows)]
        self._grids: dict[tuple[int, ...], tuple[np.ndarray, np.ndarray, np.ndarray, list[str]] | None] = {}

    # ---- one joint: exact ------------------------------------------------------------------------
    def _slab(self, j: int, ws, a: float, b: float, chain=None) -> Separation | None:
        blocked = sorted((lo, hi) for w in ws for lo, hi in w.intervals)
        lo_, hi_ = min(a, b), max(a, b)
        for lo, hi in blocked:
            if lo_ < lo and hi < hi_:          # a whole window interval lies between the two values
                w = next(w for w in ws if (lo, hi) in [tuple(iv) for iv in w.intervals])
                return Separation((j + 1,), (w.name,), "slab",
                                  f"the {w.kind} window q{j + 1} ∈ {_interval(chain, j, lo, hi)} separates start "
                                  f"(q{j + 1} = {_value(chain, j, a)}) and goal (q{j + 1} = {_value(chain, j, b)})")
        return None

    # ---- two or three joints: proven-blocked cells --------------------------------------------------
    def _grid(self, js: tuple[int, ...], ws):
        if js in self._grids:
            return self._grids[js]
        d = len(js)
        R = self.grid_cells.get(d)
        result = None
        if R:
            edges = [self._edges(j, ws, R) for j in js]
            idx = np.stack(np.meshgrid(*[np.arange(len(e) - 1) for e in edges], indexing="ij"), axis=-1).reshape(-1, d)
            lo = np.tile(self.lower, (len(idx), 1))
            hi = np.tile(self.upper, (len(idx), 1))
            for c, j in enumerate(js):
                lo[:, j] = edges[c][idx[:, c]]
                hi[:, j] = edges[c][idx[:, c] + 1]
            blocked = np.zeros(len(idx), bool)
            used = []
            for w in ws:
                if w.is_interval:
                    j = w.joint
                    for a, b in w.intervals:
                        blocked |= (lo[:, j] >= a) & (hi[:, j] <= b)
                    used.append(w.name)
                    continue
                try:
                    fn = compile_interval(window_expression(w))
                except IntervalError:
                    continue                    # left out: the verdict stays sound
                glo, ghi = fn(lo, hi)
                blocked |= (glo >= -w.epsilon) & (ghi <= w.epsilon)
                used.append(w.name)
            free = ~blocked.reshape(tuple(len(e) - 1 for e in edges))
            labels = label_cells(free)
            result = (labels, edges, free, used)
        self._grids[js] = result
        return result

    def _edges(self, j: int, ws, R: int) -> np.ndarray:
        """Cell edges along joint ``j``: R equal cells over its limits, split again at every bound of
        the single-joint interval windows on ``j`` (a slab then blocks whole cells exactly, however
        narrow it is beside the cells)."""
        lo, hi = self.lower[j], self.upper[j]
        cuts = [v for w in ws if w.is_interval and w.joint == j for iv in w.intervals for v in iv if lo < v < hi]
        e = np.unique(np.concatenate([np.linspace(lo, hi, R + 1), np.asarray(cuts, dtype=float)]))
        keep = np.concatenate([[True], np.diff(e) > 1e-12 * max(1.0, hi - lo)])
        return e[keep]

    def _cell(self, edges, q, js):
        return tuple(int(np.clip(np.searchsorted(edges[c], q[j], side="right") - 1, 0, len(edges[c]) - 2))
                     for c, j in enumerate(js))

    def separation(self, start, goal, chain=None) -> Separation | None:
        """Why no joint path joins ``start`` and ``goal`` (SI, (n,)), or None when no group proves it.
        Both are assumed valid (inside the limits and outside every window).  ``chain``: the robot's
        chain, to give the reason's joint values in its file's units (else SI)."""
        a = np.asarray(start, dtype=float)
        b = np.asarray(goal, dtype=float)
        # first, exactly: every single-joint interval window is a slab across the whole joint space,
        # whichever group it shares with other windows (leaving those out only enlarges the free set)
        for js, ws in self.groups:
            for j in js:
                slabs = [w for w in ws if w.is_interval and w.joint == j]
                sep = self._slab(j, slabs, float(a[j]), float(b[j]), chain) if slabs else None
                if sep is not None:
                    return sep
        for js, ws in self.groups:
            if len(js) == 1 and all(w.is_interval for w in ws):
                continue                       # decided exactly above
            grid = self._grid(js, ws)
            if grid is None:
                continue
            labels, edges, free, used = grid
            ca, cb = self._cell(edges, a, js), self._cell(edges, b, js)
            la, lb = labels[ca], labels[cb]
            if la == 0 or lb == 0 or la == lb:      # 0: a blocked cell (the point is not free)
                continue
            names = ", ".join(f"q{j + 1}" for j in js)
            return Separation(tuple(j + 1 for j in js), tuple(used), "cells",
                              f"the windows {', '.join(repr(u) for u in used)} cut joints ({names}) into "
                              f"separate free regions: start ({', '.join(_value(chain, j, a[j]) for j in js)}) and "
                              f"goal ({', '.join(_value(chain, j, b[j]) for j in js)}) lie in different ones")
        return None

    def same_cell(self, start, goal) -> bool:
        """False when a path between them is proven impossible (see :meth:`separation`)."""
        return self.separation(start, goal) is None


_CACHE: dict[tuple, tuple[weakref.ref, FreeCells]] = {}


def free_cells(lower, upper, windows) -> FreeCells:
    """:class:`FreeCells` of these limits and windows, built once per WindowSet object and reused
    (the grids are the expensive part; a query is a lookup)."""
    key = (id(windows), np.asarray(lower, dtype=float).tobytes(), np.asarray(upper, dtype=float).tobytes())
    hit = _CACHE.get(key)
    if hit is not None and windows is not None and hit[0]() is windows:
        return hit[1]
    cells = FreeCells(lower, upper, windows)
    if windows is not None:
        for k in [k for k, (ref, _) in _CACHE.items() if ref() is None]:
            del _CACHE[k]
        _CACHE[key] = (weakref.ref(windows), cells)
    return cells
