"""Tests of planning.timing.ptp (``ptp_move``): one-joint durations against hand-worked S-curves (each
case of the closed form), the limits and the goal on dense samples, both synchronisations, bad input,
and the durations against Ruckig's time synchronisation when ruckig is installed."""
from __future__ import annotations

import numpy as np
import pytest

from planning.timing import TimingError
from planning.timing.ptp import ptp_move


@pytest.mark.parametrize("D, v, a, j, T", [
    # trapezoidal acceleration and a cruise: each ramp v/a + a/j = 0.5 + 0.5 = 1 s covers v·1/2 = 1;
    # cruise (10 − 2)/2 = 4 s → 1 + 4 + 1 = 6 s
    (10.0, 2.0, 4.0, 8.0, 6.0),
    # triangular acceleration (v·j = 2 < a² = 16) and a cruise: ramp 2·√(v/j) = 2·√0.5 s covers v·ramp;
    # T = ramp + D/v
    (10.0, 1.0, 4.0, 2.0, 2 * np.sqrt(0.5) + 10.0),
    # trapezoidal acceleration, no cruise: vp²/a + vp·a/j = D with a = 1, j = 10, D = 2:
    # vp = (−0.1 + √(0.01 + 8))/2 = 1.36555…, T = 2·(vp/a + a/j)
    (2.0, 5.0, 1.0, 10.0, 2 * ((-0.1 + np.sqrt(0.01 + 8.0)) / 2 + 0.1)),
    # triangular acceleration, no cruise: D = 2·j·(T/4)³ (four jerk segments of T/4) → T = 4·(D/(2j))^(1/3)
    (0.25, 10.0, 100.0, 1.0, 4.0 * (0.25 / 2.0) ** (1 / 3)),
])
def test_one_joint_durations_by_hand(D, v, a, j, T):
    tr = ptp_move([0.0], [D], v, a, j)
    assert tr.duration == pytest.approx(T, rel=1e-12)
    q, qd, qdd, jk = tr.sample(np.linspace(0.0, T, 4001))
    assert q[-1, 0] == pytest.approx(D, rel=1e-12) and abs(qd[-1, 0]) < 1e-12 and abs(qdd[-1, 0]) < 1e-12
    assert np.max(np.abs(qd)) <= v * (1 + 1e-12) and np.max(np.abs(qdd)) <= a * (1 + 1e-12)
    assert np.max(np.abs(jk)) <= j * (1 + 1e-12)
    # q̇, q̈, q⃛ are the derivatives of the sampled q (central differences, away from the switches)
    t = np.linspace(0.0, T, 1001)[1:-1]
    e = 1e-5 * T
    qm, qdm, qddm, _ = tr.sample(t - e)
    qp, qdp, qddp, _ = tr.sample(t + e)
    q, qd, qdd, jk = tr.sample(t)
    assert np.max(np.abs((qp - qm) / (2 * e) - qd)) <= 1e-6 * v
    assert np.max(np.abs((qdp - qdm) / (2 * e) - qdd)) <= 1e-6 * a
    away = np.min(np.abs(t[:, None] - tr.times[0][None, :]), axis=1) > 2 * e
    assert np.max(np.abs((qddp - qddm)[away] / (2 * e) - jk[away])) <= 1e-6 * j


def _check(tr, q0, q1, v, a, j):
    t = np.linspace(0.0, tr.duration, 5001)
    q, qd, qdd, jk = tr.sample(t)
    np.testing.assert_allclose(q[0], q0, atol=1e-12)
    np.testing.assert_allclose(q[-1], q1, atol=1e-9)
    np.testing.assert_allclose(qd[[0, -1]], 0.0, atol=1e-9)
    assert np.all(np.abs(qd) <= v * (1 + 1e-9)) and np.all(np.abs(qdd) <= a * (1 + 1e-9))
    assert np.all(np.abs(jk) <= j * (1 + 1e-12))
    return q


def test_time_and_phase_synchronisation():
    rng = np.random.default_rng(3)
    v, a = np.array([2.9, 2.9, 3.0, 6.1, 5.9, 9.1]), np.array([5.8, 5.8, 6.1, 12.2, 11.9, 18.2])
    j = 10 * a
    for _ in range(20):
        q0, q1 = rng.uniform(-2, 2, 6), rng.uniform(-2, 2, 6)
        ts = ptp_move(q0, q1, v, a, j)
        _check(ts, q0, q1, v, a, j)
        single = [ptp_move(q0[[k]], q1[[k]], v[k], a[k], j[k]).duration for k in range(6)]
        assert ts.duration == pytest.approx(max(single), rel=1e-14)
        ph = ptp_move(q0, q1, v, a, j, sync="phase")
        q = _check(ph, q0, q1, v, a, j)
        # a straight line: q − q0 parallel to q1 − q0 at every sample
        d = (q1 - q0) / np.linalg.norm(q1 - q0)
        off = (q - q0) - ((q - q0) @ d)[:, None] * d[None, :]
        assert np.max(np.abs(off)) < 1e-9
        assert ph.duration >= ts.duration * (1 - 1e-12)
    # limits proportional to the move: phase synchronisation costs nothing
    q0, q1 = np.zeros(3), np.array([1.0, -2.0, 0.5])
    s = np.abs(q1)
    assert ptp_move(q0, q1, s, 2 * s, 5 * s, "phase").duration == pytest.approx(
        ptp_move(q0, q1, s, 2 * s, 5 * s).duration, rel=1e-12)
    # a joint that does not move stays put
    tr = ptp_move([0.0, 1.0], [0.5, 1.0], 1.0, 1.0, 1.0)
    assert np.all(tr.sample(np.linspace(0, tr.duration, 11))[0][:, 1] == 1.0)
    assert ptp_move([0.0], [0.0], 1.0, 1.0, 1.0).duration == 0.0


def test_bad_input():
    with pytest.raises(TimingError, match="sync"):
        ptp_move([0.0], [1.0], 1.0, 1.0, 1.0, sync="space")
    with pytest.raises(TimingError, match="j_max"):
        ptp_move([0.0], [1.0], 1.0, 1.0, 0.0)
    with pytest.raises(TimingError, match="q0 and q1"):
        ptp_move([0.0, 1.0], [1.0], 1.0, 1.0, 1.0)
    with pytest.raises(TimingError, match="v_max"):
        ptp_move([0.0, 1.0], [1.0, 2.0], [1.0, -1.0], 1.0, 1.0)


def test_durations_equal_ruckigs_time_synchronisation():
    ruckig = pytest.importorskip("ruckig")
    rng = np.random.default_rng(11)
    v = np.radians([165.0, 165.0, 175.0, 350.0, 340.0, 520.0])
    a = 2 * v
    for k in range(100):
        j = a * rng.uniform(1.0, 30.0)
        q0 = rng.uniform(-2, 2, 6)
        q1 = q0 + rng.uniform(-2, 2, 6) * rng.choice([1e-3, 0.1, 1.0], 6)
        otg, inp, traj = ruckig.Ruckig(6), ruckig.InputParameter(6), ruckig.Trajectory(6)
        inp.current_position, inp.target_position = q0.tolist(), q1.tolist()
        inp.max_velocity, inp.max_acceleration, inp.max_jerk = v.tolist(), a.tolist(), j.tolist()
        assert otg.calculate(inp, traj) == ruckig.Result.Working
        assert ptp_move(q0, q1, v, a, j).duration == pytest.approx(traj.duration, rel=1e-6)
