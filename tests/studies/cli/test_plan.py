"""rmt plan: impossible queries answered with the reason, tool-pose goals, keep-out boxes from the
command line and from a cell file; bad input exits 2 with one line."""
import json

import numpy as np
import pytest

import kin
from studies.cli import main

START = ["0", "-0.3", "0.4", "0.2", "-0.6", "0"]


def _run(argv, capsys):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def test_separated_goal_is_refused_with_the_reason(capsys):
    rc, out, err = _run(["plan", "fanuc_m16ib20", "--start", *START, "--goal", "0.4", "-0.2", "0.3", "-0.2", "0.8",
                         "0.1", "--margin", "0.05", "--json"], capsys)
    d = json.loads(out)
    assert rc == 1 and not d["success"] and d["separation"]["kind"] == "slab" and d["separation"]["joints"] == [5]
    assert "q5 ∈ [-0.05 rad, 0.05 rad] separates start (q5 = -0.6 rad) and goal (q5 = 0.8 rad)" in d["status"]


def test_goal_pose_takes_the_branch_on_the_start_side(capsys):
    robot = kin.load_robot("fanuc_m16ib20")
    far = np.array([0.4, -0.2, 0.3, -0.2, 0.8, 0.1])          # q5 > 0: across the wrist window from the start
    T = robot.fk(far)
    from kin.transforms import matrix_to_rpy
    rpy = matrix_to_rpy(T[:3, :3])
    pose = [repr(float(x)) for x in (*T[:3, 3], *rpy)]
    rc, out, err = _run(["plan", "fanuc_m16ib20", "--start", *START, "--goal-pose", *pose, "--margin", "0.05",
                         "--json"], capsys)
    d = json.loads(out)
    assert rc == 0 and d["success"] and d["proven"] and d["checks"]["windows"] == "proven"
    last = np.array(d["path"][-1])
    assert last[4] < 0 and np.abs(robot.fk(last) - T).max() < 1e-8
    assert d["goal_branch"]["in_start_cell"] >= 1


def _blocking_box(robot, s, g):
    """A small box at the straight line's middle that the line's robot (not only its tool point)
    passes through while start and goal stay clear of it: (lower, upper) in m."""
    from planning.cell import cell_from_keep_out
    from planning.collision import CollisionWorld
    from planning.ompl import KeepOutBox
    mid = robot.fk(0.5 * (s + g))
    t = np.linspace(0, 1, 200)
    for off in (0.0, 0.05, 0.1, 0.15, 0.2):
        for h in (0.01, 0.02, 0.04):
            c = mid[:3, 3] + off * mid[:3, 2]
            box = cell_from_keep_out([KeepOutBox(tuple(c - h), tuple(c + h))]).obstacles
            world = CollisionWorld(robot, obstacles=box)
            line = world.clearance(s + t[:, None] * (g - s))
            if world.clearance(s) > 0 and world.clearance(g) > 0 and line.min() < 0:
                return c - h, c + h, world
    raise AssertionError("no box blocks the straight line but leaves start and goal clear")


def test_keep_out_box_and_file(tmp_path, capsys):
    """Keep-out boxes are cell obstacles: the whole robot (its capsules) stays clear of them."""
    robot = kin.load_robot("fanuc_m16ib20")
    s = np.array([float(x) for x in START])
    goal = np.array([0.3, -0.2, 0.3, 0.1, -0.8, 0.1])
    lo, hi, world = _blocking_box(robot, s, goal)
    scale = robot.chain.length_scale
    cell = tmp_path / "cell.toml"
    cell.write_text(f"length_unit = 'mm'\n[[box]]\nlower = {(lo * 1000).tolist()}\nupper = {(hi * 1000).tolist()}\n")
    t = np.linspace(0, 1, 400)
    corners = [repr(float(x) / scale) for x in (*lo, *hi)]
    for extra in (["--keep-out", str(cell)], ["--keep-out-box", *corners]):
        rc, out, err = _run(["plan", "fanuc_m16ib20", "--start", *START, "--goal", *(repr(float(x)) for x in goal),
                             "--margin", "0.05", "--json", *extra], capsys)
        d = json.loads(out)
        assert rc == 0 and d["success"] and d["keep_out_boxes"] == 1 and d["checks"]["collisions"] == "proven"
        P = robot.chain.to_si(np.array(d["path"]))
        assert len(P) > 2                                      # the straight line is blocked
        for a, b in zip(P[:-1], P[1:]):
            assert world.clearance(a + t[:, None] * (b - a)).min() > 0


@pytest.mark.parametrize("extra, words", [
    (["--keep-out-box", "1", "1", "1", "0", "0", "0"], "--keep-out-box"),
    (["--keep-out", "/nonexistent/cell.toml"], "no such keep-out file"),
    (["--goal-pose", "1", "0", "1", "0", "90", "0"], "R P Y must be within"),
])
def test_bad_input_is_one_line(extra, words, capsys):
    argv = ["plan", "fanuc_m16ib20", "--start", *START, "--margin", "0.05"]
    argv += extra if "--goal-pose" in extra else ["--goal", *START, *extra]
    rc, out, err = _run(argv, capsys)
    assert rc == 2 and words in err and err.count("\n") == 1
