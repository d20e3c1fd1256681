"""coal, the tests' reference collision library: the shapes and distances rmtkit's are compared with,
in one place.  Import after ``pytest.importorskip("coal")`` (coal is imported here when a function runs)."""
from __future__ import annotations

import numpy as np

__all__ = ["hull", "frame_along", "capsule", "distance", "placed_distance", "transform"]


def transform(T: np.ndarray):
    """A 4×4 pose as coal's Transform3s."""
    import coal
    T = np.asarray(T, dtype=float)
    return coal.Transform3s(T[:3, :3], T[:3, 3])


def hull(points):
    """The convex hull of points (k ≥ 4, 3) as a coal Convex."""
    import coal
    vs = coal.StdVec_Vec3s()
    for p in points:
        vs.append(np.asarray(p, dtype=float))
    return coal.Convex.convexHull(vs, False, None)


def frame_along(a, b) -> np.ndarray:
    """A frame at the midpoint of a–b with z along it (coal's capsules and cylinders lie along z)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    T = np.eye(4)
    T[:3, 3] = (a + b) / 2
    n = np.linalg.norm(b - a)
    if n > 0:
        z = (b - a) / n
        x = np.cross(z, [1.0, 0, 0] if abs(z[0]) < 0.9 else [0, 1.0, 0])
        x /= np.linalg.norm(x)
        T[:3, 0], T[:3, 1], T[:3, 2] = x, np.cross(z, x), z
    return T


def capsule(a, b, r: float):
    """The capsule of segment a–b (world points) and radius r as a coal CollisionObject (a sphere when
    a = b)."""
    import coal
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    L = float(np.linalg.norm(b - a))
    if L == 0:
        return coal.CollisionObject(coal.Sphere(r), transform(frame_along(a, a)))
    return coal.CollisionObject(coal.Capsule(r, L), transform(frame_along(a, b)))


def distance(o1, o2) -> float:
    """The signed distance between two CollisionObjects (negative: how deep they overlap)."""
    import coal
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    req.enable_signed_distance = True
    coal.distance(o1, o2, req, res)
    return res.min_distance


def placed_distance(g1, T1, g2, T2) -> float:
    """coal's distance between geometries ``g1``, ``g2`` placed by 4×4 ``T1``, ``T2`` (its default
    request)."""
    import coal
    return coal.distance(g1, transform(T1), g2, transform(T2), coal.DistanceRequest(), coal.DistanceResult())
