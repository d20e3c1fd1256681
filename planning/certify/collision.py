"""Proofs that straight joint-space segments keep the robot clear of the cell and of itself.

A sampled check looks at finitely many states and can miss a link that grazes an obstacle between
two of them.  Here every segment q(t) = a + t·(b − a) is proven clear, or a colliding state found,
from clearances at finitely many states and a bound on how far the geometry can move between them.

The bound (:func:`kin.geometry.reach_radii`): along a piece [t0, t1] of a segment every point of
body k's capsules moves at most D_k = Σ_j R[j, k]·|Δq_j|·(t1 − t0).  Clearance to a fixed obstacle
is then D_k-Lipschitz in the piece, so with c0, c1 body k's obstacle clearances at its ends, for
any s in the piece c(s) ≥ max(c0 − s·D_k, c1 − (1 − s)·D_k) ≥ (c0 + c1 − D_k)/2: the piece is
proven clear of every obstacle for body k when c0 + c1 − 2m > D_k (m the required clearance).
Against another body both move, but joints before both move them together: a pair i < j changes
its distance by at most Σ_{l = i+1}^{j} R[l, j]·|Δq_l|, and body k's self bound is the largest over
its pairs.  A piece that is not settled is halved (its
midpoint evaluated); a state whose clearance is ≤ m is a violation.  Pieces still open after
``max_depth`` halvings or beyond the evaluation budget are reported as unproven, never as clear.

The pieces of every segment of a path are processed together, one batch of the clearance kernel
per level.  The proof also gives a proven lower bound on the clearance along the whole path,
min over pieces and bodies of (c0 + c1 − D)/2.

Where the native motion checker is available (a C compiler: almost always), the proof is its proof
instead — the one the planner's motion validator gives every edge (:mod:`planning.motion`, stated in
``planning/motion/motion.c``: chords of the capsules between states with a bound on the path's curvature,
intervals cut where needed) — so that the planner, ``rmt check-path`` and every other check give the
same verdict.  The halving proof above remains for a chain the checker refuses (a prismatic value
beyond its evaluable range) and without a compiler.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["CollisionProof", "Collision", "certify_collision", "MAX_DEPTH", "MAX_EVALS"]

#: halvings of a segment before a piece is left unproven (2⁻³⁰ of the segment)
MAX_DEPTH = 30
#: states evaluated per path at most (a budget: beyond it the rest is unproven)
MAX_EVALS = 2_000_000


@dataclass(frozen=True)
class Collision:
    """A state where the robot is not clear: segment ``segment`` (its first row), at fraction ``t``,
    configuration ``q`` (SI); ``body`` (index) against ``other`` (obstacle index ≥ 0, or
    −1 − body for a self pair); ``clearance`` (m; negative: penetration depth) there; ``deepest``:
    the smallest clearance along the rest of the segment (sampled, m); ``text`` names them."""

    segment: int
    t: float
    q: np.ndarray
    body: int
    other: int
    clearance: float
    text: str
    deepest: float = math.nan


@dataclass
class CollisionProof:
    """Result of :func:`certify_collision`: ``proven`` — every segment proven clear; ``violation``
    — the first colliding state found (None when none); ``unproven`` — segments neither proven nor
    refuted; ``bound`` — proven lower bound on the clearance along the proven pieces (m);
    ``min_sampled`` and ``min_index`` — the smallest clearance at an evaluated state and its
    segment; ``evaluations`` — states evaluated."""

    proven: bool
    violation: Collision | None
    unproven: list[int] = field(default_factory=list)
    bound: float = math.inf
    min_sampled: float = math.inf
    min_index: int = -1
    evaluations: int = 0


def _motion(world, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per piece (S, B): how far body k's points can move (the obstacle bound), and how far they can
    move relative to any body they are checked against (the self bound).

    Two bodies i < j are moved rigidly together by joints 1 … i; only joints i + 1 … j move body j
    relative to body i, so the distance of a pair changes by at most Σ_{l = i+1}^{j} R[l, j]·|Δq_l|
    (body i stands still in its own frame).  Body k's self bound is the largest of its pairs'."""
    A = np.abs(dq)
    D = A @ world.radii                                       # (S, B)
    if not len(world.pairs):
        return D, np.zeros_like(D)
    Dp = A @ world.pair_radii.T                               # (S, P): each pair's bound
    Ds = np.where(world.pair_bodies[None], Dp[:, :, None], 0.0).max(axis=1)
    return D, Ds


