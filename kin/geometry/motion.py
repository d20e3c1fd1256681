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

__all__ = ["reach_radii", "row_lengths"]


def row_lengths(chain) -> np.ndarray:
    """(n,) the largest length of each DH row's translation (m), over the joint's range."""
    out = []
    for (a, _, d, _, pris), (lo, hi) in zip(dh_rows(chain), chain.limits):
        dmax = max(abs(d + lo), abs(d + hi)) if pris else abs(d)
        out.append(math.hypot(a, dmax))
    return np.array(out)


def reach_radii(chain, geometry) -> np.ndarray:
    """R (n, n + 2): R[j, k] bounds |∂p/∂q_j| for every point p of body k's capsule segments, at
    every configuration (m/rad for a revolute joint j, 1 for a prismatic one; 0 when joint j does
    not move body k).

    Standard DH: joint j turns about z_{j-1} through frame j−1's origin, so the walk to frame k
    takes rows j … k.  Modified DH: joint j turns about z_j through frame j's origin: rows j+1 … k.
    The tool (body n + 1) is frame n plus the tool placement; its capsules are in the tool frame.
    """
    n = chain.n
    L = row_lengths(chain)
    tool_len = float(np.linalg.norm(chain.tool.matrix[:3, 3]))
    reach = np.zeros(n + 2)           # |p_k| bound per body
    for c in geometry.capsules:
        reach[c.body] = max(reach[c.body], c.reach)
    modified = chain.convention == "modified"
    R = np.zeros((n, n + 2))
    rev = chain.revolute_mask
    for j in range(1, n + 1):
        for k in range(j, n + 2):
            if not rev[j - 1]:
                R[j - 1, k] = 1.0
                continue
            last = min(k, n)
            first = j + 1 if modified else j
            walk = float(L[first - 1:last].sum()) if last >= first else 0.0
            if k == n + 1:
                walk += tool_len
            R[j - 1, k] = walk + reach[k]
    return R
