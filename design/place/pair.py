"""Two robots sharing one cell and one task: where each stands, which targets each takes, and that
they do not hit each other at their assigned targets.

1. A first share: each target to the robot whose region centre is nearer (without regions, the two
   halves of the targets along their longest horizontal spread).  Robot A is placed for its share
   (:func:`design.place.place`, its region), then robot B for its own, its base kept out of a square
   around A's base (both robots' :func:`footprint` plus the clearance).
2. Both get the full reach study of every target at their placements; each target goes to the
   robot that reaches it with the higher score.
3. Robot–robot check: every configuration of A at its targets against every configuration of B at
   its own (both working at once), capsule against capsule (:func:`robot_robot_clearance`).  A
   target whose configuration comes closer than ``clearance`` to any of the other robot's is moved
   to the other robot when that one reaches it (the target with most conflicts first), and the
   check is repeated; conflicts that remain are reported, never hidden.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np

from design.place.region import PlacementRegion, placement_transform
from design.place.run import PlacementResult, place
from design.reach.study import ReachSettings, ReachStudy, reach_study
from design.task.model import Targets, TaskError
from kin.geometry.clearance_numpy import seg_seg
from kin.geometry.frames import body_frames

__all__ = ["PairResult", "place_pair", "robot_robot_clearance", "footprint"]


def _capsules(world, Q: np.ndarray):
    """End points (M, C, 3) and radii (C,) of a collision world's capsules at configurations Q (M, n)."""
    F = body_frames(world.chain, Q, world.base)
    caps = world.geometry.capsules
    body = np.array([c.body for c in caps])
    a = np.array([[*c.a, 1.0] for c in caps])
    b = np.array([[*c.b, 1.0] for c in caps])
    A = np.einsum("mcij,cj->mci", F[:, body], a)[..., :3]
    B = np.einsum("mcij,cj->mci", F[:, body], b)[..., :3]
    return A, B, np.array([c.radius for c in caps])


def robot_robot_clearance(world_a, Qa: np.ndarray, world_b, Qb: np.ndarray) -> np.ndarray:
    """Clearance (m) between robot A at each row of Qa (Ma, n) and robot B at each row of Qb (Mb, m):
    (Ma, Mb), the smallest capsule-to-capsule distance (negative: overlap).  Each world carries its
    robot's placement (``base``) and capsules (tool included)."""
    Aa, Ba, ra = _capsules(world_a, np.atleast_2d(Qa))
    Ab, Bb, rb = _capsules(world_b, np.atleast_2d(Qb))
    Ma, Ca, Mb, Cb = Aa.shape[0], Aa.shape[1], Ab.shape[0], Ab.shape[1]
    out = np.empty((Ma, Mb))
    for i in range(Ma):          # one row of A against all of B: Mb·Ca·Cb segment pairs
        a1 = np.broadcast_to(Aa[i][None, :, None], (Mb, Ca, Cb, 3)).reshape(-1, 3)
        d1 = np.broadcast_to((Ba[i] - Aa[i])[None, :, None], (Mb, Ca, Cb, 3)).reshape(-1, 3)
        a2 = np.broadcast_to(Ab[:, None], (Mb, Ca, Cb, 3)).reshape(-1, 3)
        d2 = np.broadcast_to((Bb - Ab)[:, None], (Mb, Ca, Cb, 3)).reshape(-1, 3)
        d, _, _ = seg_seg(np.ascontiguousarray(a1), np.ascontiguousarray(d1), np.ascontiguousarray(a2),
                          np.ascontiguousarray(d2))
        d = d.reshape(Mb, Ca, Cb) - ra[None, :, None] - rb[None, None, :]
        out[i] = d.reshape(Mb, -1).min(axis=1)
    return out


@dataclass
class PairResult:
    """Two robots in one cell: their placements ``u`` (2, 6), full studies, the assignment per target
    (0: robot A, 1: robot B, −1: neither), the robot–robot clearance of the assigned configurations
    (m, the smallest), the remaining ``conflicts`` (target of A, target of B, clearance)."""

    robots: tuple[str, str]
    u: np.ndarray
    studies: tuple[ReachStudy, ReachStudy]
    assignment: np.ndarray
    robot_clearance: float
    conflicts: list[tuple[int, int, float]]
    placements: tuple[PlacementResult, PlacementResult]
    moved: list[int] = field(default_factory=list)
    time_s: float = 0.0

    @property
    def coverage(self) -> float:
        return float((self.assignment >= 0).mean())

    def to_dict(self) -> dict:
        from kin.transforms import matrix_to_rpy
        per = []
        for k in range(2):
            P = placement_transform(self.u[k])
            per.append({"robot": self.robots[k], "placement": {"xyz": [float(v) for v in self.u[k, :3]],
                                                               "rpy": [float(v) for v in matrix_to_rpy(P[:3, :3])]},
                        "targets": [int(i) for i in np.flatnonzero(self.assignment == k)],
                        "coverage_alone_percent": 100 * self.studies[k].coverage,
                        "method": self.placements[k].method})
        return {"coverage_percent": 100 * self.coverage, "robots": per,
                "unassigned": [int(i) for i in np.flatnonzero(self.assignment < 0)],
                "robot_clearance_m": self.robot_clearance,
                "conflicts": [{"target_a": a, "target_b": b, "clearance_m": c} for a, b, c in self.conflicts],
                "moved": self.moved, "time_s": self.time_s}


def _assign(sa: ReachStudy, sb: ReachStudy) -> np.ndarray:
    a = np.where(sa.reached & (~sb.reached | (sa.score >= sb.score)), 0, -1)
    return np.where((a < 0) & sb.reached, 1, a)