def certify_collision(world, path, max_depth: int = MAX_DEPTH, max_evals: int = MAX_EVALS,
                      stop_at_first: bool = False, explain: bool = True, bound: bool = True,
                      native: bool = True) -> CollisionProof:
    """Prove every segment of ``path`` (M, n), SI, clear of ``world`` (a
    :class:`planning.collision.CollisionWorld`) — or find the first colliding state.

    ``stop_at_first``: return as soon as any violation or unproven piece is known (what a motion
    validator needs: a yes or no); ``explain=False`` (with it) leaves the violation unnamed and unmeasured;
    ``bound=False``: with the native checker, do not measure the proven lower bound (``bound`` is then
    NaN; the verdict is the same); ``native=False``: the halving proof in Python (which sees the
    world's hulls, :class:`kin.geometry.hulls.HullRefiner`), not the native checker.  With hulls, a
    segment the native checker (capsules only) cannot prove clear is proven again so.
    """
    P = np.atleast_2d(np.asarray(path, dtype=float))
    if P.size == 0:
        return CollisionProof(True, None)
    hulls = getattr(world, "refiner", None) is not None
    if native:
        proof = _native(world, P, stop_at_first, explain, bound)
        if proof is not None and not (hulls and not proof.proven):
            return proof
        if proof is not None and hulls:
            return _hull_retry(world, P, proof, max_depth, max_evals, stop_at_first, explain, bound)
    m = world.margin
    if stop_at_first and len(P) == 2 and not hulls:
        fast = _motion_in_c(world, P, max_depth, max_evals, explain)
        if fast is not None:
            return fast
    obs, slf = world.per_body(P)
    evals = len(P)
    rowmin = np.minimum(obs.min(axis=1), slf.min(axis=1))
    min_s = float(rowmin.min())
    min_i = int(np.argmin(rowmin))
    hits: list[tuple[int, float, np.ndarray]] = []
    bad_rows = np.flatnonzero(rowmin <= m)
    for i in bad_rows:
        hits.append((int(i), 0.0, P[i]))
    if len(bad_rows) and stop_at_first:
        return _result(world, P, hits, [], -math.inf, min_s, min_i, evals)
    S = len(P) - 1
    if S <= 0:
        return _result(world, P, hits, [], float(rowmin.min()) if len(P) else math.inf, min_s, min_i, evals)
    D_obs, D_self = _motion(world, np.diff(P, axis=0))        # per unit of t, (S, B)
    # open pieces: segment, t0, t1, clearances at both ends
    seg = np.arange(S)
    t0, t1 = np.zeros(S), np.ones(S)
    o0, o1, s0, s1 = obs[:-1], obs[1:], slf[:-1], slf[1:]
    # a segment that starts in collision is settled (the violation is its first row); one that ends in
    # collision is searched for where it enters
    keep = rowmin[:-1] > m
    seg, t0, t1, o0, o1, s0, s1 = seg[keep], t0[keep], t1[keep], o0[keep], o1[keep], s0[keep], s1[keep]
    bound = float(rowmin.min())
    unproven: set[int] = set()
    for depth in range(max_depth + 1):
        if len(seg) == 0:
            break
        w = (t1 - t0)[:, None]
        need_o, need_s = D_obs[seg] * w, D_self[seg] * w
        ok = ((o0 + o1 - 2 * m > need_o) & (s0 + s1 - 2 * m > need_s)).all(axis=1)
        if ok.any():
            lb = np.minimum((o0 + o1 - need_o) / 2, (s0 + s1 - need_s) / 2).min(axis=1)
            bound = min(bound, float(lb[ok].min()))
        open_ = ~ok
        if not open_.any():
            seg = seg[:0]
            break
        seg, t0, t1, o0, o1, s0, s1 = seg[open_], t0[open_], t1[open_], o0[open_], o1[open_], s0[open_], s1[open_]
        if depth == max_depth or evals + len(seg) > max_evals:
            unproven.update(int(k) for k in seg)
            if stop_at_first:
                return _result(world, P, hits, sorted(unproven), bound, min_s, min_i, evals)
            break
        tm = 0.5 * (t0 + t1)
        Q = P[seg] + tm[:, None] * (P[seg + 1] - P[seg])
        om, sm = world.per_body(Q)
        evals += len(Q)
        qmin = np.minimum(om.min(axis=1), sm.min(axis=1))
        k = int(np.argmin(qmin))
        if qmin[k] < min_s:
            min_s, min_i = float(qmin[k]), int(seg[k])
        bad = qmin <= m
        for i in np.flatnonzero(bad):
            hits.append((int(seg[i]), float(tm[i]), Q[i]))
        if bad.any() and stop_at_first:
            return _result(world, P, hits, sorted(unproven), -math.inf, min_s, min_i, evals)
        # halve every open piece: [t0, tm] and [tm, t1]
        seg = np.concatenate([seg, seg])
        t0, t1 = np.concatenate([t0, tm]), np.concatenate([tm, t1])
        o0, o1 = np.concatenate([o0, om]), np.concatenate([om, o1])
        s0, s1 = np.concatenate([s0, sm]), np.concatenate([sm, s1])
        if hits:
            # only pieces before the first violation found can change the verdict
            fs, ft = min((h[0], h[1]) for h in hits)
            before = (seg < fs) | ((seg == fs) & (t0 < ft))
            seg, t0, t1, o0, o1, s0, s1 = (x[before] for x in (seg, t0, t1, o0, o1, s0, s1))
    return _result(world, P, hits, sorted(unproven), bound, min_s, min_i, evals)


