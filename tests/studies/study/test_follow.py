"""studies.study.follow: the task a path asks of a robot, a start from IK of the first waypoint, both
methods summed up the same way (checked against the runs' own arrays and a numpy DH product), the
JSON in the robot file's units, the figure, and solver output kept off standard output."""
from __future__ import annotations

import ctypes
import json
import math

import numpy as np
import pytest

import kin
from planning.toolpath import load_toolpath
from planning.windows import build_windows
from studies.study.follow import (
    MODES,
    check_mode,
    default_mode,
    follow_toolpath,
    solver_output_silenced,
    start_configuration,
)
from studies.toolpaths import toolpath_file
from tests.dh_numpy import fk_numpy


@pytest.fixture(scope="module")
def scara():
    return kin.load_robot("scara_rrp")


@pytest.fixture(scope="module")
def scara_run(scara):
    path = load_toolpath(toolpath_file("scara_line"), scara)
    q0, info = start_configuration(scara, path.poses[0], "position")
    return path, follow_toolpath(scara, path, q0, build_windows(scara, margin=0.05), mode="position",
                                 tolerance=(5e-3, math.radians(1)), naive=True, start=info)


def test_modes_are_the_followers():
    from planning.follow import MODES as FOLLOWER_MODES
    assert tuple(MODES) == tuple(FOLLOWER_MODES)


def test_the_task_a_path_asks(scara):
    ur = kin.load_robot("ur3_homework_pen")
    assert default_mode(ur, True) == "pose" and default_mode(ur, False) == "position"
    assert default_mode(scara, True) == "position"            # task rows x, y, z
    assert check_mode(ur, "axis", True) == "axis"
    with pytest.raises(kin.RmtError, match="--mode pose: the tool path gives positions only"):
        check_mode(ur, "pose", False, "--mode")
    with pytest.raises(kin.RmtError, match="mode axis: scara_rrp controls no tool orientation .task rows x, y, z"):
        check_mode(scara, "axis", True)
    with pytest.raises(kin.RmtError, match="unknown; allowed: pose, axis, position"):
        check_mode(ur, "joint", True)


def test_start_is_ik_of_the_first_waypoint(scara_run, scara):
    path, c = scara_run
    assert c.start["from"] == "IK of waypoint 0" and c.start["success"]
    np.testing.assert_allclose(fk_numpy(scara.chain, c.q0)[:3, 3], path.poses[0][:3, 3], atol=1e-9)


def test_summaries_from_the_runs_themselves(scara_run, scara):
    path, c = scara_run
    assert [r.key for r in c.runs] == ["qp", "naive"] and c.mode == "position"
    for r in c.runs:
        s, res = r.summary, r.result
        # position errors recomputed with the numpy DH product at every waypoint
        pe = [np.linalg.norm(fk_numpy(scara.chain, q)[:3, 3] - T[:3, 3]) for q, T in zip(res.q, path.poses)]
        assert s["max_position_error"] == pytest.approx(max(pe), abs=1e-12)
        # joint speeds: finite differences of the joint path over the path's times
        v = np.abs(np.diff(res.q, axis=0)) / np.diff(path.t)[:, None]
        np.testing.assert_allclose(s["max_joint_speed"], v.max(axis=0), rtol=1e-12)
        assert s["peak_joint_speed"] == pytest.approx(v.max(axis=0)[s["peak_joint"] - 1])
        # the robot file gives no speeds: the defaults, π rad/s and 0.5 m/s
        assert s["max_speed_ratio"] == pytest.approx(float((v / [math.pi, math.pi, 0.5]).max()))
        assert s["max_orientation_error"] is None and s["mode"] == "position"
        assert s["waypoints_in_window"] == 0 and s["windows_entered"] == []
        assert s["within_tolerance"] == (max(pe) <= 5e-3)
    assert c.run("qp").summary["within_tolerance"] and c.ok
    # the open-loop method drifts further than the follower with its feedback
    assert c.run("naive").summary["max_position_error"] > 5 * c.run("qp").summary["max_position_error"]
    assert c.run("naive").summary["pinv_steps"] == 0             # the 3×3 position Jacobian is invertible


def test_json_in_the_robot_files_units(scara_run):
    _, c = scara_run
    d = json.loads(json.dumps(c.to_json(waypoints=True), allow_nan=False))
    qp, s = d["methods"]["qp"], c.run("qp").summary
    assert d["units"]["length"] == "mm" and d["units"]["joints"] == ["rad", "rad", "mm"]
    assert qp["max_position_error"] == pytest.approx(s["max_position_error"] * 1e3)
    assert qp["max_joint_speed"][2] == pytest.approx(s["max_joint_speed"][2] * 1e3)
    assert d["tolerance"]["position"] == pytest.approx(5.0) and d["windows"] == ["boundary: sin(q2)"]
    assert d["start"]["q"][2] == pytest.approx(c.q0[2] * 1e3) and d["length"] == pytest.approx(474.34, abs=0.01)
    w = qp["per_waypoint"]
    assert len(w["q"]) == d["waypoints"] == 21 and max(w["position_error"]) == pytest.approx(qp["max_position_error"])


def test_figure_is_written(scara_run, tmp_path):
    from studies.plots.follow import plot_follow
    _, c = scara_run
    out = plot_follow(c, tmp_path / "f.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 10_000


def test_a_path_without_times_is_refused(scara):
    from planning.follow import FollowError
    path = load_toolpath(toolpath_file("scara_line"), scara)
    path.t = None
    with pytest.raises(FollowError, match="no times"):
        follow_toolpath(scara, path, np.array([0.0, 0.5, -0.15]), mode="position")


def test_c_level_printf_is_silenced(capfd):
    libc = ctypes.CDLL(None)
    print("before", flush=True)
    with solver_output_silenced():
        libc.printf(b"ERROR in osqp_setup: P must be a valid upper triangular matrix\n")
    print("after", flush=True)
    out, err = capfd.readouterr()
    assert out == "before\nafter\n" and err == ""
