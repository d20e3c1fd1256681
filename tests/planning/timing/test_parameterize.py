"""Tests of planning.timing.parameterize (both solvers, ``method="reach"`` and ``"qp"``): durations
against the closed-form bang-bang / trapezoid minimum time, and limits recomputed from finite
differences of the sampled trajectory (independent of the code's own q̇, q̈)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from planning.timing import TimingError, blend_path, check_limits, simplify_path, time_parameterize


def closed_form(L: float, v: float, a: float) -> float:
    """Minimum rest-to-rest time over distance L with |v| ≤ v, |a| ≤ a (trapezoid or triangle)."""
    return L / v + v / a if L >= v * v / a else 2.0 * math.sqrt(L / a)


def fd_ratios(t, q, v, a):
    """Largest |Δq/Δt|/v and |second divided difference|/a, recomputed here."""
    dt = np.diff(t)
    vel = np.diff(q, axis=0) / dt[:, None]
    acc = 2 * np.diff(vel, axis=0) / (dt[:-1] + dt[1:])[:, None]
    return float(np.max(np.abs(vel) / v)), float(np.max(np.abs(acc) / a))


@pytest.mark.parametrize("L, v, a", [(1.0, 1.0, 2.0),      # trapezoid, switch on the grid
                                     (1.0, 0.7, 1.3),      # trapezoid, switch between grid points
                                     (0.37, 1.0, 2.0),     # triangle (L < v²/a)
                                     (2.5, 0.4, 3.1),      # long cruise
                                     (0.05, 2.0, 0.5)])    # short, far from the speed limit
@pytest.mark.parametrize("method", ["reach", "qp"])
def test_one_joint_matches_the_closed_form(L, v, a, method):
    tr = time_parameterize(np.array([[0.3], [0.3 + L]]), v, a, method=method)
    assert tr.method == method
    T = closed_form(L, v, a)
    assert tr.duration == pytest.approx(T, rel=0.01)
    assert tr.duration >= T * (1 - 1e-6)            # never faster than the true minimum
    assert tr.q[0, 0] == pytest.approx(0.3) and tr.q[-1, 0] == pytest.approx(0.3 + L)
    fv, fa = fd_ratios(tr.t, tr.q, v, a)
    assert fv <= 1 + 1e-6 and fa <= 1 + 1e-6
    # a bang-bang profile uses the acceleration limit (and the speed limit when it cruises)
    assert fa > 0.99
    if L >= v * v / a:
        assert fv > 0.98


@pytest.mark.parametrize("method", ["reach", "qp"])
def test_one_joint_with_a_fine_grid_is_within_a_permille(method):
    tr = time_parameterize(np.array([[0.0], [1.0]]), 0.7, 1.3, ds=1e-3, method=method)
    assert tr.duration == pytest.approx(closed_form(1.0, 0.7, 1.3), rel=1e-3)


def test_one_joint_on_a_very_fine_grid_converges_to_the_closed_form():
    # 20 000 intervals: only the reachability passes handle this in milliseconds
    tr = time_parameterize(np.array([[0.0], [1.0]]), 0.7, 1.3, ds=5e-5)
    T = closed_form(1.0, 0.7, 1.3)
    assert T * (1 - 1e-9) <= tr.duration <= T * (1 + 1e-4)


@pytest.mark.parametrize("method", ["reach", "qp"])
def test_samples_and_dense_resampling_respect_the_limits(method):
    rng = np.random.default_rng(3)
    W = np.cumsum(rng.uniform(-0.8, 0.8, (7, 4)), axis=0)
    v = np.array([1.0, 0.6, 1.5, 0.8])
    a = np.array([2.0, 1.0, 4.0, 1.5])
    tr = time_parameterize(W, v, a, blend=0.1, method=method)
    assert tr.overshoot <= 1e-9
    ck = check_limits(tr, v, a, tol=1e-3)
    assert ck.ok
    fv, fa = fd_ratios(tr.t, tr.q, v[None, :], a[None, :])
    assert fv <= 1 + 1e-3 and fa <= 1 + 1e-3
    # between the samples too: the exact s(t) resampled at 1 ms, finite differences recomputed
    t = np.arange(0.0, tr.duration, 1e-3)
    q, qd, qdd = tr.sample(t)
    fv, fa = fd_ratios(t, q, v[None, :], a[None, :])
    assert fv <= 1 + 1e-3 and fa <= 1 + 1e-2       # the 3-point formula at 1 ms averages over a jump in q̈
    assert np.max(np.abs(qd) / v) <= 1 + 1e-6 and np.max(np.abs(qdd) / a) <= 1 + 1e-6
    # rest to rest, and the path starts and ends at the first and last waypoints
    assert np.allclose(tr.qd[[0, -1]], 0.0, atol=1e-9)
    np.testing.assert_allclose(tr.q[[0, -1]], W[[0, -1]], atol=1e-12)


@pytest.mark.parametrize("method", ["reach", "qp"])
def test_straight_multi_joint_path_duration(method):
    q0, q1 = np.array([0.0, 1.0, -0.5]), np.array([1.2, 0.4, 0.9])
    v = np.array([1.0, 0.3, 2.0])
    a = np.array([2.0, 3.0, 0.5])
    tr = time_parameterize(np.vstack([q0, q1]), v, a, method=method)
    D = np.abs(q1 - q0)
    per_joint = [closed_form(D[j], v[j], a[j]) for j in range(3)]
    assert tr.duration >= max(per_joint) * (1 - 1e-6)
    # on a straight line the joints move in proportion: the 1-D problem with the tightest ratios
    L = float(np.linalg.norm(q1 - q0))
    u = D / L
    assert tr.duration == pytest.approx(closed_form(L, float(np.min(v / u)), float(np.min(a / u))), rel=0.01)


@pytest.mark.parametrize("method", ["reach", "qp"])
def test_multi_segment_path_is_slower_than_every_joint_alone(method):
    W = np.array([[0.0, 0.0, 0.0], [1.0, 0.2, -0.3], [1.5, 1.0, 0.2], [0.5, 1.4, 1.0]])
    v = np.array([0.8, 1.0, 0.5])
    a = np.array([1.0, 2.0, 1.5])
    for blend in (0.0, 0.05, 0.3):
        tr = time_parameterize(W, v, a, blend=blend, method=method)
        # joint j must at least cover its net displacement
        net = np.abs(W[-1] - W[0])
        assert tr.duration >= max(closed_form(net[j], v[j], a[j]) for j in range(3)) * (1 - 1e-6)
        assert check_limits(tr, v, a).ok
    # stopping at the corners (blend 0) is slower than blending them
    t0 = time_parameterize(W, v, a, blend=0.0, method=method).duration
    t1 = time_parameterize(W, v, a, blend=0.3, method=method).duration
    assert t1 < t0
    # blend 0: at rest at every interior waypoint
    tr = time_parameterize(W, v, a, blend=0.0, method=method)
    for w in W[1:-1]:
        k = int(np.argmin(np.linalg.norm(tr.q - w, axis=1)))
        assert np.linalg.norm(tr.q[k] - w) < 1e-12 and np.allclose(tr.qd[k], 0.0, atol=1e-9)


def test_blends_stay_within_the_reported_deviation():
    W = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [2.0, 1.0]])
    bp = blend_path(W, blend=0.2)
    s = np.linspace(0, bp.length, 20001)
    q, _, _ = bp.evaluate(s)
    for w in W:
        assert np.min(np.linalg.norm(q - w, axis=1)) <= bp.max_deviation + 1e-6   # sampling resolution
    assert bp.max_deviation == pytest.approx(0.2 / 2 * math.sqrt(2) / 2, rel=1e-9)   # |B(½) − corner| for 90°
    # C¹: unit speed along the lines and through the blends' ends
    np.testing.assert_allclose(np.linalg.norm(bp.evaluate(bp.s0)[1], axis=1), 1.0, atol=1e-12)


def test_dense_follower_like_path_is_thinned_and_timed():
    th = np.linspace(0, 1.5 * np.pi, 3000)
    W = np.c_[0.3 * np.cos(th), 0.3 * np.sin(th), 0.1 * th]
    Ws = simplify_path(W, 1e-4)
    assert 10 < len(Ws) < 300
    tr = time_parameterize(W, 1.0, 2.0)
    assert check_limits(tr, 1.0, 2.0).ok
    # each joint must cover its total variation at ≤ 1 rad/s, starting and ending at rest
    travel = np.abs(np.diff(W, axis=0)).sum(axis=0)
    assert tr.duration >= max(closed_form(d, 1.0, 2.0) for d in travel) * 0.99
    assert tr.path.max_deviation <= 1e-4 + 0.05


def test_check_limits_detects_a_too_fast_trajectory():
    tr = time_parameterize(np.array([[0.0], [1.0]]), 1.0, 2.0)
    fast = type(tr)(**{**tr.__dict__, "t": tr.t / 2, "qd": tr.qd * 2, "qdd": tr.qdd * 4})
    ck = check_limits(fast, 1.0, 2.0)
    assert not ck.ok and ck.fd_velocity_ratio == pytest.approx(2.0, rel=1e-3)
    assert ck.fd_acceleration_ratio == pytest.approx(4.0, rel=1e-2)


def test_zero_length_and_bad_input():
    tr = time_parameterize(np.array([[0.5, 0.5], [0.5, 0.5]]), 1.0, 1.0)
    assert tr.duration == 0.0 and tr.q.shape == (1, 2)
    with pytest.raises(TimingError, match="v_max"):
        time_parameterize(np.array([[0.0], [1.0]]), -1.0, 1.0)
    with pytest.raises(TimingError, match="a_max"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, [1.0, 2.0])
    with pytest.raises(TimingError, match="NaN"):
        time_parameterize(np.array([[0.0], [np.nan]]), 1.0, 1.0)
    with pytest.raises(TimingError, match="ds"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, 1.0, ds=0.0)
    with pytest.raises(TimingError, match="blend"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, 1.0, blend=-1.0)
    with pytest.raises(TimingError, match="ds"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, 1.0, ds="0.1")
    with pytest.raises(TimingError, match="ds"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, 1.0, ds=1e-9)          # too many intervals
    with pytest.raises(TimingError, match="ds .* at most 5000 with method='qp'"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, 1.0, ds=1e-4, method="qp")
    with pytest.raises(TimingError, match="ds .* and j_max"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, 1.0, ds=1e-4, j_max=10.0)
    with pytest.raises(TimingError, match="method"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, 1.0, method="toppra")
    with pytest.raises(TimingError, match="backend"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, 1.0, backend="fortran")
    with pytest.raises(TimingError, match="j_max"):
        time_parameterize(np.array([[0.0], [1.0]]), 1.0, 1.0, j_max=0.0)
    with pytest.raises(TimingError, match="j_max"):
        time_parameterize(np.array([[0.0, 0.0], [1.0, 1.0]]), 1.0, 1.0, j_max=[1.0, np.inf])
    assert issubclass(TimingError, kin.RmtError)