def _hull_retry(world, P, proof: CollisionProof, max_depth, max_evals, stop_at_first, explain, bound) -> CollisionProof:
    """The native proof failed on a world with hulls: every segment it did not prove (from the first
    failing one on) proven again in Python, where the hulls count."""
    failed = [*proof.unproven, *([proof.violation.segment] if proof.violation is not None else [])]
    if not failed:
        return proof
    first = min(failed)
    again = certify_collision(world, P[first:], max_depth, max_evals, stop_at_first, explain, bound, native=False)
    if first == 0:
        return again
    head = certify_collision(world, P[:first + 1], max_depth, max_evals, stop_at_first, explain, bound)
    v = again.violation
    if v is not None:
        v = Collision(v.segment + first, v.t, v.q, v.body, v.other, v.clearance, v.text, v.deepest)
    unproven = sorted(set(head.unproven) | {k + first for k in again.unproven})
    return CollisionProof(head.proven and again.proven, v, unproven,
                          min(head.bound, again.bound), min(head.min_sampled, again.min_sampled),
                          head.min_index if head.min_sampled <= again.min_sampled else again.min_index + first,
                          head.evaluations + again.evaluations)


def _native(world, P: np.ndarray, stop_at_first: bool, explain: bool, bound: bool) -> CollisionProof | None:
    """The proof by the native motion checker, segment by segment in order (None: not available here, or a
    configuration it refuses)."""
    from planning.motion import checker_for
    chk = checker_for(world, limits=False)
    if chk is None:
        return None
    rows = world.clearance(P) if explain else np.full(len(P), np.inf)
    rows = np.atleast_1d(rows)
    min_s, min_i = float(rows.min()), int(np.argmin(rows))
    evals, least, unproven = len(P), math.inf, []
    if len(P) == 1:
        st = chk.state_status(P[0])
        if st == "bad":
            return None
        if st == "collision":
            return _result(world, P, [(0, 0.0, P[0])], [], -math.inf, min_s, min_i, evals) if explain \
                else CollisionProof(False, Collision(0, 0.0, P[0], -1, -1, math.nan, "in collision"))
        return CollisionProof(True, None, [], float(rows[0]) if bound and explain else math.nan, min_s, min_i, evals)
    for k in range(len(P) - 1):
        r = chk.check(P[k], P[k + 1], ordered=True, bound=bound)
        evals += r.evals
        if r.status == "bad":
            return None
        if r.status == "collision":
            q = P[k] + r.t * (P[k + 1] - P[k])
            if not explain:
                return CollisionProof(False, Collision(k, r.t, q, -1, -1, math.nan, "in collision"), unproven,
                                      -math.inf, min_s, min_i, evals)
            return _result(world, P, [(k, r.t, q)], unproven, -math.inf, min_s, min_i, evals)
        if r.status == "unproven":
            unproven.append(k)
            if stop_at_first:
                break
            continue
        if bound:
            least = min(least, r.bound)
    if unproven:
        return CollisionProof(False, None, unproven, math.nan, min_s, min_i, evals)
    if not bound:
        least = math.nan
    elif not math.isfinite(least):      # nothing came within the cap
        least = world.model.cap
    return CollisionProof(True, None, [], min(least, min_s) if bound else math.nan, min_s, min_i, evals)


def _motion_in_c(world, P: np.ndarray, max_depth: int, max_evals: int, explain: bool) -> CollisionProof | None:
    """One motion, yes or no, by the kernel's C version of the same proof (None: not available)."""
    D_obs, D_self = _motion(world, (P[1] - P[0])[None])
    r = world.model.prove_motion(P[0], P[1], D_obs[0], D_self[0], world.margin, max_depth, max_evals)
    if r is None:
        return None
    status, t = r
    if status == 1:
        return CollisionProof(True, None)
    if status == -1:
        return CollisionProof(False, None, [0])
    q = P[0] + t * (P[1] - P[0])
    if not explain:                 # a motion validator needs the verdict only
        return CollisionProof(False, Collision(0, t, q, -1, -1, math.nan, "in collision"))
    return _result(world, P, [(0, t, q)], [], -math.inf, math.inf, -1, 0)


def _result(world, P, hits, unproven, bound, min_s, min_i, evals) -> CollisionProof:
    violation = None
    if hits:
        k, t, q = min(hits, key=lambda h: (h[0], h[1]))
        c = world.nearest(q[None])
        body, other, clear = int(c.body[0]), int(c.other[0]), float(c.clearance[0])
        text = world.describe(body, other, clear)
        deepest = clear
        if k + 1 < len(P):      # how deep the segment goes, from where it enters
            S = P[k] + np.linspace(t, 1.0, 257)[:, None] * (P[k + 1] - P[k])
            deepest = min(clear, float(world.clearance(S).min()))
            if deepest < min(clear, 0.0):
                text += f"; up to {-deepest * 1e3:.3g} mm deep further along this segment"
        violation = Collision(k, t, np.array(q), body, other, clear, text, deepest)
        unproven = [u for u in unproven if u < k]        # pieces at or after the violation do not matter
    proven = violation is None and not unproven
    return CollisionProof(proven, violation, list(unproven), bound if violation is None else -math.inf,
                          min_s, min_i, evals)
