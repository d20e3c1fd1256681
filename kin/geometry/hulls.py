"""Clearances made tighter by convex hulls where the capsules come too close.

A robot's capsules hold its real shape but stand out of it (a flat joint housing inside a round
capsule: up to a few centimetres).  A robot file may give, besides, the convex hulls of its maker's
collision meshes (:class:`kin.geometry.LinkHull`, ``[[geometry.hull]]``).  The robot lies inside both,
so for a body and an obstacle (or another body) the larger of the two distances — capsules', hulls' —
is a lower bound of the real one, and so is anything built on it: a state clear by it is clear, and
the proofs of :mod:`planning.certify.collision` stay proofs (they bound how far the *robot's* points
move, which lie inside the capsules, so the capsules' motion bound still holds).

:class:`HullRefiner` takes the per-body clearances of the capsules (what
:meth:`kin.geometry.ClearanceModel.per_body` gives) and raises every entry at most ``margin + band``
to that larger value: per body against each obstacle it may touch, and per checked self pair, the
certified GJK distance (:func:`kin.geometry.convex.convex_distance`) between the body's hulls — its
capsules where it has none — and the obstacle's primitive (a box, sphere, capsule or cylinder; an
obstacle made of spheres, a mesh or point cloud, is left at the capsules' value) or the other body's
hulls.  An entry is replaced by min over its obstacles (pairs) of that distance only when larger and
positive (GJK measures no depth: where the hulls may touch, the capsules' depth is kept): capsule
entries are never lowered.
"""
from __future__ import annotations

import math

import numpy as np

from kin.geometry.convex import Solid, box_solid, c_distance, convex_distance_numpy, cylinder_solid, points_solid
from kin.geometry.frames import body_frames

__all__ = ["HullRefiner", "BAND"]

#: entries up to this far above the margin are refined (m): beyond, the capsules' value serves
BAND = 0.01


def _obstacle_solids(ob) -> list | None:
    """The convex solids of an obstacle, world frame (None: made of spheres, not refined)."""
    if ob.spheres is not None and len(ob.spheres):
        return None
    out = []
    for sh in ob.shapes:
        P = sh.pose
        if sh.kind == "box":
            out.append(box_solid(sh.size, P))
        elif sh.kind == "sphere":
            out.append(points_solid(np.zeros((1, 3)), sh.size[0], P))
        elif sh.kind == "capsule":
            out.append(points_solid(np.array([[0, 0, -sh.size[1]], [0, 0, sh.size[1]]]), sh.size[0], P))
        else:
            out.append(cylinder_solid(sh.size[0], sh.size[1], P))
    return out


