"""``--tcp X Y Z [R P Y]``: the tool point moved after the robot file's [tool] — FK with it is FK
without it times the offset (plain numpy), a plan to a goal pose puts the offset point on the pose,
the tool's capsules and a cell's tool stay where they are, and bad values are one line, exit 2."""
from __future__ import annotations

import contextlib
import io
import json
import math

import numpy as np
import pytest

import kin
from kin.tcp import tcp_transform, with_tcp
from studies.cli import main


def run(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    return rc, out.getvalue(), err.getvalue()


def _offset(x, y, z, r=0.0, p=0.0, w=0.0) -> np.ndarray:
    """xyz + fixed-axis roll-pitch-yaw (degrees) → 4×4, plain numpy: Rz(w)·Ry(p)·Rx(r)."""
    r, p, w = np.radians([r, p, w])
    Rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
    Ry = np.array([[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]])
    Rz = np.array([[math.cos(w), -math.sin(w), 0], [math.sin(w), math.cos(w), 0], [0, 0, 1]])
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = Rz @ Ry @ Rx, [x, y, z]
    return T


Q = ["10", "-80", "100", "-60", "-90", "30"]


@pytest.mark.parametrize("tcp", [("0", "0", "0.15"), ("0.02", "-0.01", "0.2", "30", "-20", "90")])
def test_fk_with_tcp_is_fk_times_the_offset(tcp):
    rc, out, err = run(["fk", "ur5e", *Q, "--json"])
    assert rc == 0, err
    T0 = np.array(json.loads(out)["T"])
    rc, out, err = run(["fk", "ur5e", *Q, "--json", "--tcp", *tcp])
    assert rc == 0, err
    T1 = np.array(json.loads(out)["T"])
    np.testing.assert_allclose(T1, T0 @ _offset(*map(float, tcp)), atol=1e-12)


def test_fk_with_tcp_in_millimetres():
    # abb_irb120 is written in mm and degrees: --tcp reads the file's units (FK prints them too)
    q = ["10", "20", "-30", "40", "-50", "60"]
    _, out, _ = run(["fk", "abb_irb120", *q, "--json"])
    T0 = np.array(json.loads(out)["T"])
    _, out, _ = run(["fk", "abb_irb120", *q, "--json", "--tcp", "0", "50", "120", "0", "90", "0"])
    T1 = np.array(json.loads(out)["T"])
    np.testing.assert_allclose(T1, T0 @ _offset(0, 50, 120, 0, 90, 0), atol=1e-9)


def test_plan_to_a_goal_pose_puts_the_offset_point_on_it():
    pose = [-0.45, -0.2, 0.3, 180, 0, 0]
    rc, out, err = run(["plan", "ur5e", "--start", "0", "-90", "90", "-90", "-90", "0", "--goal-pose",
                        *map(str, pose), "--tcp", "0", "0", "0.1", "--json"])
    assert rc == 0, err
    goal = json.loads(out)["goal"]
    rc, out, _ = run(["fk", "ur5e", *map(str, goal), "--json"])          # FK of the file's tool frame
    T = np.array(json.loads(out)["T"]) @ _offset(0, 0, 0.1)
    np.testing.assert_allclose(T, _offset(*pose), atol=1e-6)


def test_the_physical_tool_stays_put():
    robot = kin.load_robot("ur5e")
    T = tcp_transform([0.01, 0.02, 0.15, 10, 0, 45], "m", "deg")
    moved = with_tcp(robot, T)
    assert np.allclose(moved.tcp, T) and with_tcp(robot, np.eye(4)) is robot
    q = np.radians([10, -80, 100, -60, -90, 30])
    np.testing.assert_allclose(moved.fk(q), robot.fk(q) @ T, atol=1e-12)
    # capsules on the tool body and a cell's tool: the same clearances with and without the offset
    from pathlib import Path

    from kin.geometry import ClearanceModel
    from planning.cell import load_cell
    from planning.collision import collision_world
    cell = load_cell(Path(__file__).parents[3] / "studies" / "cells" / "fanuc_weld_cell.toml")
    fanuc = kin.load_robot("fanuc_m16ib20")
    f2 = with_tcp(fanuc, tcp_transform([0, 30, 200, 0, 20, 0], "mm", "deg"))
    Qs = np.radians([[0, 0, 0, 0, -30, 0], [20, 30, -10, 40, -60, 10], [-40, 10, 20, -90, 45, 180]])
    np.testing.assert_allclose(collision_world(f2, cell).clearance(Qs), collision_world(fanuc, cell).clearance(Qs),
                               atol=1e-12)
    g = moved.geometry
    np.testing.assert_allclose(ClearanceModel(moved, g).clearance(np.atleast_2d(q)),
                               ClearanceModel(robot, robot.geometry).clearance(np.atleast_2d(q)), atol=1e-12)


@pytest.mark.parametrize("tcp, msg", [(["0", "0"], "expected 3 or 6 numbers"), (["0", "0", "nan"], "z = nan"),
                                      (["0", "0", "1e5"], "within ±10000 m"), (["0", "0", "0", "0", "0", "361"],
                                                                              "yaw = 361.0 must be"),
                                      (["0", "x", "0"], "expected 3 or 6 numbers"),
                                      (["0", "0", "inf"], "z = inf")])
def test_hostile_tcp(tcp, msg):
    rc, out, err = run(["fk", "ur5e", *Q, "--tcp", *tcp])
    assert rc == 2 and out == "" and err.startswith("rmt: error: --tcp") and msg in err
    assert len(err.strip().splitlines()) == 1
