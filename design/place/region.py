"""Where a robot may stand: the placement region of a placement search.

A placement is the robot's base pose in the cell, u = (x, y, z, roll, pitch, yaw) (m, rad;
R = Rz(yaw)·Ry(pitch)·Rx(roll), as everywhere in rmtkit).  The region bounds each coordinate; a
coordinate whose bounds are equal is fixed.  ``tilt`` (rad) bounds roll and pitch (0: the base
stays level).  ``keep_out`` lists floor rectangles (x_min, x_max, y_min, y_max) the base position
may not stand in (a fixture's footprint, a walkway); it is a constraint on the base's origin.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from design.task.model import TaskError
from kin.transforms import make_transform, rpy_to_matrix

__all__ = ["PlacementRegion", "COORDINATES", "placement_transform"]

COORDINATES = ("x", "y", "z", "roll", "pitch", "yaw")


def placement_transform(u) -> np.ndarray:
    """4×4 of a placement u = (x, y, z, roll, pitch, yaw) (m, rad)."""
    u = np.asarray(u, float)
    return make_transform(rpy_to_matrix(u[3:6]), u[:3])


def _interval(v, what: str, lo_ok: float = -1e4, hi_ok: float = 1e4) -> tuple[float, float]:
    try:
        a, b = (float(x) for x in v)
    except (TypeError, ValueError):
        raise TaskError(f"placement region {what} must be [low, high], got {v!r}") from None
    if not (math.isfinite(a) and math.isfinite(b)) or a > b or a < lo_ok or b > hi_ok:
        raise TaskError(f"placement region {what} = [{a:g}, {b:g}] must be finite with low ≤ high "
                        f"within [{lo_ok:g}, {hi_ok:g}]")
    return a, b


@dataclass(frozen=True)
class PlacementRegion:
    """Bounds of the placement (SI): x, y, z, yaw intervals; ``tilt`` the largest |roll|, |pitch|;
    ``keep_out`` floor rectangles (x_min, x_max, y_min, y_max) the base origin stays out of."""

    x: tuple[float, float]
    y: tuple[float, float]
    z: tuple[float, float] = (0.0, 0.0)
    yaw: tuple[float, float] = (-math.pi, math.pi)
    tilt: float = 0.0
    keep_out: tuple[tuple[float, float, float, float], ...] = ()

    def __post_init__(self):
        for name in ("x", "y", "z"):
            object.__setattr__(self, name, _interval(getattr(self, name), name))
        object.__setattr__(self, "yaw", _interval(self.yaw, "yaw (rad)", -2 * math.pi, 2 * math.pi))
        t = self.tilt
        if isinstance(t, bool) or not isinstance(t, (int, float, np.integer, np.floating)) or not 0 <= t <= math.pi / 2:
            raise TaskError(f"placement tilt = {t!r} must be a number in [0, π/2] rad")
        object.__setattr__(self, "tilt", float(t))
        boxes = []
        for i, r in enumerate(self.keep_out):
            try:
                x0, x1, y0, y1 = (float(v) for v in r)
            except (TypeError, ValueError):
                raise TaskError(f"placement keep_out[{i}] must be [x_min, x_max, y_min, y_max], got {r!r}") from None
            if not all(math.isfinite(v) for v in (x0, x1, y0, y1)) or x0 >= x1 or y0 >= y1:
                raise TaskError(f"placement keep_out[{i}] = {[x0, x1, y0, y1]} must be finite with min < max")
            boxes.append((x0, x1, y0, y1))
        object.__setattr__(self, "keep_out", tuple(boxes))
        if not np.any(self.free):
            raise TaskError("placement region fixes every coordinate; free at least one (low < high)")

    @property
    def bounds(self) -> np.ndarray:
        """(6, 2) bounds of x, y, z, roll, pitch, yaw."""
        t = self.tilt
        return np.array([self.x, self.y, self.z, (-t, t), (-t, t), self.yaw], float)

    @property
    def free(self) -> np.ndarray:
        """Which of the six coordinates vary (bool (6,))."""
        b = self.bounds
        return b[:, 1] > b[:, 0]

    def names(self) -> list[str]:
        return [c for c, f in zip(COORDINATES, self.free) if f]

    def full(self, v: np.ndarray) -> np.ndarray:
        """Free coordinates (…, k) → full placements (…, 6) (fixed coordinates at their value)."""
        v = np.asarray(v, float)
        out = np.broadcast_to(self.bounds[:, 0], v.shape[:-1] + (6,)).copy()
        out[..., self.free] = v
        return out

    def allowed(self, U: np.ndarray) -> np.ndarray:
        """Whether placements U (M, 6) keep their origin out of every keep-out rectangle (bool (M,))."""
        U = np.atleast_2d(U)
        ok = np.ones(len(U), bool)
        for x0, x1, y0, y1 in self.keep_out:
            ok &= ~((U[:, 0] > x0) & (U[:, 0] < x1) & (U[:, 1] > y0) & (U[:, 1] < y1))
        return ok

    def locate(self, u, tol: float = 1e-9) -> tuple[np.ndarray, str | None]:
        """A placement u (6,) as the region writes it (yaw moved by a full turn into the yaw range when
        that brings it in) and why it lies outside the region (None when inside): a coordinate out of
        its bounds, roll or pitch beyond the tilt, the origin in a keep-out rectangle."""
        u = np.array(u, float)
        lo, hi = self.yaw
        for k in (-1, 1):
            if not lo - tol <= u[5] <= hi + tol and lo - tol <= u[5] + 2 * k * math.pi <= hi + tol:
                u[5] += 2 * k * math.pi
        b = self.bounds
        for i, name in enumerate(COORDINATES):
            if not b[i, 0] - tol <= u[i] <= b[i, 1] + tol:
                what = "tilt" if name in ("roll", "pitch") else name
                return u, f"its {name} {u[i]:.6g} lies outside the region's {what} [{b[i, 0]:.6g}, {b[i, 1]:.6g}] (SI)"
        if not self.allowed(u[None])[0]:
            return u, "its origin stands in a keep-out rectangle"
        return u, None

    def to_dict(self) -> dict:
        return {"x": list(self.x), "y": list(self.y), "z": list(self.z), "yaw": list(self.yaw), "tilt": self.tilt,
                "keep_out": [list(r) for r in self.keep_out], "free": self.names()}

    @classmethod
    def around(cls, targets_positions: np.ndarray, reach: float, z: float = 0.0, tilt: float = 0.0,
               keep_out=()) -> "PlacementRegion":
        """A default region: the targets' x–y bounding box grown by the robot's reach, z fixed."""
        P = np.asarray(targets_positions, float)
        lo, hi = P.min(axis=0) - reach, P.max(axis=0) + reach
        return cls((lo[0], hi[0]), (lo[1], hi[1]), (z, z), tilt=tilt, keep_out=keep_out)

    @classmethod
    def default(cls, robot, targets_positions: np.ndarray, z: float = 0.0) -> "PlacementRegion":
        """The region a placement search uses when none is given: :meth:`around` the targets by the
        robot's reach, taken as its structural length Σ(|a_i| + |d_i|) (an upper bound), z fixed, any yaw."""
        from design.metrics import structural_length
        return cls.around(targets_positions, structural_length(robot.chain), z=z)
