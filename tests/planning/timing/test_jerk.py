"""Tests of planning.timing.jerk (``j_max`` of time_parameterize): the jerk bound re-checked by finite
differences of the sampled trajectory (q̈ just after every grid time from one-sided second
differences of q(t), independent of the code's q̈), the speed and acceleration limits still densely
met, and the duration against the closed-form jerk-limited minimum time of one joint."""
from __future__ import annotations

import math

import numpy as np
import pytest

from kin.native import find_compiler
from planning.timing import TimingError, time_parameterize
from planning.timing.limits import dense_ratios


def s_curve_time(L: float, v: float, a: float, j: float) -> float:
    """Minimum rest-to-rest time over L with |v|, |a|, |jerk| bounded (continuous, symmetric S-curve)."""
    def ramp(vp: float) -> float:                       # time to reach speed vp from rest
        return vp / a + a / j if vp * j >= a * a else 2.0 * math.sqrt(vp / j)
    if v * ramp(v) <= L:                                # accelerate, cruise, decelerate (distance of a ramp: vp·T/2)
        return 2 * ramp(v) + (L - v * ramp(v)) / v
    lo, hi = 0.0, v
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mid * ramp(mid) < L else (lo, mid)
    return 2 * ramp(lo)


def fd_jerk_ratio(tr, jmax: np.ndarray) -> float:
    """Largest |Δq̈|/(j_max·Δt) between consecutive grid times, q̈(t_i⁺) from one-sided second
    differences of the sampled q alone (second order, (2q₀ − 5q₁ + 4q₂ − q₃)/d², d 1 % of the way to the
    next sample; at the end, from the left)."""
    k = np.flatnonzero(np.isin(tr.s, tr.grid))
    tg = tr.t[k]
    d = 1e-2 * np.r_[tr.t[k[:-1] + 1] - tg[:-1], tg[-1] - tr.t[-2]]
    t0 = np.r_[tg[:-1], tg[-1] - 3 * d[-1]]
    q = [tr.sample(t0 + i * d)[0] for i in range(4)]
    acc = (2 * q[0] - 5 * q[1] + 4 * q[2] - q[3]) / d[:, None] ** 2
    acc[-1] = (2 * q[3] - 5 * q[2] + 4 * q[1] - q[0])[-1] / d[-1] ** 2     # at the end point itself
    acc = np.vstack([np.zeros(acc.shape[1]), acc, np.zeros(acc.shape[1])])   # at rest before and after
    dt = np.diff(tg)
    dt = np.r_[dt[0], dt, dt[-1]]
    return float(np.max(np.abs(np.diff(acc, axis=0)) / (jmax[None, :] * dt[:, None])))


@pytest.mark.parametrize("L, v, a, j", [(1.0, 1.0, 2.0, 5.0), (1.0, 1.0, 2.0, 1.0), (0.3, 1.0, 1.0, 20.0)])
def test_one_joint_against_the_s_curve(L, v, a, j):
    free = time_parameterize(np.array([[0.0], [L]]), v, a)
    tr = time_parameterize(np.array([[0.0], [L]]), v, a, j_max=j)
    T = s_curve_time(L, v, a, j)
    assert tr.duration > free.duration
    # a bound on the change of the sampled q̈ admits a staircase ahead of the continuous ramp (q̈ steps
    # by j_max·Δt at once over the long first and last intervals): the optimum of that bound is 4–5 %
    # faster than the continuous S-curve here, and not much slower
    assert 0.93 * T <= tr.duration <= 1.05 * T
    assert tr.max_jerk_ratio <= 1 + 1e-9
    assert fd_jerk_ratio(tr, np.array([j])) <= 1 + 1e-3
    dv, da = dense_ratios(tr, v, a)
    assert dv <= 1 + 1e-9 and da <= 1 + 1e-9


def test_six_joint_path_jerk_and_limits():
    rng = np.random.default_rng(0)
    u = np.linspace(0.0, 1.0, 30)[:, None]
    W = 0.8 * np.sin(2 * np.pi * rng.uniform(0.3, 1.5, 6) * u + rng.uniform(0, 6, 6))
    v = np.array([2.6, 2.8, 2.8, 5.2, 5.2, 7.8])
    jm = np.full(6, 40.0)
    free = time_parameterize(W, v, 2 * v, ds=0.02)
    tr = time_parameterize(W, v, 2 * v, ds=0.02, j_max=jm)
    assert free.duration < tr.duration
    assert fd_jerk_ratio(free, jm) > 1.5                 # unconstrained, the bound is violated …
    assert fd_jerk_ratio(tr, jm) <= 1 + 1e-3             # … and with j_max it holds
    assert tr.overshoot <= 1e-9
    dv, da = dense_ratios(tr, v, 2 * v, per_interval=16)
    assert dv <= 1 + 1e-9 and da <= 1 + 1e-9
    # a smaller jerk limit takes longer
    assert time_parameterize(W, v, 2 * v, ds=0.02, j_max=10.0).duration > tr.duration


def test_no_slower_than_the_scaled_profile_and_c_agrees_with_numpy():
    W = np.array([[0.0, 0.0, 0.0], [0.6, -0.3, 0.2], [1.0, 0.4, -0.2], [1.5, 0.1, 0.3]])
    v, a, jm = np.array([1.0, 1.2, 1.5]), np.array([2.0, 3.0, 3.0]), np.array([8.0, 10.0, 12.0])
    free = time_parameterize(W, v, a, backend="numpy")
    tr = time_parameterize(W, v, a, j_max=jm, backend="numpy")
    # the free profile scaled by c meets the jerk bound when c^(3/2)·ratio ≤ 1 (q̈ ∝ c, Δt ∝ c^(−1/2)):
    # a feasible profile of duration T_free·ratio^(1/3), which the passes start from and improve
    r = fd_jerk_ratio(free, jm)
    assert tr.duration <= free.duration * r ** (1 / 3) * (1 + 1e-3)
    assert fd_jerk_ratio(tr, jm) <= 1 + 1e-3 and "jerk-limited (numpy)" in tr.qp_status
    if find_compiler() is None:
        pytest.skip("no C compiler: only the numpy pass")
    trc = time_parameterize(W, v, a, j_max=jm, backend="c")
    assert "jerk-limited (c)" in trc.qp_status and trc.max_jerk_ratio <= 1 + 1e-9
    assert trc.duration == pytest.approx(tr.duration, rel=1e-6)


def test_jerk_with_the_qp_method_and_bad_limits():
    tr = time_parameterize(np.array([[0.0], [1.0]]), 1.0, 2.0, j_max=5.0, method="qp")
    assert tr.max_jerk_ratio <= 1 + 1e-9 and "jerk" in tr.qp_status
    with pytest.raises(TimingError, match="j_max"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, 2.0, j_max=-5.0)
