"""The result of the path follower (:class:`FollowResult`) and the waypoint ranges spent inside
each window (:func:`window_ranges`).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = ["FollowResult", "window_ranges"]


@dataclass
class FollowResult:
    """Result of :func:`planning.follow.follow_path` (SI units).

    Arrays have one row per waypoint: ``q`` (N, n); ``t`` (N,) s; ``position_error`` (N,) m;
    ``orientation_error`` (N,) rad — the full rotation angle between achieved and target orientation;
    ``axis_error`` (N,) rad — the angle between the achieved and target tool z axes;
    ``joint_velocity`` (N, n) — (q_k − q_{k−1})/Δt (row 0 is zero), ``joint_speed`` its magnitude;
    ``in_window`` (N,) — index of the first window q_k is inside, −1 for none; ``forced`` (N,) —
    True where the step that ended at row k had to drop a window barrier (stage 2); ``sigma_min``
    (N,) — smallest singular value of the robot's task Jacobian.
    """

    mode: str
    t: np.ndarray
    q: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    axis_error: np.ndarray
    joint_velocity: np.ndarray
    joint_speed: np.ndarray
    in_window: np.ndarray
    forced: np.ndarray
    sigma_min: np.ndarray
    v_max: np.ndarray
    tolerance: tuple[float, float]
    qp_status: dict[str, int] = field(default_factory=dict)
    window_names: list[str] = field(default_factory=list)

    @property
    def peak_joint_speed(self) -> float:
        """Largest joint speed over the path (rad/s or m/s)."""
        return float(self.joint_speed.max()) if self.joint_speed.size else 0.0

    @property
    def max_tracking_error(self) -> float:
        """Largest position error (m)."""
        return float(self.position_error.max())

    @property
    def max_orientation_error(self) -> float:
        """Largest orientation error the mode tracks (rad): full angle (pose), tool-axis angle (axis),
        NaN for position mode (not tracked)."""
        if self.mode == "pose":
            return float(self.orientation_error.max())
        if self.mode == "axis":
            return float(self.axis_error.max())
        return math.nan

    @property
    def within_tolerance(self) -> bool:
        """Position error ≤ tolerance[0] at every waypoint and, unless position mode, the tracked
        orientation error ≤ tolerance[1]."""
        ok = self.max_tracking_error <= self.tolerance[0]
        return bool(ok and (self.mode == "position" or self.max_orientation_error <= self.tolerance[1]))

    @property
    def speed_ratio(self) -> float:
        """max_k,j |q̇_kj| / v_max_j (≤ 1 when the speed limits hold)."""
        return float((self.joint_speed / self.v_max[None, :]).max()) if self.joint_speed.size else 0.0

    def window_ranges(self) -> list[dict]:
        """Waypoint ranges inside each window: [{"window", "name", "ranges": [[first, last], ...],
        "waypoints"}] for the windows that were entered."""
        return window_ranges(self.in_window, self.window_names)

    def summary(self) -> dict:
        """Scalars and window ranges (JSON-friendly; NaN stays NaN)."""
        return {"mode": self.mode, "waypoints": int(len(self.t)), "duration_s": float(self.t[-1] - self.t[0]),
                "peak_joint_speed": self.peak_joint_speed, "speed_ratio": self.speed_ratio,
                "max_position_error_m": self.max_tracking_error,
                "max_orientation_error_rad": float(self.orientation_error.max()),
                "max_axis_error_rad": float(self.axis_error.max()),
                "tolerance": {"position_m": self.tolerance[0], "orientation_rad": self.tolerance[1]},
                "within_tolerance": self.within_tolerance, "forced_steps": int(self.forced.sum()),
                "min_sigma": float(self.sigma_min.min()), "qp_status": dict(self.qp_status),
                "windows_entered": self.window_ranges()}


def window_ranges(in_window: np.ndarray, names: Sequence[str] = ()) -> list[dict]:
    """Contiguous waypoint ranges [first, last] (inclusive) of each window index in ``in_window``."""
    out = []
    for w in sorted(set(int(x) for x in np.unique(in_window)) - {-1}):
        idx = np.flatnonzero(in_window == w)
        breaks = np.flatnonzero(np.diff(idx) > 1)
        starts = np.r_[idx[0], idx[breaks + 1]]
        ends = np.r_[idx[breaks], idx[-1]]
        out.append({"window": w, "name": names[w] if w < len(names) else str(w),
                    "ranges": [[int(a), int(b)] for a, b in zip(starts, ends)], "waypoints": int(len(idx))})
    return out
