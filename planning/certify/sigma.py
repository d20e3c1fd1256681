"""Proofs that σ_min stays above a floor along straight joint-space segments.

Weyl's inequality bounds how fast the smallest singular value can change: |σ_min(A) − σ_min(B)| ≤
‖A − B‖₂ ≤ ‖A − B‖_F.  Along a straight segment, ‖J(q′) − J(q)‖_F ≤ Σ_k L_k·|q′_k − q_k|, where L_k
bounds ‖∂J/∂q_k‖_F over the whole joint space (:func:`jacobian_lipschitz`).  For a geometric
Jacobian with columns [z_i × (p − o_i); z_i]:

* a revolute joint k turns z_i (by at most |Δq_k|) and p − o_i (whose length is at most R, the
  largest distance between a joint origin and the tool point), so ‖∂J_i/∂q_k‖ ≤ √((2R)² + 1);
* a prismatic joint k moves p − o_i along a unit axis and turns nothing: ‖∂J_i/∂q_k‖ ≤ 1;

summed over the n columns.  R is bounded from the chain's DH values, the limits of its prismatic
joints and its tool offset.  The bound is crude (it holds for every configuration), so a segment
is proven piece by piece: at the middle of a piece σ_min is evaluated, and the whole piece is proven
when σ_mid − Σ_k L_k·|Δq_k|·(half the piece) ≥ the floor; a middle below the floor is a violation;
otherwise the piece is halved (up to ``max_depth`` times, after which it is reported unproven).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["SigmaProof", "certify_sigma", "jacobian_lipschitz", "reach_bound"]


@dataclass
class SigmaProof:
    """Result of :func:`certify_sigma`: ``proven`` — σ_min ≥ floor on every segment; ``violation`` —
    (segment, t, q, σ_min) of the first state found below it, or None; ``unproven`` — segment indices
    neither proven nor refuted; ``evaluations`` — σ_min evaluations used."""

    proven: bool
    violation: tuple[int, float, np.ndarray, float] | None
    unproven: list[int] = field(default_factory=list)
    evaluations: int = 0


def reach_bound(chain) -> float:
    """An upper bound (m) of the distance between any joint origin and the tool point, over every
    configuration inside the limits (design parameters at their nominal values)."""
    total = 0.0
    for j in chain.joints:
        # a prismatic joint's variable is its d: the offset plus the farther limit
        d_extent = abs(chain.resolve(j.d)) + (0.0 if j.is_revolute else max(abs(j.limits[0]), abs(j.limits[1])))
        total += abs(chain.resolve(j.a)) + d_extent
    total += float(np.linalg.norm(chain.tool.matrix[:3, 3]))
    return total


def jacobian_lipschitz(robot) -> np.ndarray:
    """L (n,): ‖∂J/∂q_k‖_F ≤ L_k everywhere (SI: per rad for revolute, per m for prismatic joints)."""
    chain = robot.chain
    R = reach_bound(chain)
    n = chain.n
    col_rev = math.sqrt(4 * R * R + 1.0)
    return np.array([math.sqrt(n) * (col_rev if j.is_revolute else 1.0) for j in chain.joints])


def certify_sigma(robot, path, floor: float, max_depth: int = 30, max_evaluations: int = 2_000_000) -> SigmaProof:
    """Prove σ_min (of the task Jacobian) ≥ ``floor`` on every straight segment of ``path`` (M, n),
    SI, or find the first state below it.  See the module docstring."""
    P = np.asarray(path, dtype=float)
    if len(P) == 1:
        P = np.vstack([P, P])
    L = jacobian_lipschitz(robot)
    A, D = P[:-1], P[1:] - P[:-1]
    rate = np.abs(D) @ L                         # σ_min can fall at most rate·Δt over Δt of a segment
    seg = np.arange(len(A))
    t0, t1 = np.zeros(len(A)), np.ones(len(A))
    found: tuple[int, float, np.ndarray, float] | None = None
    evaluations = 0
    unproven: list[int] = []
    rows = robot.sigma_min(P)
    evaluations += len(P)
    low = np.nonzero(rows < floor)[0]
    if len(low):
        r = int(low[0])
        k, t = (r, 0.0) if r < len(A) else (len(A) - 1, 1.0)
        found = (k, t, P[r].copy(), float(rows[r]))
    for depth in range(max_depth + 1):
        if found is not None:
            keep = (seg < found[0]) | ((seg == found[0]) & (t0 < found[1]))
            seg, t0, t1 = seg[keep], t0[keep], t1[keep]
        if not len(seg):
            break
        tm = 0.5 * (t0 + t1)
        Q = A[seg] + tm[:, None] * D[seg]
        s = robot.sigma_min(Q)
        evaluations += len(seg)
        bad = np.nonzero(s < floor)[0]
        if len(bad):
            order = np.lexsort((tm[bad], seg[bad]))
            i = bad[order[0]]
            cand = (int(seg[i]), float(tm[i]), Q[i].copy(), float(s[i]))
            if found is None or cand[:2] < found[:2]:
                found = cand
        # not proven: split (a piece whose middle is below the floor too: its left half may hold an
        # earlier violation; the filter above drops what lies after the first one found)
        open_ = s - rate[seg] * 0.5 * (t1 - t0) < floor
        seg, t0, t1, tm = seg[open_], t0[open_], t1[open_], tm[open_]
        if depth == max_depth or evaluations + 2 * len(seg) > max_evaluations:
            unproven = sorted({int(k) for k in seg})
            break
        seg = np.repeat(seg, 2)
        t0, t1 = np.column_stack([t0, tm]).ravel(), np.column_stack([tm, t1]).ravel()
    if found is not None:       # pieces left just before the violation found are in its own segment
        unproven = [k for k in unproven if k < found[0]]
    return SigmaProof(found is None and not unproven, found, unproven, evaluations)
