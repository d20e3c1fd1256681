"""How far any point of a body can move when the joints move: the Lipschitz bound of the proofs.

For a point p fixed to body k and a revolute joint j ≤ k, ∂p/∂q_j = z_j × (p − o_j), with o_j any
point of joint j's axis, so |∂p/∂q_j| ≤ |p − o_j|.  Walking from o_j to p frame by frame,

    |p − o_j| ≤ Σ_{i between joint j's axis and frame k} |t_i| + |p_k|,

where |t_i| is the length of row i's translation (√(a_i² + d_i²); a prismatic row at its largest
extent) and |p_k| is p's distance from frame k's origin.  A prismatic joint moves every later point
by exactly its own motion: |∂p/∂q_j| = 1.  Hence along a straight joint motion Δq every point of
every capsule of body k moves at most

    D_k(Δq) = Σ_{j ≤ k} R[j, k]·|Δq_j|          (:func:`reach_radii` gives R, metres per rad or per m)

and the distance of a capsule to anything fixed changes by at most as much: a proof of clearance
between two samples needs only their clearances and D_k (see :mod:`planning.collision.proof`).
The bound holds for every configuration; tests check it against finite differences of the body
frames at random configurations.
"""
from __future__ import annotations

import math

import numpy as np

from kin.geometry.frames import dh_rows

__all__ = ["capsule_radii", "curvature_bound", "reach_radii", "row_lengths"]


def row_lengths(chain) -> np.ndarray:
    """(n,) the largest length of each DH row's translation (m), over the joint's range."""
    out = []
    for (a, _, d, _, pris), (lo, hi) in zip(dh_rows(chain), chain.limits):
        dmax = max(abs(d + lo), abs(d + hi)) if pris else abs(d)
        out.append(math.hypot(a, dmax))
    return np.array(out)


def _walks(chain) -> np.ndarray:
    """W (n, n + 2): the walk of :func:`reach_radii` from joint j's axis to body k's frame origin (m;
    the tool's includes the tool placement), before a body's own reach is added."""
    n = chain.n
    L = row_lengths(chain)
    tool_len = float(np.linalg.norm(chain.tool.matrix[:3, 3]))
    cum = np.concatenate([[0.0], np.cumsum(L)])           # cum[i] = L[0] + … + L[i − 1]
    j = np.arange(1, n + 1)[:, None]                      # joints 1 … n
    k = np.arange(n + 2)[None, :]                         # bodies 0 … n + 1
    first = j + 1 if chain.convention == "modified" else j
    last = np.minimum(k, n)
    W = np.where(last >= first, cum[np.clip(last, 0, n)] - cum[np.clip(first - 1, 0, n)], 0.0)
    W = W + np.where(k == n + 1, tool_len, 0.0)
    return np.where(k >= j, W, 0.0)


def capsule_radii(chain, geometry) -> np.ndarray:
    """R (C, n): the bound of :func:`reach_radii` for each capsule of ``geometry`` on its own (its
    own reach instead of its body's largest): R[c, j] bounds |∂p/∂q_j| for every point p of capsule
    c's segment at every configuration (m/rad for a revolute joint, 1 for a prismatic one, 0 where joint
    j does not move the capsule's body)."""
    n = chain.n
    W = _walks(chain)
    rev = chain.revolute_mask
    caps = geometry.capsules
    body = np.array([c.body for c in caps], dtype=np.int64)
    ends = np.array([(*c.a, *c.b) for c in caps], dtype=float).reshape(-1, 6)
    reach = np.maximum(np.linalg.norm(ends[:, :3], axis=1), np.linalg.norm(ends[:, 3:], axis=1))
    moves = np.arange(1, n + 1)[None, :] <= body[:, None]          # joint j moves body k when j ≤ k
    R = np.where(rev[None, :], W[:, body].T + reach[:, None], 1.0)
    return np.where(moves, R, 0.0)


def curvature_bound(R: np.ndarray, dq: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """M (C,): a bound on |d²p/dt²| (m) for every point p of each capsule along the straight joint motion
    q(t) = a + t·dq, t ∈ [0, 1], given the capsules' :func:`capsule_radii` R (C, n).

    With v_j = ∂p/∂q_j (z_j × (p − o_j) for a revolute joint, z_j for a prismatic one), p' = Σ_j dq_j v_j
    and p'' = Σ_j dq_j v_j'.  Axis z_j is turned by the revolute joints before j only, so |z_j'| ≤ W_j =
    Σ_{l<j, revolute} |dq_l|; the point o_j moves with those joints, so |p' − o_j'| ≤ W_j |p − o_j| +
    Σ_{l≥j} |dq_l| R_l; and |p − o_j| ≤ R_j.  Hence, over the joints j that move p,

        M = Σ_{j revolute} |dq_j| (2 W_j R_j + Σ_{l≥j} |dq_l| R_l) + Σ_{j prismatic} |dq_j| W_j.

    A point then stays within (t − t0)(t1 − t)/2 · M ≤ (t1 − t0)²/8 · M of the chord between its
    positions at t0 and t1 — what :mod:`planning.motion` proves motions with."""
    R = np.atleast_2d(np.asarray(R, dtype=float))
    A = np.abs(np.asarray(dq, dtype=float))
    rev = np.asarray(revolute, dtype=bool)
    W = np.concatenate([[0.0], np.cumsum(np.where(rev, A, 0.0))[:-1]])      # Σ_{l<j} revolute |dq_l|
    moves = R > 0
    tail = np.cumsum((A * R)[:, ::-1], axis=1)[:, ::-1]                     # Σ_{l≥j} |dq_l| R_l
    per_joint = np.where(rev, 2 * W * R + tail, W) * A
    return np.where(moves, per_joint, 0.0).sum(axis=1)


def reach_radii(chain, geometry) -> np.ndarray:
    """R (n, n + 2): R[j, k] bounds |∂p/∂q_j| for every point p of body k's capsule segments, at
    every configuration (m/rad for a revolute joint j, 1 for a prismatic one; 0 when joint j does
    not move body k).

    Standard DH: joint j turns about z_{j-1} through frame j−1's origin, so the walk to frame k
    takes rows j … k.  Modified DH: joint j turns about z_j through frame j's origin: rows j+1 … k.
    The tool (body n + 1) is frame n plus the tool placement; its capsules are in the tool frame.
    """
    n = chain.n
    W = _walks(chain)
    reach = np.zeros(n + 2)           # |p_k| bound per body
    for c in geometry.capsules:
        reach[c.body] = max(reach[c.body], c.reach)
    rev = chain.revolute_mask
    R = np.zeros((n, n + 2))
    for j in range(1, n + 1):
        for k in range(j, n + 2):
            R[j - 1, k] = W[j - 1, k] + reach[k] if rev[j - 1] else 1.0
    return R
