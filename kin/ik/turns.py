"""Whole turns of revolute joints: :func:`nearest_turns` moves every revolute angle of a solution by
whole turns (2π) to the copy nearest a reference configuration inside the joint limits — the same
pose, the branch a user asked to be near."""
from __future__ import annotations

import math

import numpy as np

__all__ = ["nearest_turns"]

TWO_PI = 2 * math.pi


def nearest_turns(chain, q, ref) -> np.ndarray:
    """``q`` (n,) SI with each revolute angle replaced by its whole-turn copy q_j + 2πk nearest
    ``ref[j]`` among those within the joint's limits; a joint with no copy inside its limits, and
    every prismatic joint, keeps its value."""
    q = np.asarray(q, dtype=float).copy()
    ref = np.asarray(ref, dtype=float)
    for j in np.flatnonzero(chain.revolute_mask):
        lo, hi, x = float(chain.lower[j]), float(chain.upper[j]), float(q[j])
        if not (math.isfinite(x) and math.isfinite(float(ref[j]))):
            continue
        k_lo = math.ceil((lo - x) / TWO_PI - 1e-12)
        k_hi = math.floor((hi - x) / TWO_PI + 1e-12)
        if k_hi < k_lo:
            continue
        k = min(max(round((float(ref[j]) - x) / TWO_PI), k_lo), k_hi)
        q[j] = min(max(x + TWO_PI * k, lo), hi)
    return q
