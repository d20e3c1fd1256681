"""Body frames in numpy: the 4×4 pose of every body (base, links, tool) for a batch of configurations.

The compiled clearance kernel computes the same frames in C; this module is what Python code uses to
place capsules for reports and messages, and the kernel's fallback when no compiler is available.
"""
from __future__ import annotations

import numpy as np

__all__ = ["body_frames", "dh_rows"]


def dh_rows(chain) -> np.ndarray:
    """(n, 5) array: a, alpha, d, theta (SI, parameters at their nominal values), prismatic flag."""
    D = chain.dh_table()
    return np.hstack([D, (~chain.revolute_mask).astype(float)[:, None]])


def body_frames(chain, Q, base: np.ndarray | None = None) -> np.ndarray:
    """Poses of bodies 0 … n + 1 in the world: (N, n + 2, 4, 4) for Q (N, n), SI.

    Body 0 is DH frame 0 (``base`` · the chain's base placement; ``base`` is where a cell puts the
    robot, identity by default), body k is DH frame k, body n + 1 is the tool frame (frame n · the
    chain's tool placement).
    """
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    N, n = Q.shape
    rows = dh_rows(chain)
    W = np.eye(4) if base is None else np.asarray(base, dtype=float)
    F = np.empty((N, n + 2, 4, 4))
    F[:, 0] = W @ chain.base.matrix
    modified = chain.convention == "modified"
    for k in range(n):
        a, alpha, d, theta, pris = rows[k]
        th = theta + (0.0 if pris else Q[:, k])
        dd = d + (Q[:, k] if pris else 0.0)
        th = np.broadcast_to(th, (N,))
        dd = np.broadcast_to(dd, (N,))
        ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(alpha), np.sin(alpha)
        A = np.zeros((N, 4, 4))
        A[:, 3, 3] = 1.0
        if modified:    # Rx(α)·Tx(a)·Rz(θ)·Tz(d)
            A[:, 0, 0], A[:, 0, 1], A[:, 0, 3] = ct, -st, a
            A[:, 1, 0], A[:, 1, 1], A[:, 1, 2], A[:, 1, 3] = st * ca, ct * ca, -sa, -sa * dd
            A[:, 2, 0], A[:, 2, 1], A[:, 2, 2], A[:, 2, 3] = st * sa, ct * sa, ca, ca * dd
        else:           # Rz(θ)·Tz(d)·Tx(a)·Rx(α)
            A[:, 0, 0], A[:, 0, 1], A[:, 0, 2], A[:, 0, 3] = ct, -st * ca, st * sa, a * ct
            A[:, 1, 0], A[:, 1, 1], A[:, 1, 2], A[:, 1, 3] = st, ct * ca, -ct * sa, a * st
            A[:, 2, 1], A[:, 2, 2], A[:, 2, 3] = sa, ca, dd
        F[:, k + 1] = F[:, k] @ A
    F[:, n + 1] = F[:, n] @ chain.tool.matrix
    return F
