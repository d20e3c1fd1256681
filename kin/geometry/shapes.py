"""Collision shapes: the capsules a robot is made of, and the primitives and sphere sets of obstacles.

Everything is in SI units (m).  A robot's links are *capsules* — a segment ``a``–``b`` swept by a ball
of ``radius`` — fixed in one body's frame (a sphere is a capsule with ``a == b``): the clearance of a
capsule is the distance of its segment minus the radius, which is what makes the kernel fast and
the proofs of :mod:`planning.collision` simple.  Obstacles are primitives (sphere, capsule, box,
cylinder) placed by a 4×4 pose in the world, or sets of spheres (meshes and point clouds, enclosed
by :mod:`kin.geometry.enclose`).

Bodies are numbered ``0`` (the robot's base, fixed in DH frame 0), ``1 … n`` (body k moves with
joint k, fixed in DH frame k) and ``n + 1`` (the tool, fixed in frame n like body n but named apart
so a cell can let the tool touch the part it works on).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from kin.errors import GeometryError

__all__ = ["SHAPE_KINDS", "LinkCapsule", "LinkHull", "Shape", "Obstacle"]

#: obstacle primitive kinds and the meaning of their ``size``
SHAPE_KINDS = {
    "sphere": "(radius, 0, 0)",
    "capsule": "(radius, half_length, 0): the segment runs along the local z axis, ±half_length",
    "box": "(half_x, half_y, half_z)",
    "cylinder": "(radius, half_length, 0): axis along the local z axis, ±half_length",
}


def _vec3(v) -> tuple[float, float, float]:
    x = tuple(float(c) for c in v)
    if len(x) != 3:
        raise ValueError(f"expected three coordinates, got {len(x)}")
    return x  # type: ignore[return-value]


@dataclass(frozen=True)
class LinkCapsule:
    """A capsule fixed in body ``body``'s frame: segment ``a``–``b`` (m) and ``radius`` (m, ≥ 0).

    ``name`` says where it comes from (``"link 3"``, a URDF link's name, ``"tool"``) for messages.
    """

    body: int
    a: tuple[float, float, float]
    b: tuple[float, float, float]
    radius: float
    name: str = ""

    def __post_init__(self):
        object.__setattr__(self, "a", _vec3(self.a))
        object.__setattr__(self, "b", _vec3(self.b))
        object.__setattr__(self, "radius", float(self.radius))

    @property
    def length(self) -> float:
        return math.dist(self.a, self.b)

    @property
    def reach(self) -> float:
        """The largest distance of a segment point from the body frame's origin (m)."""
        return max(math.hypot(*self.a), math.hypot(*self.b))


@dataclass(frozen=True)
class LinkHull:
    """The convex hull of ``points`` (k, 3; m, in body ``body``'s frame) dilated by ``radius`` (m, ≥ 0:
    e.g. what rounding the points to a file's digits may have cut off) — a solid that holds the body's
    real shape.  ``name`` says where it comes from (a mesh's name) for messages; ``array`` is the points
    as a read-only (k, 3) array."""

    body: int
    points: tuple[tuple[float, float, float], ...]
    radius: float = 0.0
    name: str = ""
    array: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        P = np.array(self.points, dtype=float)
        if P.ndim != 2 or P.shape[1] != 3 or not len(P):
            raise ValueError(f"hull points have shape {P.shape}; expected (k, 3) with k ≥ 1")
        if not np.isfinite(P).all():
            raise ValueError("hull points must be finite")
        if not (math.isfinite(self.radius) and self.radius >= 0):
            raise ValueError(f"hull radius {self.radius!r} must be a finite number ≥ 0")
        P.setflags(write=False)
        object.__setattr__(self, "points", tuple(tuple(float(x) for x in p) for p in P))
        object.__setattr__(self, "array", P)
        object.__setattr__(self, "radius", float(self.radius))

    @property
    def reach(self) -> float:
        """The largest distance of a point of the hull from the body frame's origin (m)."""
        return float(np.sqrt((self.array ** 2).sum(axis=1)).max()) + self.radius


@dataclass(frozen=True)
class Shape:
    """An obstacle primitive: ``kind`` (a key of :data:`SHAPE_KINDS`), ``size`` (m, see there) and
    ``pose`` (4×4, the shape's frame in the world; the shape is centred on its frame's origin)."""

    kind: Literal["sphere", "capsule", "box", "cylinder"]
    size: tuple[float, float, float]
    pose: np.ndarray = field(default_factory=lambda: np.eye(4))

    def __post_init__(self):
        if self.kind not in SHAPE_KINDS:
            raise ValueError(f"shape kind {self.kind!r} unknown; allowed: {', '.join(SHAPE_KINDS)}")
        object.__setattr__(self, "size", _vec3(self.size))
        P = np.array(self.pose, dtype=float)
        if P.shape != (4, 4):
            raise ValueError(f"shape pose has shape {P.shape}; expected (4, 4)")
        P.setflags(write=False)
        object.__setattr__(self, "pose", P)

    @property
    def bounding_radius(self) -> float:
        """The radius of a ball about the shape's origin that holds the whole shape (m)."""
        r, h, z = self.size
        if self.kind == "sphere":
            return r
        if self.kind == "box":
            return math.sqrt(r * r + h * h + z * z)
        return math.hypot(r, h) if self.kind == "cylinder" else r + h


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A named obstacle of a work cell, in world coordinates (m).

    ``shapes``: primitives; ``spheres``: an (K, 4) array of x, y, z, radius (a mesh or point cloud
    enclosed by spheres); ``ignore``: bodies allowed to touch it (e.g. the tool against the part it
    welds); ``over_estimate``: how far the spheres may stand out of the geometry they enclose (m).
    """

    name: str
    shapes: tuple[Shape, ...] = ()
    spheres: np.ndarray | None = None
    ignore: frozenset[int] = frozenset()
    over_estimate: float = 0.0
    kind: str = ""          # what the cell file called it (box, mesh, point_cloud, …), for reports

    def __post_init__(self):
        object.__setattr__(self, "shapes", tuple(self.shapes))
        object.__setattr__(self, "ignore", frozenset(int(b) for b in self.ignore))
        if self.spheres is not None:
            S = np.ascontiguousarray(self.spheres, dtype=float)
            if S.ndim != 2 or S.shape[1] != 4:   # reshaping would silently regroup a (K, 3) array
                raise GeometryError(f"obstacle {self.name!r}: spheres have shape {S.shape}; expected (K, 4) "
                                    "x, y, z, radius")
            S.setflags(write=False)
            object.__setattr__(self, "spheres", S)

    @property
    def n_primitives(self) -> int:
        return len(self.shapes) + (0 if self.spheres is None else len(self.spheres))
