"""Per-joint speed and acceleration limits of a timed trajectory: the validation of the limits given
to :func:`planning.timing.time_parameterize` and :func:`check_limits`, and the check of a trajectory
against them (:func:`check_limits`, :class:`LimitCheck`).

SI units throughout: rad/s, rad/s² for revolute joints, m/s, m/s² for prismatic ones.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planning.timing.trajectory import TimedTrajectory, TimingError

__all__ = ["check_limits", "LimitCheck", "dense_ratios", "dense_times", "LIMIT_RANGE", "limit_out_of_range"]

#: the allowed range of every speed, acceleration, jerk and torque limit a user gives — ``rmt time``'s
#: ``--v-max``/``--a-max``/``--j-max``/``--tau-max`` and a task's ``[cycle]`` ``v_max``/``a_max``/``tau_max``
#: — in the file's units (angle or length unit per s, s², s³; N·m or N): finite, and wide enough for any
#: machine while v², a·s and their quotients stay far from floating-point underflow and overflow
#: (1e-300 would make v² vanish, 1e308 overflow)
LIMIT_RANGE = (1e-6, 1e7)


def limit_out_of_range(values) -> int | None:
    """Index of the first value outside :data:`LIMIT_RANGE` (or not finite), None when all are inside."""
    lo, hi = LIMIT_RANGE
    for k, x in enumerate(np.atleast_1d(np.asarray(values, dtype=float))):
        if not (lo <= x <= hi):
            return k
    return None


@dataclass(frozen=True)
class LimitCheck:
    """Result of :func:`check_limits`: ratios to the limits (≤ 1 holds), at the samples (analytic
    q̇, q̈) and from finite differences of the sampled q over t."""

    ok: bool
    velocity_ratio: float
    acceleration_ratio: float
    fd_velocity_ratio: float
    fd_acceleration_ratio: float
    tol: float


def _limits(x, n: int, name: str) -> np.ndarray:
    arr = np.asarray(x, dtype=float)
    v = np.full(n, float(arr)) if arr.ndim == 0 else arr
    if v.shape != (n,) or not np.all(np.isfinite(v)) or not np.all(v > 0):
        raise TimingError(f"{name} {x!r} must be a positive finite number or {n} of them "
                          f"({'rad/s or m/s' if name == 'v_max' else 'rad/s² or m/s²'})")
    return v.astype(float)


def check_limits(traj: TimedTrajectory, v_max, a_max, tol: float = 1e-3) -> LimitCheck:
    """Check a trajectory against speed and acceleration limits, within a relative ``tol``.

    Checked: the analytic q̇, q̈ at the samples, and finite differences of the sampled q over t —
    (q_{i+1} − q_i)/Δt_i for the speed, the second divided difference
    2·(v_i − v_{i−1})/(Δt_{i−1} + Δt_i) for the acceleration (it is a positively weighted average of
    q̈ over the two intervals, so it stays within the limit when q̈ does).  ``ok`` when every ratio is
    ≤ 1 + tol.
    """
    n = traj.q.shape[1]
    vmax = _limits(v_max, n, "v_max")
    amax = _limits(a_max, n, "a_max")
    if not (math.isfinite(tol) and tol >= 0):
        raise TimingError(f"tol = {tol!r} must be a finite number ≥ 0 (relative)")
    vr = float(np.max(np.abs(traj.qd) / vmax)) if len(traj.t) else 0.0
    ar = float(np.max(np.abs(traj.qdd) / amax)) if len(traj.t) else 0.0
    fvr = far = 0.0
    if len(traj.t) > 1:
        dt = np.diff(traj.t)
        v = np.diff(traj.q, axis=0) / dt[:, None]
        fvr = float(np.max(np.abs(v) / vmax))
        if len(traj.t) > 2:
            acc = 2 * np.diff(v, axis=0) / (dt[:-1] + dt[1:])[:, None]
            far = float(np.max(np.abs(acc) / amax))
    ok = max(vr, ar, fvr, far) <= 1.0 + tol
    return LimitCheck(bool(ok), vr, ar, fvr, far, float(tol))


def dense_times(t: np.ndarray, per_interval: int) -> np.ndarray:
    """``per_interval`` times in every interval [t_k, t_{k+1}) of ``t`` (K,), the last a hair before
    t_{k+1} (the interval's own end, where q̈ may jump), plus the final time."""
    if len(t) < 2:
        return np.asarray(t, dtype=float).copy()
    u = np.linspace(0.0, 1.0, per_interval + 1)[1:]
    u = np.r_[0.0, u[:-1], 1.0 - 1e-9]
    dt = np.diff(t)
    return np.r_[(t[:-1, None] + dt[:, None] * u[None, :]).ravel(), t[-1]]


def dense_ratios(traj: TimedTrajectory, v_max, a_max, per_interval: int = 8) -> tuple[float, float]:
    """Largest |q̇_j|/v_j and |q̈_j|/A_j over ``per_interval`` + 1 times in every interval between the
    trajectory's samples (both ends included), from the exact s(t) (:meth:`TimedTrajectory.sample`):
    the re-check between grid points."""
    n = traj.q.shape[1]
    vmax = _limits(v_max, n, "v_max")
    amax = _limits(a_max, n, "a_max")
    if not (isinstance(per_interval, int) and 1 <= per_interval <= 10_000):
        raise TimingError(f"per_interval = {per_interval!r} must be an integer in [1, 10000]")
    _, qd, qdd = traj.sample(dense_times(traj.t, per_interval))
    return float(np.max(np.abs(qd) / vmax)), float(np.max(np.abs(qdd) / amax))
