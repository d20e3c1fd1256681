"""studies.study.drawing: the drawing task of the ur3_drawing study (docs/machines.md §6) — its path
against the task's geometry, the singular start, the homework's Jacobian against the correct one,
and the comparison run_drawing_study makes (naive resolved rate against the OSQP follower).

Tracking errors are recomputed with the plain numpy DH of ``dh_numpy`` (not rmtkit's kinematics).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from planning.windows import build_windows
from studies.study.drawing import START_Q, drawing_path, homework_jacobian, pen_robot, run_drawing_study
from tests.dh_numpy import pose_errors_numpy


@pytest.fixture(scope="module")
def pen():
    return pen_robot()


@pytest.fixture(scope="module")
def pen_windows(pen):
    return build_windows(pen, margin=math.radians(5.0))


@pytest.fixture(scope="module")
def drawing(pen, pen_windows):
    return run_drawing_study(pen, windows=pen_windows, modes=("pose", "position"), series=True)


def test_drawing_path_geometry(pen):
    poses, t, _ = drawing_path(pen, START_Q)
    assert poses.shape == (5001, 4, 4) and t[-1] == pytest.approx(20.0) and t[1] == pytest.approx(0.004)
    p = poses[:, :3, 3]
    # docs/machines.md §6: the pen pose (-0.2173, -0.3878, 1.03611) m; x fixed; closed path
    np.testing.assert_allclose(p[0], [-0.2173, -0.3878, 1.03611], atol=1e-5)
    np.testing.assert_allclose(p[:, 0], p[0, 0], atol=1e-15)
    np.testing.assert_allclose(p[-1], p[0], atol=1e-12)
    R, y0, z0 = 0.05, p[0, 1], p[0, 2]
    corners = p[[1000, 2000, 3000, 4000], 1:]
    np.testing.assert_allclose(corners, [[y0 - R, z0 - R], [y0 - R, z0 - 2 * R], [y0 + R, z0 - 2 * R],
                                         [y0 + R, z0 - R]], atol=1e-12)
    # counter-clockwise seen from +x (y right, z up): the signed area is positive
    yz = p[:, 1:]
    area = 0.5 * np.sum(yz[:-1, 0] * yz[1:, 1] - yz[1:, 0] * yz[:-1, 1])
    assert area == pytest.approx(math.pi * R * R / 2 + 2 * R * R, rel=1e-4)
    # the orientation is held
    np.testing.assert_allclose(poses[:, :3, :3], np.broadcast_to(poses[0, :3, :3], (5001, 3, 3)), atol=0)


def test_start_pose_is_exactly_singular_and_loses_a_pen_tilt(drawing):
    st = drawing["start"]
    assert st["sigma_min"] < 1e-12
    # the lost twist is a rotation about base y, not about the pen axis (−x)
    np.testing.assert_allclose(st["lost_twist"], [0, 0, 0, 0, 1, 0], atol=1e-9)
    np.testing.assert_allclose(st["pen_axis"], [-1, 0, 0], atol=1e-12)
    assert st["lost_rotation_about_pen_axis"] < 1e-9


def test_qp_completes_the_drawing_within_tolerance(pen, drawing):
    tol_p, tol_o = drawing["tolerance"]["position_m"], drawing["tolerance"]["orientation_rad"]
    assert (tol_p, tol_o) == (1e-3, pytest.approx(math.radians(1)))
    d = drawing["qp"]["pose"]
    assert d["within_tolerance"]
    assert d["max_position_error_m"] <= tol_p and d["max_orientation_error_rad"] <= tol_o
    # independent check of the run's errors on every 10th waypoint, with the numpy DH
    poses, _, _ = drawing_path(pen, START_Q)
    Q = drawing["series"]["qp_pose"]["q"]
    pe, oe = pose_errors_numpy(pen.chain, Q[::10], poses[::10])
    assert pe.max() <= tol_p and oe.max() <= tol_o
    assert pe.max() == pytest.approx(drawing["series"]["qp_pose"]["position_error"][::10].max(), abs=1e-12)
    # speed limits: default π rad/s
    assert d["speed_ratio"] <= 1 + 1e-9


def test_naive_homework_method_blows_up_qp_does_not(drawing):
    nh, qp = drawing["naive_homework"], drawing["qp"]["pose"]
    assert nh["pinv_steps"] >= 1 and nh["first_pinv_steps"][0] == 0       # J exactly singular at the start
    assert nh["peak_joint_speed"] >= 1e3 * qp["peak_joint_speed"]        # measured ~1e19×
    assert nh["max_position_error_m"] > 0.01 and not nh["within_tolerance"]
    assert qp["peak_joint_speed"] < 0.2                                    # measured 0.057 rad/s


def test_naive_method_with_the_correct_jacobian(drawing, pen):
    # honest finding: with the right Jacobian the naive method survives this particular path
    nv = drawing["naive"]
    assert nv["first_pinv_steps"] == [0]             # solve raised at the exactly singular start
    assert nv["singular_steps"] >= 1
    assert nv["within_tolerance"] and nv["max_position_error_m"] < 1e-4
    assert nv["peak_joint_speed"] == pytest.approx(drawing["qp"]["pose"]["peak_joint_speed"], rel=0.2)


def test_homework_jacobian_uses_axes_z1_to_z6(pen):
    # the correct Jacobian's column i uses z_{i-1}; the homework's uses z_i: its last column is
    # [z6 × 0; z6] and its first column is the correct second column's axis
    q = np.array([0.1, 0.2, 1.3, -1.1, 0.4, 0.3])
    Jh = homework_jacobian(pen)(q)
    J = pen.jacobian(q)
    T = pen.fk(q)
    np.testing.assert_allclose(Jh[:3, -1], 0, atol=1e-12)
    np.testing.assert_allclose(Jh[3:, -1], T[:3, 2], atol=1e-12)
    np.testing.assert_allclose(Jh[3:, :-1], J[3:, 1:], atol=1e-12)


def test_windows_only_where_the_path_forces_them(drawing):
    pose, pos = drawing["qp"]["pose"], drawing["qp"]["position"]
    # pose mode: the whole drawing lies on the wrist singular set (θ5 = 0 forced), every step forced
    assert [w["name"] for w in pose["windows_entered"]] == ["wrist: sin(q5)"]
    assert pose["windows_entered"][0]["ranges"] == [[0, 5000]]
    assert pose["forced_steps"] == 5000
    assert pose["max_abs_q5_rad"] < 1e-6 and pose["max_abs_q1_rad"] < 1e-6
    # position mode: not forced — out of the wrist window within the first 2 s, and never back
    ranges = pos["windows_entered"]
    assert len(ranges) == 1 and ranges[0]["ranges"][0][0] == 0 and len(ranges[0]["ranges"]) == 1
    assert ranges[0]["ranges"][0][1] < 500
    assert pos["forced_steps"] == 0
    assert pos["max_position_error_m"] <= 1e-3
    s = drawing["series"]["qp_position"]["in_window"]
    assert np.all(s[ranges[0]["ranges"][0][1] + 1:] == -1)
