"""Helpers of the cell tests (not a test module): covering checks in numpy."""
from __future__ import annotations

import numpy as np


def uncovered(points: np.ndarray, spheres: np.ndarray, chunk: int = 2000) -> np.ndarray:
    """The points (N, 3) that lie in none of the spheres (K, 4), exactly (no tolerance)."""
    out = []
    C, r2 = spheres[:, :3], spheres[:, 3] ** 2
    for s in range(0, len(points), chunk):
        P = points[s:s + chunk]
        d2 = ((P[:, None, :] - C[None]) ** 2).sum(axis=2)
        out.append(P[~(d2 <= r2[None]).any(axis=1)])
    return np.concatenate(out) if out else points[:0]


def in_balls(spheres: np.ndarray, per_sphere: int, rng) -> np.ndarray:
    """Random points inside every sphere (K, 4) — on their surfaces and throughout their volumes."""
    K = len(spheres)
    d = rng.normal(size=(K, per_sphere, 3))
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    t = rng.random((K, per_sphere, 1)) ** (1 / 3)
    t[:, : per_sphere // 2] = 1.0                           # half on the surface
    return (spheres[:, None, :3] + d * t * spheres[:, None, 3:]).reshape(-1, 3)
