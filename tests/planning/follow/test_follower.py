"""Tests of planning.follow (OSQP path follower, naive resolved rate).

Tracking errors are recomputed with the plain numpy DH of ``dh_numpy`` (not rmtkit's kinematics);
limits are checked on the returned joint path itself.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import kin
from planning.follow import (
    DEFAULT_V_MAX_REVOLUTE,
    FollowError,
    follow_path,
    joint_velocity_limits,
    resolved_rate,
    window_ranges,
)
from planning.windows import build_windows
from tests.dh_numpy import pose_errors_numpy


def _min_jerk_line(robot, q0, delta, duration=2.0, N=501):
    T0 = robot.fk(q0)
    t = np.linspace(0.0, duration, N)
    u = t / duration
    s = 10 * u ** 3 - 15 * u ** 4 + 6 * u ** 5
    poses = np.tile(T0, (N, 1, 1))
    poses[:, :3, 3] += np.outer(s, delta)
    return poses, t


@pytest.fixture(scope="module")
def fanuc():
    return kin.load_robot("fanuc_m16ib20")


# ---- the follower on ordinary paths ----------------------------------------------------------------------
def test_tracking_error_on_a_nonsingular_line(fanuc):
    q0 = np.array([0.0, 0.3, -0.4, 0.0, -0.9, 0.0])
    poses, t = _min_jerk_line(fanuc, q0, [0.0, 0.2, -0.1])
    res = follow_path(fanuc, (poses, t), q0)
    assert res.q.shape == (len(t), 6)
    assert np.all(fanuc.sigma_min(res.q) > 0.3)           # the line stays away from singularities
    pe, oe = pose_errors_numpy(fanuc.chain, res.q, poses)
    assert pe.max() <= 1e-4
    assert oe.max() <= 1e-4
    assert res.max_tracking_error == pytest.approx(pe.max(), abs=1e-9)
    assert res.within_tolerance and res.qp_status.get("solved", 0) == len(t) - 1
    # the open-loop naive method drifts more on the same path (no feedback)
    naive = resolved_rate(fanuc, (poses, t), q0)
    assert naive.max_tracking_error > 10 * pe.max()


def test_joint_and_speed_limits_hold_at_every_step(fanuc):
    # joint 1 confined to ±0.1 rad, all speeds to 0.2 rad/s; the path asks for a 0.4 m sweep in 1 s
    chain = fanuc.chain
    joints = list(chain.joints)
    joints[0] = dataclasses.replace(joints[0], limits=(-0.1, 0.1))
    robot = kin.Robot(dataclasses.replace(chain, name="fanuc_narrow", joints=tuple(joints)))
    q0 = np.array([0.0, 0.3, -0.4, 0.0, -0.9, 0.0])
    poses, t = _min_jerk_line(robot, q0, [0.0, 0.4, 0.0], duration=1.0, N=251)
    v = 0.2
    res = follow_path(robot, (poses, t), q0, v_max=v)
    Q = res.q
    assert np.all(Q >= robot.chain.lower - 1e-12) and np.all(Q <= robot.chain.upper + 1e-12)
    speeds = np.abs(np.diff(Q, axis=0)) / np.diff(t)[:, None]
    assert speeds.max() <= v * (1 + 1e-9)
    assert Q[:, 0].max() == pytest.approx(0.1, abs=1e-9)     # joint 1 reached its limit and stopped there
    assert not res.within_tolerance                          # the path is not feasible: reported honestly
    assert res.speed_ratio <= 1 + 1e-9


def test_default_speed_limit_when_the_file_gives_none(fanuc):
    assert all(j.max_velocity is None for j in fanuc.chain.joints)
    np.testing.assert_array_equal(joint_velocity_limits(fanuc), np.full(6, DEFAULT_V_MAX_REVOLUTE))
    ur5 = kin.load_robot("ur5e")
    assert joint_velocity_limits(ur5)[0] == pytest.approx(ur5.chain.joints[0].max_velocity)


def test_bad_input_is_a_typed_error_naming_the_parameter(fanuc):
    q0 = np.array([0.0, 0.3, -0.4, 0.0, -0.9, 0.0])
    poses, t = _min_jerk_line(fanuc, q0, [0.0, 0.1, 0.0], N=11)
    with pytest.raises(FollowError, match="mode 'joint' unknown; allowed: pose, axis, position"):
        follow_path(fanuc, (poses, t), q0, mode="joint")
    with pytest.raises(FollowError, match="dt"):
        follow_path(fanuc, poses, q0)
    with pytest.raises(FollowError, match="strictly increasing"):
        follow_path(fanuc, (poses, t[::-1]), q0)
    bad = poses.copy()
    bad[3, 0, 3] = np.nan
    with pytest.raises(FollowError, match="NaN"):
        follow_path(fanuc, bad, q0, dt=0.01)
    with pytest.raises(FollowError, match="v_max"):
        follow_path(fanuc, poses, q0, dt=0.01, v_max=-1.0)
    with pytest.raises(FollowError, match="feedback"):
        follow_path(fanuc, poses, q0, dt=0.01, feedback=2.0)
    with pytest.raises(kin.JointLimitError, match="joint 2"):
        follow_path(fanuc, poses, np.array([0.0, 5.0, 0.0, 0.0, 0.0, 0.0]), dt=0.01)
    assert issubclass(FollowError, kin.RmtError)


# ---- the naive method in the follower's task modes ---------------------------------------------------------
@pytest.fixture(scope="module")
def scara():
    return kin.load_robot("scara_rrp")


def _scara_line(robot, q0, delta, N=101, duration=2.0):
    """Positions (N, 3) m along a straight line from fk(q0), and their times."""
    p0 = robot.fk(q0)[:3, 3]
    return p0 + np.outer(np.linspace(0.0, 1.0, N), delta), np.linspace(0.0, duration, N)


def test_naive_position_mode_is_the_square_position_jacobian(scara):
    # the SCARA controls x, y, z: its 3×3 position Jacobian is square, so solve, never pinv; and the
    # open-loop method takes exactly the steps J_v⁻¹·Δp of the numpy Jacobian
    from tests.dh_numpy import jacobian_numpy
    q0 = np.array([0.3, 1.2, -0.15])
    P, t = _scara_line(scara, q0, [0.05, -0.03, 0.02], N=6)
    res = resolved_rate(scara, (P, t), q0, mode="position")
    assert res.mode == "position" and res.pinv_steps == [] and res.diverged_at is None
    q = q0.copy()
    for k in range(len(P) - 1):
        q = q + np.linalg.solve(jacobian_numpy(scara.chain, q)[:3], P[k + 1] - P[k])
        np.testing.assert_allclose(res.q[k + 1], q, atol=1e-12)
    assert math.isnan(res.max_orientation_error)                    # not tracked in position mode
    assert res.summary()["mode"] == "position"
    # in pose mode the 6×3 Jacobian is not square: the pseudo-inverse at every step, and the rotation
    # rows it cannot serve pull the tool off the line
    poses = np.tile(scara.fk(q0), (len(P), 1, 1))
    poses[:, :3, 3] = P
    pose = resolved_rate(scara, (poses, t), q0)
    assert pose.pinv_steps == list(range(len(P) - 1))
    assert pose.max_tracking_error > 10 * res.max_tracking_error


def test_naive_axis_mode_leaves_the_turn_about_the_tool_axis_free(fanuc):
    # a line with the tool turning about its own z axis: in axis mode that turn is not tracked, the
    # tool axis is; in pose mode both are
    q0 = np.array([0.0, 0.3, -0.4, 0.0, -0.9, 0.0])
    T0 = fanuc.fk(q0)
    N = 201
    t = np.linspace(0.0, 2.0, N)
    poses = np.tile(T0, (N, 1, 1))
    poses[:, :3, 3] += np.outer(np.linspace(0, 1, N), [0.0, 0.1, 0.0])
    for k, a in enumerate(np.linspace(0.0, 0.5, N)):
        c, s_ = math.cos(a), math.sin(a)
        poses[k, :3, :3] = T0[:3, :3] @ np.array([[c, -s_, 0], [s_, c, 0], [0, 0, 1]])
    axis = resolved_rate(fanuc, (poses, t), q0, mode="axis")
    pose = resolved_rate(fanuc, (poses, t), q0, mode="pose")
    assert axis.pinv_steps == list(range(N - 1))                       # 5×6: not square
    assert axis.max_orientation_error == pytest.approx(float(np.nanmax(axis.axis_error)))
    assert axis.max_orientation_error < 1e-3 and axis.max_tracking_error < 1e-3
    assert float(np.nanmax(axis.orientation_error)) > 0.3              # the turn of 0.5 rad is left out
    assert pose.max_orientation_error < 1e-3
    with pytest.raises(FollowError, match="mode 'joint' unknown"):
        resolved_rate(fanuc, (poses, t), q0, mode="joint")


def test_follower_beyond_reach_warns_nothing(scara):
    # a line that leaves the SCARA's reach (675 mm) through its boundary singularity: windows are
    # dropped as forced and the step is re-solved — without a numpy warning on the way
    import warnings
    q0 = np.array([0.0, 0.8, -0.15])
    P, t = _scara_line(scara, q0, [0.3, 0.0, 0.0], N=151, duration=3.0)
    windows = build_windows(scara, margin=0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = follow_path(scara, P, q0, windows, mode="position", dt=t[1])
    assert not res.within_tolerance and res.speed_ratio <= 1 + 1e-9
    # no configuration reaches past 675 mm: the error is at least the distance beyond it
    beyond = np.linalg.norm(P[:, :2], axis=1).max() - 0.675
    assert beyond > 0.05 and res.max_tracking_error >= beyond - 1e-9


def test_window_ranges():
    w = np.array([-1, 0, 0, -1, 0, 2, 2, -1])
    out = window_ranges(w, ["a", "b", "c"])
    assert out == [{"window": 0, "name": "a", "ranges": [[1, 2], [4, 4]], "waypoints": 3},
                   {"window": 2, "name": "c", "ranges": [[5, 6]], "waypoints": 2}]


def test_resolved_rate_at_an_exactly_singular_start():
    # the UR3-like pen arm at θ5 = 0 (docs/machines.md §6): J is exactly singular, solve raises, the
    # pseudo-inverse takes that step; a small move in the y–z plane with the orientation held
    pen = kin.load_robot("ur3_homework_pen")
    q0 = np.array([0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0, 0.0])
    T0 = pen.fk(q0)
    poses = np.tile(T0, (11, 1, 1))
    poses[:, 1, 3] += np.linspace(0.0, 1e-3, 11)
    poses[:, 2, 3] -= np.linspace(0.0, 5e-4, 11)
    res = resolved_rate(pen, (poses, np.linspace(0.0, 0.04, 11)), q0)
    assert res.pinv_steps[0] == 0 and math.isinf(res.condition[0])
    assert np.all(np.isfinite(res.q)) and res.max_tracking_error < 1e-6
