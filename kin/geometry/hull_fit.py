"""A convex hull with few points that still holds a mesh: :func:`thin_hull`.

A collision mesh's hull may have hundreds of corners (a joint housing's round rim).  The hull of a
subset S of them, dilated by ρ, holds the whole hull when every dropped corner lies within ρ of
hull(S).  :func:`thin_hull` grows S greedily — the extreme points along the axes first, then the
corner farthest outside hull(S) (measured against its facet planes, which never overstate the
distance) — until every corner is within ρ of hull(S) by the certified distances of
:mod:`kin.geometry.convex`.  Rounding the kept points to ``decimals`` (a robot file's digits) moves
them by at most √3/2·10^−decimals, which the returned radius adds.
"""
from __future__ import annotations

import math

import numpy as np

from kin.geometry.convex import convex_distance, points_solid

__all__ = ["thin_hull"]


def thin_hull(points, rho: float, decimals: int | None = None) -> tuple[np.ndarray, float]:
    """(kept points (k, 3), radius): the hull of the kept points dilated by the radius holds every
    point of ``points`` (m); ``rho`` > 0 the dilation allowed for dropping points (m); ``decimals``
    rounds the kept points (the radius grows by the rounding)."""
    from scipy.spatial import ConvexHull, QhullError

    P = np.unique(np.asarray(points, dtype=float).reshape(-1, 3), axis=0)
    if len(P) < 4:
        out = P if decimals is None else np.round(P, decimals)
        return out, float(np.linalg.norm(out - P, axis=1).max()) if len(P) else 0.0
    idx = sorted({int(np.argmax(P[:, a] * s)) for a in range(3) for s in (1.0, -1.0)})
    while True:
        try:
            H = ConvexHull(P[idx])
        except (QhullError, ValueError):               # flat so far: add the point farthest from the rest
            d = np.linalg.norm(P[:, None] - P[idx][None], axis=2).min(axis=1)
            if d.max() == 0:
                break
            idx.append(int(np.argmax(d)))
            continue
        outside = (P @ H.equations[:, :3].T + H.equations[:, 3]).max(axis=1)
        j = int(np.argmax(outside))
        if outside[j] > 0.9 * rho:
            idx.append(j)
            continue
        S = points_solid(P[idx])
        d = np.array([convex_distance(points_solid(p[None]), S) for p in P])
        j = int(np.argmax(d))
        if d[j] <= rho - 1e-9:
            break
        idx.append(j)
    kept = P[sorted(idx)]
    radius = rho
    if decimals is not None:
        radius += math.sqrt(3) / 2 * 10.0 ** (-decimals)
        kept = np.round(kept, decimals)
    return kept, radius
