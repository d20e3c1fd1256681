"""A trajectory between its samples, and resampled at a fixed rate.

Between two samples k and k+1 (h = t[k+1] − t[k], u = (t − t[k]) / h ∈ [0, 1]) the trajectory is the
quartic in t with the first sample's q, q̇, q̈ and the second's q, q̇ (the q̈ of a sample holds from
it on; the next sample may start another, as the piecewise-constant s̈ of
:func:`planning.timing.time_parameterize` does)::

    q(u) = q0 + v0·h·u + a0·h²·u²/2 + C3·u³ + C4·u⁴
    C3 = 4·Δq − h·Δv,  C4 = h·Δv − 3·Δq,  Δq = q1 − q0 − v0·h − a0·h²/2,  Δv = v1 − v0 − a0·h

On a straight joint-space segment timed by rmt time (q linear in s, s quadratic in t) the quartic is
the trajectory itself (C3 = C4 = 0); on a blend it is the trajectory within rounding wherever an
interval lies on one piece of the path.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["evaluate", "resample_times", "MAX_SAMPLES"]

#: the most samples a resampled trajectory may have (33 minutes at 500 Hz)
MAX_SAMPLES = 1_000_000


def evaluate(traj, times) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, q̇, q̈ (T, n) of ``traj`` (a :class:`~studies.export.trajectory.Trajectory`) at ``times``
    (T,) s, clipped to [0, duration]; a time equal to a sample's gives that sample exactly."""
    tt = np.clip(np.atleast_1d(np.asarray(times, float)), traj.t[0], traj.t[-1])
    t, q, v, a = traj.t, traj.q, traj.qd, traj.qdd
    k = np.clip(np.searchsorted(t, tt, side="right") - 1, 0, len(t) - 2)
    h = (t[k + 1] - t[k])[:, None]
    u = ((tt - t[k])[:, None]) / h
    q0, v0, a0, q1, v1 = q[k], v[k], a[k], q[k + 1], v[k + 1]
    dq = q1 - q0 - v0 * h - 0.5 * a0 * h * h
    dv = v1 - v0 - a0 * h
    c3 = 4.0 * dq - h * dv
    c4 = h * dv - 3.0 * dq
    Q = q0 + u * (v0 * h + u * (0.5 * a0 * h * h + u * (c3 + u * c4)))
    V = v0 + u * (a0 * h + u * (3.0 * c3 + u * 4.0 * c4) / h)
    A = a0 + u * (6.0 * c3 + u * 12.0 * c4) / (h * h)
    end = tt >= t[-1]                      # the last sample itself, not the last quartic at u = 1
    Q[end], V[end], A[end] = q[-1], v[-1], a[-1]
    return Q, V, A


def resample_times(duration: float, rate: float) -> np.ndarray:
    """0, 1/rate, 2/rate, … and ``duration`` itself last (the final step may be shorter): the times of
    a stream at ``rate`` Hz.  Raises ValueError beyond :data:`MAX_SAMPLES`."""
    steps = math.ceil(duration * rate - 1e-9)
    if steps + 1 > MAX_SAMPLES:
        raise ValueError(f"{duration:g} s at {rate:g} Hz is {steps + 1} samples; at most {MAX_SAMPLES}")
    return np.minimum(np.arange(steps + 1) / rate, duration)
