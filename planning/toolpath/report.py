"""The result of a tool-path validation: :class:`ToolPathReport` (per-waypoint arrays, the verdict,
a JSON-ready summary) and the :class:`Problem` it names, of one of the :data:`KINDS`.

Built by :func:`planning.toolpath.check.validate_toolpath`.  Nothing here prints.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kin.errors import ArgumentError
from planning.toolpath.model import ToolPath
from planning.windows import WindowSet

__all__ = ["ToolPathReport", "Problem", "KINDS"]

#: problem kinds, in the order they rank at one waypoint
KINDS = ("unreachable", "branch_jump", "limits", "window", "sigma_min", "speed", "collision")


@dataclass(frozen=True)
class Problem:
    """A problem at waypoint ``index``: its ``kind`` (one of :data:`KINDS`), a text, and where it is
    on the path — arc length ``s`` (m) and time ``t`` (s, or None without timing)."""

    index: int
    kind: str
    detail: str
    s: float
    t: float | None
    origin: str = ""
    #: True: the problem is on the joint motion from waypoint ``index`` to ``index + 1`` (arc length
    #: ``s`` to ``s_end``), not at a waypoint
    segment: bool = False
    s_end: float | None = None

    def to_dict(self) -> dict:
        return {"index": self.index, "kind": self.kind, "detail": self.detail, "s": self.s, "t": self.t,
                "origin": self.origin,
                "segment": [self.index, self.index + 1] if self.segment else None}

    def where(self, total: int | None = None) -> str:
        """``waypoint i [of N] (s = …, t = …, line/segment …)``, or ``the segment from waypoint i to
        i + 1 [of N] (s = … to … m, …)``."""
        s = f"s = {self.s:.6g} m" if not self.segment else f"s = {self.s:.6g} to {self.s_end:.6g} m"
        parts = [s] + ([] if self.t is None else [f"t = {self.t:.6g} s"])
        parts += [self.origin] if self.origin else []
        of = "" if total is None else f" of {total}"
        if self.segment:
            return f"the segment from waypoint {self.index} to {self.index + 1}{of} ({', '.join(parts)})"
        return f"waypoint {self.index}{of} ({', '.join(parts)})"


@dataclass
class ToolPathReport:
    """Result of :func:`validate_toolpath`.  Arrays have one row per waypoint (N); SI units.

    q (N, n) joint solution; reachable (N,) bool; position_error (N,) m; orientation_error (N,) rad
    (0 in position mode); limit_margin (N,) min over joints of the distance to the nearer limit (rad
    or m; < 0 outside); sigma_min, manipulability (N,) of the task Jacobian; window (N,) index into
    ``window_names`` (−1: none); joint_speed (N, n) rad/s or m/s (NaN without timing or next to an
    unreachable waypoint); speed_ratio (N,) max over joints of |q̇|/max speed (NaN when no joint
    has one); joint_step (N,) largest |Δq| from the previous reachable waypoint; flags: kind →
    (N,) bool where that problem occurs.
    """

    robot: str
    source: str
    mode: str
    s: np.ndarray
    t: np.ndarray | None
    q: np.ndarray
    reachable: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    limit_margin: np.ndarray
    sigma_min: np.ndarray
    manipulability: np.ndarray
    window: np.ndarray
    window_names: list[str]
    joint_speed: np.ndarray
    speed_ratio: np.ndarray
    joint_step: np.ndarray
    flags: dict[str, np.ndarray]
    first_problem: Problem | None
    thresholds: dict
    elapsed_s: float
    stats: dict = field(default_factory=dict)
    windows: WindowSet | None = field(default=None, repr=False)
    toolpath: ToolPath | None = field(default=None, repr=False)
    clearance: np.ndarray | None = None      # (N,) m per waypoint (NaN: unreachable); None without a work cell
    collision_check: str | None = None       # "proven" / "sampled" between waypoints; None without a work cell
    #: problems of the joint motions between consecutive waypoints (planning.toolpath.between), by segment
    segment_problems: list = field(default_factory=list)
    segments_check: str | None = None        # how windows and floor were decided between waypoints; None: unchecked

    # ---- summary ------------------------------------------------------------------------------
    @property
    def ok(self) -> bool:
        """True when no waypoint has a problem."""
        return self.first_problem is None

    @property
    def n_waypoints(self) -> int:
        return len(self.s)

    @property
    def counts(self) -> dict[str, int]:
        """Waypoints with each kind of problem."""
        return {k: int(self.flags[k].sum()) for k in KINDS}

    @property
    def segment_counts(self) -> dict[str, int]:
        """Segments (between consecutive waypoints) with each kind of problem."""
        from planning.toolpath.between import SEGMENT_KINDS
        return {k: sum(p.kind == k for p in self.segment_problems) for k in SEGMENT_KINDS}

    def window_name(self, i: int) -> str | None:
        """Name of the window waypoint ``i`` is in, or None."""
        w = int(self.window[i])
        return None if w < 0 else self.window_names[w]

    def problems(self, kind: str | None = None) -> np.ndarray:
        """Indices of the waypoints with a problem (of ``kind``, or of any kind)."""
        if kind is None:
            m = np.zeros(self.n_waypoints, bool)
            for k in KINDS:
                m |= self.flags[k]
            return np.nonzero(m)[0]
        if kind not in KINDS:
            raise ArgumentError(f"problem kind {kind!r} unknown; allowed: {', '.join(KINDS)}")
        return np.nonzero(self.flags[kind])[0]

    def _min(self, a: np.ndarray) -> tuple[float | None, int | None]:
        v = np.where(self.reachable & np.isfinite(a), a, np.inf)
        if not np.isfinite(v).any():
            return None, None
        i = int(np.argmin(v))
        return float(v[i]), i

    def verdict(self) -> str:
        """One line: VALID, or INVALID with the first problem, its kind and where it is."""
        N = self.n_waypoints
        if self.ok:
            sig, i = self._min(self.sigma_min)
            extra = "" if sig is None else f"; min σ_min {sig:.3g} at waypoint {i}"
            return f"VALID: all {N} waypoints reachable, no problem found{extra}"
        p = self.first_problem
        others = ", ".join(f"{k} {c}" for k, c in self.counts.items() if c)
        segs = ", ".join(f"{k} {c}" for k, c in self.segment_counts.items() if c)
        tally = "; ".join(([f"waypoints with problems: {others}"] if others else [])
                          + ([f"segments with problems: {segs}"] if segs else []))
        return f"INVALID: first problem at {p.where(N)}: {p.kind} — {p.detail} [{tally}]"

    def summary(self) -> dict:
        """JSON-ready summary (SI units; non-finite numbers as None)."""
        sig, isig = self._min(self.sigma_min)
        man, iman = self._min(self.manipulability)
        lim, ilim = self._min(self.limit_margin)
        reach = self.reachable
        sr = self.speed_ratio[np.isfinite(self.speed_ratio)]
        qd = self.joint_speed[np.isfinite(self.joint_speed).all(axis=1)] if self.joint_speed.size else self.joint_speed
        return _clean({
            "valid": self.ok, "first_problem": None if self.first_problem is None else self.first_problem.to_dict(),
            "verdict": self.verdict(), "robot": self.robot, "source": self.source, "mode": self.mode,
            "waypoints": self.n_waypoints, "reachable": int(reach.sum()),
            "length": float(self.s[-1]), "duration": None if self.t is None else float(self.t[-1]),
            "counts": self.counts,
            "segment_counts": self.segment_counts, "segments_check": self.segments_check,
            "segment_problems": [{"segment": [p.index, p.index + 1], "kind": p.kind, "detail": p.detail,
                                  "check": p.check} for p in self.segment_problems],
            "min_sigma": sig, "min_sigma_index": isig, "min_manipulability": man, "min_manipulability_index": iman,
            "min_limit_margin": lim, "min_limit_margin_index": ilim,
            "max_position_error": float(self.position_error[reach].max()) if reach.any() else None,
            "max_orientation_error": float(self.orientation_error[reach].max()) if reach.any() else None,
            "max_joint_step": float(np.nanmax(self.joint_step)) if np.isfinite(self.joint_step).any() else None,
            "max_joint_speed": np.abs(qd).max(axis=0).tolist() if len(qd) else None,
            "max_speed_ratio": float(sr.max()) if len(sr) else None,
            "min_clearance": None if self.clearance is None else self._min(self.clearance)[0],
            "min_clearance_index": None if self.clearance is None else self._min(self.clearance)[1],
            "collision_check": self.collision_check,
            "windows": list(self.window_names),
            "waypoints_in_windows": int((self.window >= 0).sum()),
            "thresholds": self.thresholds, "elapsed_s": self.elapsed_s, "stats": self.stats,
            "units": "SI (m, rad, s)",
        })

    def to_dict(self, waypoints: bool = False) -> dict:
        """The :meth:`summary`, plus the per-waypoint arrays when ``waypoints`` is True (JSON-ready)."""
        d = self.summary()
        if waypoints:
            d["per_waypoint"] = _clean({
                "s": self.s, "t": self.t, "q": self.q, "reachable": self.reachable,
                "position_error": self.position_error, "orientation_error": self.orientation_error,
                "limit_margin": self.limit_margin, "sigma_min": self.sigma_min,
                "manipulability": self.manipulability, "window": self.window,
                "joint_speed": self.joint_speed, "speed_ratio": self.speed_ratio, "joint_step": self.joint_step,
                "clearance": self.clearance,
                "flags": {k: v for k, v in self.flags.items()}})
        return d


def _clean(obj):
    """numpy → plain Python, NaN/inf → None (strict JSON)."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        if obj.dtype == bool:
            return obj.tolist()
        if np.issubdtype(obj.dtype, np.integer):
            return obj.tolist()
        return _clean(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        return x if math.isfinite(x) else None
    return obj
