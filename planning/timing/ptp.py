"""Point-to-point jerk-limited moves: :func:`ptp_move`, the time-optimal rest-to-rest move between two
joint positions under per-joint speed, acceleration and jerk limits, as a :class:`PTPTrajectory`.

One joint.  Moving a distance D from rest to rest with |q̇| ≤ v, |q̈| ≤ a, |q⃛| ≤ j, the fastest move is
the classic 7-segment S-curve: jerk +j, 0, −j (acceleration ramp up, hold, down) to a peak speed v_p,
a cruise at v_p, and the mirror image down to rest.  Reaching v_p takes T_a(v_p) = v_p/a + a/j when
v_p ≥ a²/j (the acceleration reaches a and holds), else 2·√(v_p/j) (a triangular acceleration of peak
√(v_p·j)), and covers v_p·T_a/2; so the duration is T(v_p) = T_a(v_p) + D/v_p, falling with v_p on the
profiles that fit (v_p·T_a(v_p) ≤ D).  The minimum time takes v_p = v when v·T_a(v) ≤ D (cruise),
else the v_p with v_p·T_a(v_p) = D (no cruise): v_p = (a/2)·(√(a²/j² + 4D/a) − a/j) when that is ≥ a²/j,
else (D·√j/2)^(2/3).

Several joints.  ``sync="time"``: every joint finishes with the slowest: each is re-profiled to the
common duration T by lowering its peak speed (the unique v_p with T(v_p) = T; a and j still at their
limits); rest to rest, every T ≥ the joint's minimum is reachable, so T is the largest minimum time —
what Ruckig's time synchronisation gives.  ``sync="phase"``: a straight line in joint space,
q = q0 + (q1 − q0)·u(t) with u the time-optimal S-curve over 1 under the tightest of the joints' limits
divided by |q1_j − q0_j| (never faster than time synchronisation).

SI units throughout: rad, rad/s, rad/s², rad/s³ for revolute joints, m, m/s, m/s², m/s³ for prismatic
ones.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from planning.timing.limits import _limits
from planning.timing.trajectory import TimingError

__all__ = ["ptp_move", "PTPTrajectory", "s_curve_time", "SYNCS"]

SYNCS = ("time", "phase")


def _ramp(vp: float, a: float, j: float) -> tuple[float, float]:
    """Time to reach speed vp from rest and the peak acceleration on the way."""
    if vp * j >= a * a:
        return vp / a + a / j, a
    return 2.0 * math.sqrt(vp / j), math.sqrt(vp * j)


def _peak_speed(D: float, v: float, a: float, j: float) -> float:
    """Peak speed of the minimum-time move over D ≥ 0 (module docstring)."""
    if v * _ramp(v, a, j)[0] <= D:
        return v
    vp = 0.5 * a * (math.sqrt((a / j) ** 2 + 4.0 * D / a) - a / j)
    return vp if vp * j >= a * a else (0.5 * D * math.sqrt(j)) ** (2.0 / 3.0)


def s_curve_time(D: float, v: float, a: float, j: float) -> float:
    """Minimum rest-to-rest time over a distance D ≥ 0 under |q̇| ≤ v, |q̈| ≤ a, |q⃛| ≤ j."""
    if D <= 0.0:
        return 0.0
    vp = _peak_speed(D, v, a, j)
    return _ramp(vp, a, j)[0] + D / vp


def _segments(D: float, v: float, a: float, j: float, T: float) -> tuple[np.ndarray, np.ndarray]:
    """Durations (7,) and jerks (7,) of the move over D ≥ 0 lasting T ≥ its minimum time."""
    if D <= 0.0:
        return np.r_[T, np.zeros(6)], np.zeros(7)
    vp = _peak_speed(D, v, a, j)
    if T > s_curve_time(D, v, a, j) * (1 + 1e-15):
        # T(vp) = T_a(vp) + D/vp falls from +inf (vp → 0) to the minimum time at the peak speed above;
        # it exceeds T at vp = D/T (T_a > 0)
        vp = brentq(lambda x: _ramp(x, a, j)[0] + D / x - T, D / T, vp, xtol=1e-15 * vp, rtol=1e-15)
    Ta, ap = _ramp(vp, a, j)
    t1, t2 = ap / j, max(vp / ap - ap / j, 0.0)
    cruise = max(T - 2.0 * Ta, 0.0)
    return np.array([t1, t2, t1, cruise, t1, t2, t1]), np.array([j, 0.0, -j, 0.0, -j, 0.0, j])


@dataclass
class PTPTrajectory:
    """A rest-to-rest move of piecewise-constant jerk per joint (SI).

    ``q0``, ``q1`` (n,): start and goal; ``duration`` s; ``sync``: ``"time"`` or ``"phase"``;
    ``v_max``, ``a_max``, ``j_max`` (n,): the limits; ``times`` (n, 8): the segment boundaries of each
    joint (0 … duration); ``jerk`` (n, 7): the jerk on each segment; ``min_times`` (n,): each joint's
    own minimum time."""

    q0: np.ndarray
    q1: np.ndarray
    duration: float
    sync: str
    v_max: np.ndarray
    a_max: np.ndarray
    j_max: np.ndarray
    times: np.ndarray
    jerk: np.ndarray
    min_times: np.ndarray

    def sample(self, times) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """q, q̇, q̈, q⃛ (T, n) at the given times (clipped to [0, duration]), exact (cubic pieces)."""
        tau = np.clip(np.atleast_1d(np.asarray(times, dtype=float)), 0.0, self.duration)
        n = len(self.q0)
        q = np.empty((len(tau), n))
        qd, qdd, jk = np.empty_like(q), np.empty_like(q), np.empty_like(q)
        for k in range(n):
            tb, J = self.times[k], self.jerk[k]
            # state at every segment start, integrated exactly
            p, vv, aa = [self.q0[k]], [0.0], [0.0]
            for i in range(7):
                h = tb[i + 1] - tb[i]
                p.append(p[-1] + vv[-1] * h + aa[-1] * h * h / 2 + J[i] * h ** 3 / 6)
                vv.append(vv[-1] + aa[-1] * h + J[i] * h * h / 2)
                aa.append(aa[-1] + J[i] * h)
            i = np.clip(np.searchsorted(tb, tau, side="right") - 1, 0, 6)
            h = tau - tb[i]
            P, V, A, Jk = np.array(p)[i], np.array(vv)[i], np.array(aa)[i], J[i]
            q[:, k] = P + V * h + A * h * h / 2 + Jk * h ** 3 / 6
            qd[:, k] = V + A * h + Jk * h * h / 2
            qdd[:, k] = A + Jk * h
            jk[:, k] = Jk
        return q, qd, qdd, jk


def ptp_move(q0, q1, v_max, a_max, j_max, sync: str = "time") -> PTPTrajectory:
    """The time-optimal rest-to-rest move from ``q0`` to ``q1`` ((n,) each) under per-joint limits
    (scalars or (n,), > 0), synchronised by ``sync`` (``"time"``: every joint finishes with the slowest;
    ``"phase"``: a straight line in joint space); see the module docstring.  Raises
    :class:`TimingError` for bad input."""
    if sync not in SYNCS:
        raise TimingError(f"sync = {sync!r} unknown; allowed: {', '.join(SYNCS)}")
    a0 = np.asarray(q0, dtype=float)
    a1 = np.asarray(q1, dtype=float)
    if a0.ndim != 1 or a0.shape != a1.shape or not (np.all(np.isfinite(a0)) and np.all(np.isfinite(a1))):
        raise TimingError(f"q0 and q1 must be two finite joint vectors of one length (got shapes {a0.shape}, "
                          f"{a1.shape})")
    n = len(a0)
    vmax, amax, jmax = (_limits(x, n, name) for x, name in ((v_max, "v_max"), (a_max, "a_max"), (j_max, "j_max")))
    delta = a1 - a0
    D = np.abs(delta)
    sign = np.where(delta < 0, -1.0, 1.0)
    tmin = np.array([s_curve_time(D[k], vmax[k], amax[k], jmax[k]) for k in range(n)])
    times, jerk = np.zeros((n, 8)), np.zeros((n, 7))
    if sync == "time":
        T = float(tmin.max(initial=0.0))
        for k in range(n):
            tau, J = _segments(D[k], vmax[k], amax[k], jmax[k], T)
            times[k, 1:], jerk[k] = np.cumsum(tau), sign[k] * J
    else:
        mov = D > 0
        if not np.any(mov):
            T, tau, J = 0.0, np.zeros(7), np.zeros(7)
        else:
            lim = [float(np.min(x[mov] / D[mov])) for x in (vmax, amax, jmax)]
            T = s_curve_time(1.0, *lim)
            tau, J = _segments(1.0, *lim, T)
        times[:, 1:] = np.cumsum(tau)[None, :]
        jerk[:] = (delta[:, None] * J[None, :])
    times[:, -1] = T                                       # the common end, exactly
    return PTPTrajectory(q0=a0.copy(), q1=a1.copy(), duration=T, sync=sync, v_max=vmax, a_max=amax, j_max=jmax,
                         times=times, jerk=jerk, min_times=tmin)
