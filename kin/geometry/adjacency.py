"""Body pairs that touch in every configuration: never worth checking against each other.

Capsules along DH offsets overlap wherever links meet at a point — the two links on either side of
a spherical wrist touch at the wrist centre whatever the joints do — and a checker that tests such a
pair reports every configuration in collision.  Like MoveIt's setup assistant ("always in
collision"), :func:`always_touching_pairs` samples configurations and returns the non-adjacent
pairs whose capsules overlap in every one of them; a pair that is clear in even one sample is
checked.  "Overlap" allows for rounding: capsules closer than :data:`TOUCH` count as touching (a
torch mount at exactly the wrist's radius touches it in every configuration, to 1e-16 m).  The
samples are fixed (a seed and q = 0), so the answer depends only on the robot.
"""
from __future__ import annotations

import numpy as np

__all__ = ["always_touching_pairs", "SAMPLES", "TOUCH"]

#: capsules closer than this (m) touch
TOUCH = 1e-6
#: configurations sampled (uniform within the limits, seed 0), plus q = 0 clipped to the limits
SAMPLES = 256


def always_touching_pairs(chain, geometry, samples: int = SAMPLES) -> list[tuple[int, int]]:
    """The checked body pairs (i < j) of ``geometry`` whose capsules overlap in every sampled
    configuration of ``chain``."""
    from kin.geometry.clearance_numpy import seg_seg
    from kin.geometry.frames import body_frames
    pairs = geometry.checked_pairs(chain.n)
    if not pairs:
        return []
    rng = np.random.default_rng(0)
    Q = rng.uniform(chain.lower, chain.upper, size=(samples, chain.n))
    Q = np.vstack([np.clip(np.zeros(chain.n), chain.lower, chain.upper), Q])
    F = body_frames(chain, Q)                                   # (S, B, 4, 4)

    def ends(c):            # the capsule's segment in the world, per sample: start (S, 3), direction (S, 3)
        R, t = F[:, c.body, :3, :3], F[:, c.body, :3, 3]
        a = R @ np.array(c.a) + t
        return a, R @ np.array(c.b) + t - a

    caps = {}
    for c in geometry.capsules:
        caps.setdefault(c.body, []).append((c, *ends(c)))
    out = []
    for i, j in pairs:
        clear = np.full(len(Q), np.inf)
        for ci, ai, di in caps[i]:
            for cj, aj, dj in caps[j]:
                d, _, _ = seg_seg(ai, di, aj, dj)
                clear = np.minimum(clear, d - ci.radius - cj.radius)
        if (clear <= TOUCH).all():
            out.append((i, j))
    return out
