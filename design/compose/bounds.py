"""Proven bounds: cheap tests that an assembly — or every completion of a partial one — cannot serve
a part, applied before the reach study.  Each says *infeasible* only when no configuration within
the joint limits can satisfy the reach study's acceptance (position within the target's tolerance,
orientation within :data:`ANGLE_MARGIN`, which is ten times the IK's), so it never removes a
feasible assembly.

**dof** (complete assemblies): when every revolute joint turns about a parallel axis (direction d;
they then stay parallel in every configuration), every rotation is about d, which keeps each
point's height along d and each tool direction's angle with d: the tool's height along d can change
only by the prismatic joints' travel times their component along d, and a tool axis that makes
angle β with d at q = 0 makes it always — a target whose height or axis angle lies beyond (by more
than the tolerance) is out.  When the revolute axes are moreover one line and every prismatic joint
slides along it, the tool's distance from that line is fixed too.  Without a revolute joint the
tool keeps its orientation.  (A count of joints alone — "an axis target needs five" — proves
nothing for finitely many targets: a four-joint SCARA drills vertical holes; it is not used.)

**reach_bound**: pick o, the first joint's axis point (fixed in the world) and, for each later
joint k, its axis point p_k (a point of the body before it, and — on the axis — of the body after
it).  For a revolute joint k the distance p_k → p_{k+1} (or → the tool point after the last joint)
never changes; for a prismatic one it lies between the least and greatest distance over its travel.
By the triangle inequality the tool point's distance from o is at most U, the sum of the greatest
distances, and at least max_k (least_k − (U − greatest_k)); a target farther than U + tolerance or
nearer than that minus the tolerance is out.  For a *partial* assembly, U also adds the largest sum
of module extents (input to output origin over the module's travel) any completion can append —
:meth:`design.compose.space.ComposeSpace.max_remaining` — so a partial assembly whose every
completion falls short is proven empty as a whole.

**holding** (complete): :func:`kin.modules.holding` found a configuration within the limits whose
gravity torque exceeds a joint's ``max_torque`` — the assembly cannot hold itself at rest (``rmt
assemble`` refuses it).  A partial assembly is never pruned by it: modules added later change every
torque.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kin.modules import Assembly, Catalogue
from kin.modules.catalogue import Module
from kin.transforms import make_transform, rot_z

__all__ = ["Sketch", "PartGeometry", "sketch", "module_extent", "dof_bound", "reach_bound", "partial_reach_bound",
           "holding_bound", "ANGLE_MARGIN", "PARALLEL_TOL"]

#: orientation slack (rad) beyond which a bound calls a tool axis wrong (the IK accepts 1e-6 rad)
ANGLE_MARGIN = 1e-5
#: axes whose directions differ by less than this (sine of the angle) are parallel
PARALLEL_TOL = 1e-12
_POS_EPS = 1e-9         # m: floating-point slack added to every position tolerance


def module_extent(m: Module) -> float:
    """The greatest distance between a module's input and output origins over its travel (m): the
    triangle inequality through the joint frame for a joint module."""
    if m.kind == "base":
        return 0.0
    out = np.asarray(m.out)[:3, 3]
    if m.kind != "joint":
        return float(np.linalg.norm(out))
    ax = float(np.linalg.norm(np.asarray(m.axis)[:3, 3]))
    if m.type == "revolute":
        return ax + float(np.linalg.norm(out))
    return ax + max(float(np.linalg.norm(out + np.array([0.0, 0.0, q]))) for q in m.limits)


@dataclass(frozen=True)
class Sketch:
    """An assembly (or a prefix) at q = 0 in the robot's frame: per joint its axis point, direction,
    type and limits; the end point and rotation (the tool frame, or the last output frame)."""

    points: np.ndarray          # (n, 3)
    dirs: np.ndarray            # (n, 3)
    revolute: np.ndarray        # (n,) bool
    limits: np.ndarray          # (n, 2)
    end: np.ndarray             # (3,)
    end_rot: np.ndarray         # (3, 3)

    def segments(self) -> tuple[np.ndarray, np.ndarray]:
        """Least and greatest length (n,) of each segment: axis point k → axis point k+1 (→ the end)."""
        n = len(self.points)
        nxt = np.vstack([self.points[1:], self.end[None]])
        lo, hi = np.zeros(n), np.zeros(n)
        for k in range(n):
            v = nxt[k] - self.points[k]
            if self.revolute[k]:
                lo[k] = hi[k] = float(np.linalg.norm(v))
                continue
            z, (a, b) = self.dirs[k], self.limits[k]
            ends = [float(np.linalg.norm(v + q * z)) for q in (a, b)]
            hi[k] = max(ends)
            t = min(max(-float(v @ z), a), b)          # the travel nearest the axis point
            lo[k] = float(np.linalg.norm(v + t * z))
        return lo, hi


def sketch(catalogue: Catalogue, modules, twists) -> Sketch:
    """The :class:`Sketch` of a module list (base first) at q = 0, without validating it (an
    :class:`Assembly` prefix from the space is valid by construction)."""
    pts, dirs, rev, lims = [], [], [], []
    T = np.eye(4)
    for i, name in enumerate(modules):
        m = catalogue.modules[name]
        if m.kind == "base":
            T = np.asarray(m.out)
            continue
        Tin = T @ make_transform(rot_z(twists[i - 1]))
        if m.kind == "joint":
            J = Tin @ m.axis
            pts.append(J[:3, 3].copy())
            dirs.append(J[:3, 2].copy())
            rev.append(m.type == "revolute")
            lims.append(m.limits)
            T = J @ m.out
        else:
            T = Tin @ m.out
    return Sketch(np.array(pts).reshape(-1, 3), np.array(dirs).reshape(-1, 3), np.array(rev, bool),
                  np.array(lims, float).reshape(-1, 2), T[:3, 3].copy(), T[:3, :3].copy())


@dataclass(frozen=True)
class PartGeometry:
    """What the bounds need of a part, in the robot's frame: target positions (N, 3), the tool
    axes (N, 3) or None, rotations (N, 3, 3) or None, the cone half-angle, the tolerance (m)."""

    name: str
    positions: np.ndarray
    axes: np.ndarray | None
    rotations: np.ndarray | None
    half_angle: float
    tolerance: float

    @classmethod
    def of(cls, part) -> "PartGeometry":
        P = np.linalg.inv(part.placement)
        t = part.targets
        pos = t.positions @ P[:3, :3].T + P[:3, 3]
        axes = None if t.axes is None else t.axes @ P[:3, :3].T
        rots = None if t.rotations is None else np.einsum("ij,njk->nik", P[:3, :3], t.rotations)
        return cls(part.name, pos, axes, rots, t.cone_half_angle if t.orientation == "cone" else 0.0, t.tolerance)

    @property
    def slack(self) -> float:
        return self.tolerance * (1 + 1e-9) + _POS_EPS


def _fmt(x: float) -> str:
    return f"{1000 * x:.4g} mm"


def reach_bound(sk: Sketch, g: PartGeometry, remaining: float | None = None) -> str | None:
    """Why no configuration reaches every target (module text), or None.  ``remaining``: for a
    partial assembly, the most its completions can add to the reach (the inner bound is then skipped)."""
    if not len(sk.points):
        return None
    lo, hi = sk.segments()
    U = float(hi.sum()) + (remaining or 0.0)
    d = np.linalg.norm(g.positions - sk.points[0], axis=1)
    far = int(np.argmax(d))
    if d[far] > U + g.slack:
        whose = "any completion's tool point" if remaining is not None else "the tool point"
        return (f"target {far} is {_fmt(d[far])} from the first joint's axis point; {whose} is at most "
                f"{_fmt(U)} from it")
    if remaining is None:
        inner = float(np.max(lo - (hi.sum() - hi)))
        near = int(np.argmin(d))
        if d[near] < inner - g.slack:
            return (f"target {near} is {_fmt(d[near])} from the first joint's axis point; the tool point is at "
                    f"least {_fmt(inner)} from it")
    return None


def partial_reach_bound(sk: Sketch, g: PartGeometry, remaining: float) -> str | None:
    """:func:`reach_bound` of a partial assembly whose completions add at most ``remaining`` (m)."""
    if remaining == -math.inf:
        return None
    return reach_bound(sk, g, max(remaining, 0.0))


def _angle(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.arccos(np.clip(np.sum(u * v, axis=-1), -1.0, 1.0))


def _orientation(sk: Sketch, g: PartGeometry, d: np.ndarray | None) -> str | None:
    """Orientation part of :func:`dof_bound`: about d only (d None: no rotation at all)."""
    if g.axes is None:
        return None
    R0 = sk.end_rot
    if g.rotations is not None:
        cols = [(R0[:, c], g.rotations[:, :, c], "xyz"[c]) for c in range(3)]
    else:
        cols = [(R0[:, 2], g.axes, "z")]
    for tool, want, name in cols:
        if d is None:
            miss = _angle(np.broadcast_to(tool, want.shape), want)
        else:
            miss = np.abs(_angle(tool, d) - _angle(want, np.broadcast_to(d, want.shape)))
        bad = miss > g.half_angle + ANGLE_MARGIN
        if bad.any():
            i = int(np.argmax(miss))
            how = "keeps its orientation (no revolute joint)" if d is None else \
                "turns about one direction only (every revolute axis parallel)"
            return (f"the tool {how}: target {i} needs its {name} axis {math.degrees(miss[i]):.4g}° from any it "
                    f"can take")
    return None


def dof_bound(sk: Sketch, g: PartGeometry) -> str | None:
    """Why the assembly lacks the freedom the part needs (module text), or None."""
    rev = sk.revolute
    if rev.any():
        d = sk.dirs[rev][0]
        if any(np.linalg.norm(np.cross(d, z)) > PARALLEL_TOL for z in sk.dirs[rev]):
            return None
        dirs = [d]
    else:
        pz = list(sk.dirs)
        dirs = [np.eye(3)[i] for i in range(3)] + pz
        dirs += [np.cross(a, b) for i, a in enumerate(pz) for b in pz[i + 1:]]
        dirs = [v / np.linalg.norm(v) for v in dirs if np.linalg.norm(v) > 1e-9]
    pris = ~rev
    for dv in dirs:
        c = sk.dirs[pris] @ dv
        lo_q, hi_q = sk.limits[pris, 0], sk.limits[pris, 1]
        h0 = float(sk.end @ dv)
        hmin = h0 + float(np.minimum(lo_q * c, hi_q * c).sum())
        hmax = h0 + float(np.maximum(lo_q * c, hi_q * c).sum())
        h = g.positions @ dv
        out = (h < hmin - g.slack) | (h > hmax + g.slack)
        if out.any():
            i = int(np.flatnonzero(out)[0])
            what = "along every revolute axis" if rev.any() else "along a fixed direction"
            return (f"the tool point's height {what} stays within [{_fmt(hmin)}, {_fmt(hmax)}]; target {i} is at "
                    f"{_fmt(float(h[i]))}")
    if rev.any():
        d = dirs[0]
        o = sk.points[rev][0]
        line = all(np.linalg.norm(np.cross(p - o, d)) <= 1e-12 for p in sk.points[rev])
        slide = all(np.linalg.norm(np.cross(z, d)) <= PARALLEL_TOL for z in sk.dirs[pris])
        if line and slide:
            r0 = float(np.linalg.norm(np.cross(sk.end - o, d)))
            r = np.linalg.norm(np.cross(g.positions - o, d), axis=1)
            bad = np.abs(r - r0) > g.slack
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                return (f"every revolute axis is one line: the tool point stays {_fmt(r0)} from it; target {i} is "
                        f"{_fmt(float(r[i]))} from it")
        return _orientation(sk, g, d)
    return _orientation(sk, g, None)


def holding_bound(chain) -> str | None:
    """Why the assembled robot cannot hold itself at rest (:func:`kin.modules.holding` proved a joint
    fails), or None."""
    from kin.modules import holding
    rep = holding(chain)
    return rep.failure_text(chain) if rep.fails else None


def screen(catalogue: Catalogue, assembly: Assembly, geometries) -> tuple[str, str, str] | None:
    """(stage, part name, reason) of the first cheap bound (dof, then reach) that rules a complete
    assembly out for one of the parts (:class:`PartGeometry`), or None."""
    sk = sketch(catalogue, assembly.modules, assembly.twists)
    for stage, bound in (("dof", dof_bound), ("reach_bound", reach_bound)):
        for g in geometries:
            why = bound(sk, g)
            if why:
                return stage, g.name, why
    return None
