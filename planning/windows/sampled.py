"""Point-set windows: the neighbourhood of a singular component known only by samples (the
numeric analysis of :mod:`kin.singular.numeric`).

A :class:`PointSetWindow` holds points of the component in the coordinates of the joints the
component depends on (moving any other joint never leaves the set) and contains every
configuration whose distance to the nearest point, over those joints, is at most ``width`` (SI:
rad, m).  Nearest points come from a KD-tree (scipy, imported when a window first measures a
distance, so that loading and using other windows does not import it).  With ``normals`` (a
hypersurface), each point stands for the disc of its ``radius`` around it in the set's tangent
plane, and the distance is to the nearest disc (:func:`kin.singular.numeric.sampled_distance`).
The window is only as fine as its samples: ``detail["resolution"]`` is the estimated largest
distance from the set to its nearest sample, so the window holds at least the
(width − resolution)-neighbourhood of the set.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from planning.errors import WindowError
from planning.windows.base import WindowBase

if TYPE_CHECKING:
    from scipy.spatial import cKDTree

#: most points a window file may hold
MAX_POINTS = 1_000_000


@dataclass
class PointSetWindow(WindowBase):
    """A window around sampled points (SI units; the common fields are :class:`WindowBase`'s);
    ``points`` (K, len(joints)) over ``joints`` (1-based)."""

    points: np.ndarray
    detail: dict = field(default_factory=dict)
    normals: np.ndarray | None = None
    radius: np.ndarray | None = None
    _tree: cKDTree | None = field(default=None, repr=False, compare=False)

    is_point_set: ClassVar[bool] = True
    joint = None
    intervals = None
    epsilon = None

    @property
    def is_interval(self) -> bool:
        return False

    def __post_init__(self):
        self.joints = tuple(int(j) for j in self.joints)
        self.points = np.asarray(self.points, dtype=float).reshape(-1, len(self.joints))
        if not (math.isfinite(self.width) and self.width >= 0):
            raise WindowError(f"window {self.name!r}: width {self.width} must be a finite number ≥ 0 (rad or m)")
        if not self.joints or len(set(self.joints)) != len(self.joints) or \
                not all(1 <= j <= self.n for j in self.joints):
            raise WindowError(f"window {self.name!r}: joints {self.joints} must be distinct joints 1…{self.n}")
        if not np.all(np.isfinite(self.points)):
            raise WindowError(f"window {self.name!r}: points must be finite numbers")
        if (self.normals is None) != (self.radius is None):
            raise WindowError(f"window {self.name!r}: normals and radius go together (both or neither)")
        if self.radius is not None:
            self.radius = np.asarray(self.radius, dtype=float).reshape(-1)
            if self.radius.shape != (len(self.points),) or not np.all(np.isfinite(self.radius) & (self.radius >= 0)):
                raise WindowError(f"window {self.name!r}: radius must hold one finite number ≥ 0 per point")
        if self.normals is not None:
            self.normals = np.asarray(self.normals, dtype=float)
            norm = np.linalg.norm(self.normals, axis=1) if self.normals.ndim == 2 else None
            if self.normals.shape != self.points.shape or not np.all(np.abs(norm - 1) < 1e-6):
                raise WindowError(f"window {self.name!r}: normals must be unit vectors, one per point")

    @property
    def tree(self) -> cKDTree:
        """The KD-tree of ``points`` (built, and scipy.spatial imported, on first use)."""
        if self._tree is None:
            from scipy.spatial import cKDTree
            self._tree = cKDTree(self.points)
        return self._tree

    def _batch(self, Q) -> tuple[np.ndarray, bool]:
        arr = np.asarray(Q, dtype=float)
        if arr.shape[-1:] != (self.n,) or arr.ndim not in (1, 2):
            raise WindowError(f"window {self.name!r}: configurations must have shape ({self.n},) or (N, {self.n}); "
                              f"got {arr.shape}")
        return arr.reshape(-1, self.n), arr.ndim == 1

    def distance(self, Q) -> np.ndarray:
        """Distance (N,) over the window's joints to the nearest point; inf without points."""
        Q2, _ = self._batch(Q)
        if len(self.points) == 0:
            return np.full(len(Q2), np.inf)
        from kin.singular.numeric import sampled_distance  # the numeric analysis: only when used
        return sampled_distance(self.tree, self.normals, self.radius, Q2[:, [j - 1 for j in self.joints]])

    def contains(self, Q) -> np.ndarray:
        """Boolean (N,) — or a bool for one configuration — True within ``width`` of a point."""
        _, single = self._batch(Q)
        inside = self.distance(Q) <= self.width
        return bool(inside[0]) if single else inside

    def distance_out(self, Q) -> np.ndarray:
        """Signed margin (N,): distance − width (> 0 outside, ≤ 0 inside), joint units."""
        return self.distance(Q) - self.width

    def excess(self, q) -> float:
        """max(distance − width, 0) for one configuration: 0 exactly when inside."""
        return max(float(self.distance_out(np.asarray(q, dtype=float)[None])[0]), 0.0)

    def margin_and_gradient(self, q, h: float = 1e-7) -> tuple[float, np.ndarray]:
        """(distance − width, its gradient over ``joints`` by central differences) at one configuration (n,)."""
        q = np.asarray(q, dtype=float)
        if len(self.points) == 0:
            return math.inf, np.zeros(len(self.joints))
        cols = [j - 1 for j in self.joints]
        Q = np.repeat(q[None], 1 + 2 * len(cols), axis=0)
        for a, j in enumerate(cols):
            Q[1 + 2 * a, j] += h
            Q[2 + 2 * a, j] -= h
        d = self.distance(Q)
        return float(d[0]) - self.width, (d[1::2] - d[2::2]) / (2 * h)

    def to_dict(self) -> dict:
        return {"name": self.name, "kind": self.kind, "expr": self.expr, "joints": list(self.joints),
                "width": self.width, "method": self.method, "detail": self.detail, "type": "points",
                "points": self.points.tolist(), "radius": None if self.radius is None else self.radius.tolist(),
                "normals": None if self.normals is None else self.normals.tolist()}

    @classmethod
    def from_dict(cls, d: dict, n: int, where: str = "windows") -> "PointSetWindow":
        """Read and check one window entry (as written by :meth:`to_dict`)."""
        try:
            joints = tuple(int(j) for j in d["joints"])
            pts = d["points"]
            if not isinstance(pts, list) or len(pts) > MAX_POINTS or not all(
                    isinstance(p, list) and len(p) == len(joints) for p in pts):
                raise ValueError(f"points must be a list of at most {MAX_POINTS} lists of {len(joints)} numbers")
            if any(isinstance(x, (bool, str)) for p in pts for x in p):
                raise ValueError("points must hold numbers")
            width, radius, normals = d["width"], d.get("radius"), d.get("normals")
            if isinstance(width, (bool, str)):
                raise ValueError("width must be a number")
            if radius is not None and not (isinstance(radius, list) and len(radius) == len(pts) and not any(
                    isinstance(x, (bool, str)) for x in radius)):
                raise ValueError("radius must be null or one number per point")
            if normals is not None and not (isinstance(normals, list) and len(normals) == len(pts) and all(
                    isinstance(p, list) and len(p) == len(joints) and not any(isinstance(x, (bool, str)) for x in p)
                    for p in normals)):
                raise ValueError("normals must be null or one list of numbers per point")
            return cls(name=str(d["name"]), kind=str(d["kind"]), expr=str(d["expr"]), joints=joints,
                       width=float(width), method=str(d["method"]), n=n,
                       points=np.array(pts, dtype=float).reshape(-1, len(joints)),
                       detail=dict(d.get("detail", {})),
                       radius=None if radius is None else np.array(radius, dtype=float),
                       normals=None if normals is None else np.array(normals, dtype=float).reshape(-1, len(joints)))
        except (KeyError, TypeError, ValueError) as e:
            raise WindowError(f"{where}: point-set window entry is incomplete or malformed ({e}); needs name, "
                              "kind, expr, joints, width, method and points") from None


def is_point_set_entry(d) -> bool:
    """Whether a window file entry describes a point-set window."""
    return isinstance(d, dict) and d.get("type") == "points"