def place_pair(robots, targets: Targets, cell=None, regions: tuple[PlacementRegion, PlacementRegion] | None = None,
               clearance: float = 0.0, settings: ReachSettings | None = None, starts: int = 3, candidates: int = 24,
               seed: int = 0, max_time: float = 600.0, max_moves: int = 200,
               progress: Callable[[str], None] | None = None) -> PairResult:
    """Place two robots (a pair of :class:`kin.Robot`) in one ``cell`` for one set of ``targets``, each
    within its region, and split the targets between them (see the module text)."""
    if len(robots) != 2 or (regions is not None and len(regions) != 2):
        raise TaskError("place_pair takes two robots and, if given, two placement regions")
    t0 = time.perf_counter()
    settings = settings or ReachSettings()
    say = progress or (lambda s: None)
    ra, rb = regions if regions is not None else (None, None)
    share = _initial_split(targets, ra, rb)
    ra_res = place(robots[0], _subset(targets, share == 0), cell, ra, clearance, settings=settings, starts=starts,
                   candidates=candidates, seed=seed, max_time=max_time / 2, progress=say)
    # robot B keeps its base out of robot A's footprint (a square around A's base origin)
    half = footprint(robots[0]) + footprint(robots[1]) + clearance
    ax, ay = ra_res.u[0], ra_res.u[1]
    keep = ((ax - half, ax + half, ay - half, ay + half),)
    if rb is None:
        rb = PlacementRegion.default(robots[1], targets.positions[share == 1], z=float(ra_res.u[2]))
    rb = replace(rb, keep_out=tuple(rb.keep_out) + keep)
    rb_res = place(robots[1], _subset(targets, share == 1), cell, rb, clearance, settings=settings, starts=starts,
                   candidates=candidates, seed=seed, max_time=max_time / 2, progress=say)
    sa = reach_study(robots[0], targets, cell, placement_transform(ra_res.u), clearance, settings=settings)
    sb = reach_study(robots[1], targets, cell, placement_transform(rb_res.u), clearance, settings=settings)
    assign = _assign(sa, sb)
    from planning.collision import collision_world
    wa, wb = collision_world(robots[0], cell, clearance), collision_world(robots[1], cell, clearance)
    wa.move_base(placement_transform(ra_res.u))
    wb.move_base(placement_transform(rb_res.u))
    moved: list[int] = []
    while True:
        ia, ib = np.flatnonzero(assign == 0), np.flatnonzero(assign == 1)
        C = robot_robot_clearance(wa, sa.q[ia], wb, sb.q[ib]) if len(ia) and len(ib) else np.full((len(ia), len(ib)),
                                                                                                   np.inf)
        bad = C <= clearance
        if not bad.any() or len(moved) >= max_moves:
            break
        # the target in most conflicts that the other robot also reaches moves over
        count = np.concatenate([bad.sum(axis=1), bad.sum(axis=0)])
        who = np.concatenate([ia, ib])
        side = np.concatenate([np.zeros(len(ia), int), np.ones(len(ib), int)])
        other_reaches = np.where(side == 0, sb.reached[who], sa.reached[who])
        cand = np.flatnonzero((count > 0) & other_reaches & ~np.isin(who, moved))
        if not len(cand):
            break
        k = cand[np.argmax(count[cand])]
        assign[who[k]] = 1 - side[k]
        moved.append(int(who[k]))
        say(f"target {who[k]} moved to robot {'AB'[1 - side[k]]} (robot–robot conflict)")
    conflicts = [(int(ia[i]), int(ib[j]), float(C[i, j])) for i, j in zip(*np.nonzero(C <= clearance))]
    rc = float(C.min()) if C.size else float("inf")
    return PairResult((robots[0].name, robots[1].name), np.array([ra_res.u, rb_res.u]), (sa, sb), assign, rc,
                      conflicts, (ra_res, rb_res), moved, time.perf_counter() - t0)


def footprint(robot) -> float:
    """How far (m) the robot's base and first link stand out from its base axis: the largest horizontal
    distance of a capsule of body 0 or 1 from the base origin plus its radius, at the middle of the
    joint ranges (body 1 turns about the base axis for the usual arm)."""
    geom = robot.geometry                 # the robot file's capsules, else the default along the DH offsets
    F = body_frames(robot.chain, 0.5 * (robot.chain.lower + robot.chain.upper))[0]
    out = 0.05
    for c in geom.capsules:
        if c.body in (0, 1):
            for end in (c.a, c.b):
                w = F[c.body] @ np.array([*end, 1.0])
                out = max(out, float(np.hypot(w[0], w[1])) + c.radius)
    return out


def _initial_split(targets: Targets, ra: PlacementRegion | None, rb: PlacementRegion | None) -> np.ndarray:
    """First share of the targets: to the nearer region centre (x–y), or, without regions, the two
    halves along the targets' longest horizontal spread."""
    P = targets.positions[:, :2]
    if ra is not None and rb is not None:
        ca = np.array([np.mean(ra.x), np.mean(ra.y)])
        cb = np.array([np.mean(rb.x), np.mean(rb.y)])
        share = (np.linalg.norm(P - cb, axis=1) < np.linalg.norm(P - ca, axis=1)).astype(int)
    else:
        c = P - P.mean(axis=0)
        _, _, Vt = np.linalg.svd(c, full_matrices=False)
        proj = c @ Vt[0]
        share = (proj > np.median(proj)).astype(int)
    if share.min() == share.max():          # one robot would get nothing: halve by index
        share = (np.arange(len(share)) >= len(share) // 2).astype(int)
    return share


def _subset(targets: Targets, mask: np.ndarray) -> Targets:
    return replace(targets, positions=targets.positions[mask],
                   axes=None if targets.axes is None else targets.axes[mask],
                   rotations=None if targets.rotations is None else targets.rotations[mask])
