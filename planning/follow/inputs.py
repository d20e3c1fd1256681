"""Inputs of the path followers (:func:`planning.follow.follow_path`,
:func:`planning.follow.resolved_rate.resolved_rate`): their task :data:`MODES`, the :class:`FollowError`
they raise for a bad request,
the joint-speed limits with their defaults (:data:`DEFAULT_V_MAX_REVOLUTE` = π rad/s,
:data:`DEFAULT_V_MAX_PRISMATIC` = 0.5 m/s, used where the robot file gives no ``max_velocity``), the
path as (poses (N, 4, 4), times (N,)) arrays, and the check of the start configuration.
"""
from __future__ import annotations

import math

import numpy as np

from kin.errors import ConfigurationError
from planning.errors import PlanningError

__all__ = ["FollowError", "MODES", "DEFAULT_V_MAX_REVOLUTE", "DEFAULT_V_MAX_PRISMATIC", "joint_velocity_limits"]

#: the task modes of both followers: position and full orientation (6 DOF), position and the tool z
#: axis (5 DOF), the tool point only (3 DOF)
MODES = ("pose", "axis", "position")

DEFAULT_V_MAX_REVOLUTE = math.pi     # rad/s, used when a revolute joint has no max_velocity
DEFAULT_V_MAX_PRISMATIC = 0.5        # m/s, used when a prismatic joint has no max_velocity


class FollowError(PlanningError, ValueError):
    """A path-following request is invalid (bad path, start, limits or settings)."""


def joint_velocity_limits(robot, v_max=None) -> np.ndarray:
    """Per-joint speed limits (n,), SI.  ``v_max``: None (the robot file's ``max_velocity``, or the
    defaults :data:`DEFAULT_V_MAX_REVOLUTE` / :data:`DEFAULT_V_MAX_PRISMATIC` where it gives none),
    a scalar for every joint, or an array (n,)."""
    n = robot.n
    if v_max is None:
        return np.array([j.max_velocity if j.max_velocity is not None else
                         (DEFAULT_V_MAX_REVOLUTE if j.is_revolute else DEFAULT_V_MAX_PRISMATIC)
                         for j in robot.chain.joints], dtype=float)
    v = np.broadcast_to(np.asarray(v_max, dtype=float), (n,)) if np.ndim(v_max) == 0 else np.asarray(v_max, float)
    if v.shape != (n,) or not np.all(np.isfinite(v)) or not np.all(v > 0):
        raise FollowError(f"v_max {v_max!r} must be a positive finite number or {n} of them (rad/s, m/s)")
    return v.astype(float).copy()


def _check_mode(mode) -> str:
    if mode not in MODES:
        raise FollowError(f"mode {mode!r} unknown; allowed: {', '.join(MODES)}")
    return mode


def _path_arrays(path, dt: float | None, mode: str) -> tuple[np.ndarray, np.ndarray]:
    """(poses (N, 4, 4), times (N,)) from an array of poses (or positions in position mode), a
    ``(poses, times)`` pair, or an object with ``poses`` and ``times`` attributes."""
    times = None
    if hasattr(path, "poses"):
        poses = path.poses
        times = getattr(path, "times", None)
        if times is None:
            times = getattr(path, "t", None)
    elif isinstance(path, tuple) and len(path) == 2:
        poses, times = path
    else:
        poses = path
    P = np.asarray(poses, dtype=float)
    if P.ndim == 2 and P.shape[1] == 3:
        if mode != "position":
            raise FollowError(f"a path of positions (N, 3) can only be followed in mode 'position', not {mode!r}")
        T = np.tile(np.eye(4), (len(P), 1, 1))
        T[:, :3, 3] = P
        P = T
    if P.ndim != 3 or P.shape[1:] != (4, 4) or len(P) < 2:
        raise FollowError(f"path poses have shape {np.shape(poses)}; expected (N, 4, 4) with N ≥ 2 "
                          "(or positions (N, 3) in position mode)")
    if not np.all(np.isfinite(P)):
        raise FollowError("path poses hold NaN or infinite values")
    if times is None:
        if dt is None or not (math.isfinite(dt) and dt > 0):
            raise FollowError(f"dt = {dt!r}: a path without times needs a positive finite step dt (s)")
        t = np.arange(len(P)) * float(dt)
    else:
        t = np.asarray(times, dtype=float)
        if t.shape != (len(P),) or not np.all(np.isfinite(t)) or not np.all(np.diff(t) > 0):
            raise FollowError(f"path times have shape {t.shape} for {len(P)} poses; they must be finite and "
                              "strictly increasing (s)")
    return P, t


def _check_start(robot, q0) -> np.ndarray:
    q = np.asarray(q0, dtype=float)
    if q.shape != (robot.n,) or not np.all(np.isfinite(q)):
        raise ConfigurationError(f"q0 has shape {q.shape} or non-finite values; expected ({robot.n},) finite "
                                 f"for {robot.name}")
    robot.check_limits(q)
    return q.copy()
