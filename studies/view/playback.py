"""Path playback of ``rmt view``: a joint path (``rmt plan --out``: one configuration per row, robot file
units) or a timed trajectory (``rmt time --out``: columns t, q1 … qn, …) as a :class:`Timeline` — the
configuration at any point of the timeline slider, the swept tool trace, and σ_min, the clearance and
the windows along it for the plot under the timeline.

A path has no times: its timeline runs over its joint-space length (0 … 1, evenly spaced in arc
length, :func:`studies.jointpath.densify`) and plays at a steady pace; a trajectory's runs over its
times (s) and plays in real time (its rows interpolated linearly, as a controller streams them)."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studies.export.trajectory import TrajectoryFileError, read_trajectory
from studies.jointpath import outside_limits, read_path_csv

__all__ = ["Timeline", "TrajectoryFileError", "path_timeline", "trajectory_timeline",
           "PLOT_SAMPLES", "TRACE_POINTS", "PATH_SECONDS"]

#: the largest trajectory file read (as rmt check-path's joint paths)
#: samples of σ_min, clearance and windows plotted under the timeline
PLOT_SAMPLES = 400
#: points of the swept tool trace
TRACE_POINTS = 400
#: an untimed path plays over this many seconds
PATH_SECONDS = 8.0


@dataclass(frozen=True)
class Timeline:
    """``t`` (M,) increasing, ``Q`` (M, n; SI) the configuration at each; ``timed``: ``t`` is seconds
    (a trajectory, played in real time) — else the fraction of the path's joint-space length, played
    over :data:`PATH_SECONDS`; ``source`` the file."""

    t: np.ndarray
    Q: np.ndarray
    timed: bool
    source: str

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])

    @property
    def unit(self) -> str:
        return "s" if self.timed else "fraction of the path"

    def at(self, s: float) -> np.ndarray:
        """The configuration at timeline value ``s`` (clamped to the ends), linear between rows."""
        t, Q = self.t, self.Q
        if len(t) == 1 or s <= t[0]:
            return Q[0].copy()
        if s >= t[-1]:
            return Q[-1].copy()
        k = int(np.searchsorted(t, s, side="right")) - 1
        u = (s - t[k]) / (t[k + 1] - t[k])
        return (1 - u) * Q[k] + u * Q[k + 1]

    def samples(self, m: int) -> tuple[np.ndarray, np.ndarray]:
        """``m`` timeline values evenly spread over it and their configurations."""
        s = np.linspace(self.t[0], self.t[-1], m) if len(self.t) > 1 else self.t[:1]
        return s, np.array([self.at(v) for v in s])

    def playback_speed(self) -> float:
        """Timeline units per second of wall-clock time: 1 for a trajectory (real time)."""
        return 1.0 if self.timed else max(self.duration, 1e-12) / PATH_SECONDS

    def tool_trace(self, model, m: int = TRACE_POINTS) -> np.ndarray:
        """The tool frame's origin (m, world/cell frame) at ``m`` samples along the timeline."""
        from kin.geometry import body_frames
        _, Q = self.samples(m)          # a path's timeline is its arc length: evenly spaced along it
        F = body_frames(model.chain, Q, model.base)[:, -1]
        return F[:, :3, 3]


def path_timeline(robot, path: str | Path) -> Timeline:
    """A joint path CSV (what ``rmt plan --out`` writes) as a timeline over its arc length (0 … 1)."""
    P = read_path_csv(robot, path)
    if len(P) == 1:
        return Timeline(np.zeros(1), P, False, str(path))
    seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
    total = float(seg.sum())
    if total == 0:
        return Timeline(np.zeros(1), P[:1], False, str(path))
    t = np.concatenate([[0.0], np.cumsum(seg) / total])
    keep = np.concatenate([[True], seg > 0])            # repeated waypoints: one row each
    return Timeline(t[keep], P[keep], False, str(path))


def trajectory_timeline(robot, path: str | Path) -> Timeline:
    """A timed trajectory CSV as a timeline in seconds, its joint values checked against the limits."""
    traj = read_trajectory(robot, path)
    why = outside_limits(robot, traj.q, lambda i: f"{path}: data row {i + 1}")
    if why is not None:
        raise TrajectoryFileError(why)
    return Timeline(traj.t, traj.q, True, str(path))


def path_profile(model, timeline: Timeline, m: int = PLOT_SAMPLES) -> dict:
    """σ_min, clearance (m) and window membership at ``m`` timeline values: ``{"s": …, **profile}``."""
    s, Q = timeline.samples(m)
    return {"s": s, **model.profile(Q)}