class HullRefiner:
    """Refines per-body clearances of ``geometry`` (a :class:`kin.geometry.RobotGeometry` with hulls)
    against ``obstacles`` (world frame; their ``ignore`` sets respected) and the body pairs
    ``self_pairs``, for ``chain`` placed at ``base``."""

    def __init__(self, chain, geometry, obstacles, base, self_pairs):
        self.chain = chain
        self.base = np.eye(4) if base is None else np.asarray(base, dtype=float)
        n = chain.n
        self.B = n + 2
        self.hull_bodies = sorted({h.body for h in geometry.hulls})
        # per body: its hulls, or its capsules where it has none — as solids in the body's frame
        self.parts: dict[int, list[Solid]] = {}
        for b in range(n + 2):
            hs = [Solid(h.array, None, h.radius) for h in geometry.hulls if h.body == b]
            cs = [Solid(np.array([c.a, c.b]), None, c.radius) for c in geometry.capsules if c.body == b]
            self.parts[b] = hs or cs
        self.obstacles = [(ob, _obstacle_solids(ob)) for ob in obstacles]
        # every checked pair of a body that has hulls or is paired with one (an entry is the least over
        # all the body's pairs, so all of them are measured again)
        self.pairs: dict[int, list[int]] = {b: [] for b in range(n + 2)}
        touched = {b for p in self_pairs for b in p if set(p) & set(self.hull_bodies)}
        for i, j in self_pairs:
            if i in touched:
                self.pairs[i].append(j)
            if j in touched:
                self.pairs[j].append(i)
        self._fn = c_distance()

    def __bool__(self) -> bool:
        return bool(self.hull_bodies)

    def _distance(self, A: list, FA, pa, B: list, FB, pb, best: float) -> float:
        """The least bound between solids ``A`` (placed by the 4×4 ``FA`` at address ``pa``, or None: their
        own poses) and ``B`` (likewise), or ``best`` when none can be nearer (balls around them first)."""
        fn = self._fn
        for a in A:
            ca = a.placed_centre if FA is None else FA[:3, :3] @ a.centre + FA[:3, 3]
            for b in B:
                cb = b.placed_centre if FB is None else FB[:3, :3] @ b.centre + FB[:3, 3]
                if math.dist(ca, cb) - a.reach - b.reach >= best:
                    continue                     # their balls are farther apart than the best so far
                if fn is not None:
                    d = fn(a.ptr, len(a.points), a.pose_ptr if FA is None else pa, a.radius,
                           b.ptr, len(b.points), b.pose_ptr if FB is None else pb, b.radius)
                else:
                    d = convex_distance_numpy(Solid(a.points, a.pose if FA is None else FA, a.radius),
                                              Solid(b.points, b.pose if FB is None else FB, b.radius))
                if d < best:
                    best = d
        return best

    def refine(self, Q: np.ndarray, obs: np.ndarray, slf: np.ndarray, margin: float, cap: float,
               band: float = BAND) -> tuple[np.ndarray, np.ndarray]:
        """Per-body clearances (N, n + 2) ``obs`` and ``slf`` of configurations ``Q`` (N, n), SI, with
        every entry ≤ ``margin + band`` of a body with hulls (or paired with one) raised to the
        hulls' value where that is larger (copies; at most ``cap``)."""
        if not self:
            return obs, slf
        obs, slf = np.array(obs, dtype=float), np.array(slf, dtype=float)
        single = obs.ndim == 1
        Q, Ob, S = np.atleast_2d(Q), np.atleast_2d(obs), np.atleast_2d(slf)
        lim = margin + band
        rows = np.flatnonzero((Ob[:, self.hull_bodies] <= lim).any(axis=1) | (S <= lim).any(axis=1))
        if not len(rows):
            return (Ob[0], S[0]) if single else (Ob, S)
        frames = np.ascontiguousarray(body_frames(self.chain, Q[rows], base=self.base))     # (R, B, 4, 4)
        at = frames.ctypes.data
        for k, i in enumerate(rows):
            F = frames[k]

            def ptr(b):
                return at + (k * self.B + b) * 128          # F[b]'s address: 16 doubles a frame
            for b in self.hull_bodies:
                if Ob[i, b] > lim:
                    continue
                best = np.inf
                for ob, sol in self.obstacles:
                    if b in ob.ignore:
                        continue
                    if sol is None:
                        best = -np.inf
                        break
                    best = self._distance(self.parts[b], F[b], ptr(b), sol, None, None, best)
                    if best <= Ob[i, b]:
                        break
                if best > max(Ob[i, b], 0.0):
                    Ob[i, b] = min(best, cap)
            done: dict[tuple[int, int], float] = {}
            for b in range(S.shape[1]):
                if S[i, b] > lim or not self.pairs[b]:
                    continue
                best = np.inf
                for j in self.pairs[b]:
                    key = (min(b, j), max(b, j))
                    if key not in done:
                        done[key] = self._distance(self.parts[b], F[b], ptr(b), self.parts[j], F[j], ptr(j), np.inf)
                    best = min(best, done[key])
                    if best <= S[i, b]:
                        break
                if best > max(S[i, b], 0.0):
                    S[i, b] = min(best, cap)
        return (Ob[0], S[0]) if single else (Ob, S)
