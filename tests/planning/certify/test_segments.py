"""planning.certify.segments: proofs checked against dense sampling of every segment, and a graze
between the states of a sampled check found by the proof."""
import math

import numpy as np
import pytest

import kin
from planning.certify import certify_path
from planning.validate import check_path
from planning.windows import build_windows


@pytest.fixture(scope="module")
def fanuc():
    robot = kin.load_robot("fanuc_m16ib20")
    return robot, build_windows(robot, margin=0.05)


def _dense_inside(ws, a, b, count=20001):
    t = np.linspace(0.0, 1.0, count)
    Q = a + t[:, None] * (b - a)
    return t, ws.which(Q) >= 0


def test_proofs_agree_with_dense_sampling(fanuc):
    robot, ws = fanuc
    Q = robot.random_configurations(3000, seed=11)
    Q = Q[ws.which(Q) < 0][:240].reshape(-1, 2, robot.n)
    proven = violated = 0
    for a, b in Q:
        proof = certify_path(ws, np.array([a, b]))
        t, inside = _dense_inside(ws, a, b)
        if proof.proven:
            proven += 1
            assert not inside.any()
        else:
            assert proof.violation is not None and not proof.unproven
            violated += 1
            v = proof.violation
            assert ws.contains(v.q)                                   # the state found is inside
            assert np.allclose(v.q, a + v.t * (b - a))
            # no sampled state clearly before it is inside (the proof finds the entry)
            assert not inside[t < v.t - 1e-3].any()
    assert proven >= 5 and violated >= 5


def test_a_graze_between_sampled_states_is_found(fanuc):
    robot, ws = fanuc
    w = next(w for w in ws.windows if w.kind == "shoulder")
    e2, e3 = np.eye(6)[1], np.eye(6)[2]

    def g(x):
        return w.g(np.atleast_2d(x))[0]

    def touch(q, target):                             # Newton on q2 until g(q) = target
        for _ in range(60):
            dg = (g(q + 1e-7 * e2) - g(q - 1e-7 * e2)) / 2e-7
            q = q - (g(q) - target) / dg * e2
        return q

    def tangent(q):                                   # the level set's tangent in (q2, q3)
        gr = np.array([(g(q + 1e-7 * e) - g(q - 1e-7 * e)) / 2e-7 for e in (e2, e3)])
        d = np.zeros(6)
        d[1:3] = [-gr[1], gr[0]]
        return d / np.linalg.norm(d)

    q = robot.random_configurations(1, seed=2)[0]
    q[4] = 0.8                                        # away from the wrist window
    q = touch(q, (1 - 1e-6) * w.epsilon)
    d = tangent(q)
    curvature = (g(q + 1e-3 * d) + g(q - 1e-3 * d) - 2 * g(q)) / 1e-6
    if curvature < 0:                                 # along this line g falls: graze from the other side
        q = touch(q, -(1 - 1e-6) * w.epsilon)
        d = tangent(q)
    assert w.contains(q)
    # a segment through q along the tangent: only a sliver about 1e-3 rad long is inside the window
    a, b = q - 0.3 * d, q + 0.3 * d
    assert not ws.contains(a) and not ws.contains(b)
    # a sampled check with 17 steps on this segment: q, at its middle, falls halfway between two states
    coarse = np.abs(b - a).max() / 17 * (1 + 1e-9)
    assert coarse < math.radians(2.1)
    sampled = check_path(robot, np.array([a, b]), ws, None, coarse, 1e-3, prove=False)
    proof = certify_path(ws, np.array([a, b]))
    assert proof.violation is not None and ws.contains(proof.violation.q)
    assert abs(proof.violation.t - 0.5) < 0.01
    assert sampled.valid                              # the sampled check misses it: the point of a proof
    proven = check_path(robot, np.array([a, b]), ws, None, coarse, 1e-3)    # check_path proves by default
    assert not proven.valid and proven.first_violation.kind == "window" and "(proven)" in proven.first_violation.detail
    assert proven.windows_check == "proven"


def test_interval_windows_are_decided_exactly(fanuc):
    robot, ws = fanuc
    wrist = next(w for w in ws.windows if w.kind == "wrist")
    a = np.array([0.0, 0.3, 0.2, 0.0, -0.6, 0.0])
    b = a.copy()
    b[4] = 0.8
    proof = certify_path(ws, np.array([a, b]))
    v = proof.violation
    lo = min(iv[0] for iv in wrist.intervals)
    assert v.window == wrist.name
    assert v.q[4] == pytest.approx(lo, abs=1e-12)
    assert v.t == pytest.approx((lo - a[4]) / (b[4] - a[4]), abs=1e-12)


def test_bad_paths_are_refused(fanuc):
    _, ws = fanuc
    with pytest.raises(ValueError):
        certify_path(ws, np.zeros((3, 5)))
    with pytest.raises(ValueError):
        certify_path(ws, np.full((2, 6), np.nan))
