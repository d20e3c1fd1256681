"""The spline through waypoints (planning.timing.spline) and ``time_parameterize(shape="spline")``:
exact passage, C¹, the joint range, closed forms, limits on the continuous trajectory."""
from __future__ import annotations

import math

import numpy as np
import pytest

from planning.timing import TimingError, time_parameterize
from planning.timing.limits import dense_ratios
from planning.timing.shaping import blend_path
from planning.timing.spline import spline_path


def wavy(m=40, n=3, seed=1):
    rng = np.random.default_rng(seed)
    u = np.linspace(0, 1, m)[:, None]
    f, ph = rng.uniform(0.5, 2.5, (2, n)), rng.uniform(0, 2 * np.pi, (2, n))
    return 0.8 * np.sin(2 * np.pi * f[0] * u + ph[0]) + 0.3 * np.sin(2 * np.pi * f[1] * u + ph[1])


@pytest.mark.parametrize("parameter", ["uniform", "chord"])
@pytest.mark.parametrize("sub", [1, 2, 5])
def test_passes_every_waypoint_and_is_c1(parameter, sub):
    W = wavy()
    bp, shape = spline_path(W, parameter, sub)
    q, _, _ = bp.evaluate(shape.s)
    assert np.max(np.abs(q - W)) < 1e-12
    assert bp.max_deviation == 0.0
    inner = bp.s0[1:]
    _, dl, _ = bp.evaluate(inner, bp.piece_of(inner, "left"))
    _, dr, _ = bp.evaluate(inner, bp.piece_of(inner, "right"))
    assert np.max(np.abs(dl - dr)) < 1e-9 * (1 + np.max(np.abs(dl)))
    # every piece quadratic: q″ constant on it (second differences of samples)
    ss = bp.s0[3] + bp.ell[3] * np.linspace(0.1, 0.9, 5)
    dd = np.diff(bp.evaluate(ss)[0], 2, axis=0)
    assert np.allclose(dd, dd[0], atol=1e-12)


def test_a_cubic_is_reproduced_and_a_line_is_kept():
    """Not-a-knot cubic splines reproduce a cubic polynomial exactly, so on waypoints sampled from
    one (uniform parameter) the path stays within its reported deviation of the polynomial, and
    that deviation shrinks like h³ or better with ``sub``."""
    t = np.linspace(0.0, 1.0, 12)
    poly = lambda x: np.c_[x ** 3 - x, 0.5 * x ** 2 + 0.2, -2 * x ** 3 + x ** 2]
    W = poly(t)
    devs = []
    for sub in (1, 2, 4):
        bp, shape = spline_path(W, "uniform", sub)
        ss = np.linspace(0, bp.length, 2001)
        x = ss / bp.length
        err = np.max(np.linalg.norm(bp.evaluate(ss)[0] - poly(x), axis=1))
        assert err <= 1.05 * shape.cubic_deviation + 1e-12
        devs.append(err)
    assert devs[2] < devs[0] / 8
    line = np.linspace([0.0, 1.0], [2.0, -1.0], 7)
    bp, shape = spline_path(line)
    ss = np.linspace(0, bp.length, 301)
    q = bp.evaluate(ss)[0]
    assert shape.segment_deviation < 1e-12
    assert np.max(np.abs(q[:, 0] + q[:, 1] - 1.0)) < 1e-12


def test_joint_range_is_exact():
    bp, _ = spline_path(wavy(seed=4))
    lo, hi = bp.joint_range()
    q = bp.evaluate(np.linspace(0, bp.length, 200001))[0]
    assert np.all(q.min(axis=0) >= lo - 1e-12) and np.all(q.max(axis=0) <= hi + 1e-12)
    assert np.max(np.abs(q.min(axis=0) - lo)) < 1e-6 and np.max(np.abs(q.max(axis=0) - hi)) < 1e-6
    # the spline overshoots the waypoints' own range somewhere (why the range is reported)
    W = wavy(seed=4)
    assert np.any(hi > W.max(axis=0) + 1e-6) or np.any(lo < W.min(axis=0) - 1e-6)


def test_two_waypoints_time_is_the_bang_bang_closed_form():
    """Rest to rest over a straight line of length L with acceleration A only binding: T = 2√(L/A)
    (the speed limit is never reached: peak √(L·A) < v)."""
    W = np.array([[0.0, 0.0], [0.6, 0.8]])          # L = 1
    A = 2.0
    tr = time_parameterize(W, v_max=[10.0, 10.0], a_max=[A * 0.6, A * 0.8], shape="spline")
    T = 2 * math.sqrt(1.0 / A)
    assert T <= tr.duration <= T * (1 + 1e-3)


