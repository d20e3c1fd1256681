"""Issue 29's acceptance pick-and-place on the bundled UR5e shelf cell: from home, windows of 5°, goals
by pose in the CELL frame, each move starting where the last ended — through the Python API and the
CLI.  Pick A, place low, pick B and place high all plan, proven (windows, σ_min floor, collisions),
every joint travelling far less than a turn, re-checked densely by check_path.  Place low is the move
the capsules alone refused (its branches on the start's side come within a centimetre of themselves and
of the table, closer than the capsules stand out of the arm): the UR5e's hulls of its maker's meshes
(``[[geometry.hull]]``) prove it clear."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kin
from kin.transforms import make_transform, rpy_to_matrix
from planning.collision import collision_world
from planning.ompl.planner import plan
from planning.validate import check_path
from planning.windows import build_windows
from studies.cli import main
from studies.cli.common import bundled_cells, cell_file
from tests.dh_numpy import fk_numpy

HOME = [0, -90, 90, -90, -90, 0]
PICK_A, PLACE_LOW = (0.45, -0.20, 0.95, 180, 0, 0), (0.10, 0.40, 1.08, -90, 0, 0)
PICK_B, PLACE_HIGH = (0.55, 0.10, 0.95, 180, 0, 0), (0.10, 0.40, 1.38, -90, 0, 0)


def _pose(t):
    return make_transform(rpy_to_matrix(np.radians(t[3:])), np.array(t[:3], dtype=float))


def test_the_cell_is_bundled():
    assert "ur5e_shelf_cell" in bundled_cells()
    text = cell_file("ur5e_shelf_cell").read_text()
    assert text.startswith("# UR5e pick-and-place cell") and "# base on the table top" in text


def _check_move(robot, ws, world, res, target):
    assert res.success and res.proven and res.proof.proven
    assert res.check.collision_check == "proven"
    travel = np.abs(np.diff(res.path, axis=0)).sum(axis=0)
    assert travel.max() <= math.pi                        # no joint travels more than half a turn
    F = world.base @ fk_numpy(robot.chain, res.path[-1])  # the goal reaches the target in the cell frame
    assert np.abs(F - _pose(target)).max() < 1e-8
    dense = check_path(robot, res.path, ws, 1e-3, world=world)
    assert dense.valid and dense.min_clearance > 0


@pytest.mark.slow
def test_pick_and_place_python_api():
    robot = kin.load_robot("ur5e")
    ws = build_windows(robot, margin=math.radians(5))
    world = collision_world(robot, cell_file("ur5e_shelf_cell"))
    q = robot.chain.to_si(HOME)
    res = plan(robot, q, None, ws, goal_pose=_pose(PICK_A), goal_frame="cell", world=world, sigma_min=1e-3)
    _check_move(robot, ws, world, res, PICK_A)
    q = res.path[-1]
    for target in (PLACE_LOW, PICK_B, PLACE_HIGH, PICK_A):       # on from where the last move ended
        res = plan(robot, q, None, ws, goal_pose=_pose(target), goal_frame="cell", world=world, sigma_min=1e-3)
        _check_move(robot, ws, world, res, target)
        q = res.path[-1]


def _cli(capsys, start, target, tmp_path, name):
    out_csv = tmp_path / f"{name}.csv"
    rc = main(["plan", "ur5e", "--start", *map(str, start), "--goal-pose", *map(str, target), "--cell",
               "ur5e_shelf_cell", "--margin", "5", "--json", "--out", str(out_csv)])
    out, _ = capsys.readouterr()
    return rc, json.loads(out), out_csv


@pytest.mark.slow
def test_pick_and_place_cli(capsys, tmp_path):
    robot = kin.load_robot("ur5e")
    world = collision_world(robot, cell_file("ur5e_shelf_cell"))
    start = HOME
    for name, target in (("pick_a", PICK_A), ("place_low", PLACE_LOW), ("pick_b", PICK_B),
                         ("place_high", PLACE_HIGH)):
        rc, d, out_csv = _cli(capsys, start, target, tmp_path, name)
        assert d["goal_frame"] == "cell"
        assert rc == 0 and d["success"] and d["proven"] and d["checks"]["collisions"] == "proven"
        P = np.array(d["path"])
        assert np.abs(np.diff(P, axis=0)).sum(axis=0).max() <= 180.0
        F = world.base @ fk_numpy(robot.chain, robot.chain.to_si(P[-1]))
        assert np.abs(F - _pose(target)).max() < 1e-6
        rc2 = main(["check-path", "ur5e", str(out_csv), "--cell", "ur5e_shelf_cell", "--margin", "5"])
        capsys.readouterr()
        assert rc2 == 0
        start = list(P[-1])
    rc, _, _ = _cli(capsys, HOME, PICK_A, tmp_path, "text")
    main(["plan", "ur5e", "--start", *map(str, HOME), "--goal-pose", *map(str, PICK_A), "--cell", "ur5e_shelf_cell",
          "--margin", "5"])
    text, _ = capsys.readouterr()
    assert "goal pose (cell frame of 'ur5e shelf cell'): goal q = (-39.668, -76.876, 121.77, -134.89, -90, " in text