def test_limits_hold_between_samples_and_spline_beats_blends_through_many_waypoints():
    W = wavy(m=60, n=4, seed=2)
    v, a = np.array([2.0, 2.5, 3.0, 3.5]), np.array([8.0, 10.0, 12.0, 15.0])
    spl = time_parameterize(W, v, a, shape="spline")
    assert spl.max_velocity_ratio <= 1 + 1e-9 and spl.max_acceleration_ratio <= 1 + 1e-9
    dv, da = dense_ratios(spl, v, a, 40)
    assert dv <= 1 + 1e-9 and da <= 1 + 1e-9
    ble = time_parameterize(W, v, a, shape="blend")
    assert spl.duration < ble.duration
    # the trajectory visits every waypoint, in order
    q = spl.sample(np.linspace(0, spl.duration, 20001))[0]
    for w in W:
        assert np.min(np.linalg.norm(q - w, axis=1)) < 2e-3


def test_against_toppra_typical_use():
    """TOPP-RA as its documentation shows it (a cubic spline through the waypoints at uniform
    parameter, its proposed grid) on a 30-waypoint path: the spline shape's time converges from above
    to TOPP-RA's as the grid is refined, with its limits holding everywhere (TOPP-RA's hold at its
    grid points only)."""
    ta = pytest.importorskip("toppra")
    import toppra.algorithm as algo
    import toppra.constraint as con
    W = wavy(m=30, n=3, seed=3)
    v, a = np.array([2.0, 2.5, 3.0]), np.array([8.0, 10.0, 12.0])
    path = ta.SplineInterpolator(np.linspace(0, 1, len(W)), W)
    inst = algo.TOPPRA([con.JointVelocityConstraint(np.c_[-v, v]), con.JointAccelerationConstraint(np.c_[-a, a])],
                       path, parametrizer="ParametrizeConstAccel")
    peer = inst.compute_trajectory().duration
    ours = time_parameterize(W, v, a, shape="spline")
    fine = time_parameterize(W, v, a, shape="spline", ds=ours.path.length / 6000)
    assert fine.duration <= ours.duration <= peer * 1.005      # the default grid: within 0.5 %
    assert fine.duration <= peer * 1.0005                     # converging to TOPP-RA's (which overshoots)


@pytest.mark.parametrize("kw, match", [
    (dict(parameter="centripetal"), "parameter"),
    (dict(sub=0), "sub"),
    (dict(sub=2.5), "sub"),
    (dict(sub=True), "sub"),
])
def test_bad_options_are_one_line(kw, match):
    with pytest.raises(TimingError, match=match) as e:
        spline_path(wavy(), **kw)
    assert "\n" not in str(e.value)


def test_bad_shape_and_trivial_paths():
    with pytest.raises(TimingError, match="shape"):
        time_parameterize(wavy(), 1.0, 1.0, shape="bezier")
    with pytest.raises(TimingError, match="NaN"):
        spline_path(np.array([[0.0, np.nan], [1.0, 1.0]]))
    tr = time_parameterize(np.zeros((3, 2)), 1.0, 1.0, shape="spline")
    assert tr.duration == 0.0
    bp, _ = spline_path([[0.0, 0.0], [1.0, 0.0]])
    assert bp.length > 0 and len(bp.ell) == 1
    assert blend_path(wavy()).n == spline_path(wavy())[0].n


@pytest.mark.parametrize("tol", [1e-2, 1e-4])
def test_polyline_stays_within_its_tolerance(tol):
    """Every dense point of the path lies within ``tol`` of the polyline (distance to the nearest
    segment computed directly), and the polyline's vertices lie on the path."""
    bp, _ = spline_path(wavy(m=12, seed=5))
    P = bp.polyline(tol)
    assert np.allclose(P[0], bp.waypoints[0]) and np.allclose(P[-1], bp.waypoints[-1])
    ss = np.linspace(0, bp.length, 4001)
    q = bp.evaluate(ss)[0]
    a, d = P[:-1], np.diff(P, axis=0)
    L2 = np.einsum("ij,ij->i", d, d)
    best = np.full(len(q), np.inf)
    for k in range(0, len(a), 256):
        aa, dd, ll = a[k:k + 256], d[k:k + 256], L2[k:k + 256]
        x = q[:, None, :] - aa[None]
        u = np.clip(np.einsum("ijk,jk->ij", x, dd) / np.where(ll > 0, ll, 1.0), 0, 1)
        dist = np.linalg.norm(x - u[..., None] * dd[None], axis=2).min(axis=1)
        best = np.minimum(best, dist)
    assert best.max() <= tol * (1 + 1e-9)
    assert best.max() >= tol / 20                   # not needlessly fine
    with pytest.raises(TimingError, match="tolerance"):
        bp.polyline(0.0)
