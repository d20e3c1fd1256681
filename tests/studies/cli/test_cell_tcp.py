"""A work cell's ``[[tool]] tcp = [x, y, z, roll, pitch, yaw]`` (the cell's units): with ``--cell`` the
commands that take ``--tcp`` use it exactly as ``--tcp`` (the same goals, the same IK), ``--tcp`` overrides
it with a note on stderr, the Python cell exposes it (``Cell.tcp``, ``Cell.with_tcp``), and hostile
values are one line naming the file, the table and the range, exit 2."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kin
from planning.cell import cell_tcp, load_cell, parse_cell
from planning.errors import CellError
from tests.studies.cli.test_tcp import _offset, run

# the same offset as a cell in mm (the cell's units) and as --tcp on ur5e (its file: m, deg)
CELL_MM = 'length_unit = "mm"\nangle_unit = "deg"\n[[tool]]\ntcp = [20, -10, 150, 0, 20, 90]\n'
TCP_M = ["0.02", "-0.01", "0.15", "0", "20", "90"]
OFFSET = _offset(0.02, -0.01, 0.15, 0, 20, 90)
START = ["0", "-90", "90", "-90", "-90", "0"]
POSE = [-0.45, -0.2, 0.3, 180, 0, 0]


@pytest.fixture
def cell_mm(tmp_path):
    p = tmp_path / "tcp_cell.toml"
    p.write_text(CELL_MM)
    return str(p)


def test_the_cell_holds_the_tcp_in_si():
    cell = parse_cell('length_unit = "in"\nangle_unit = "rad"\n[[tool]]\nname = "torch"\ntype = "sphere"\n'
                      'center = [0, 0, 4]\nradius = 1\ntcp = [1, 2, 3, 0.5, 0, 0]\n', "c.toml")
    np.testing.assert_allclose(cell.tcp, _offset(0.0254, 0.0508, 0.0762, math.degrees(0.5)), atol=1e-15)
    assert len(cell.tool) == 1                            # the table holding the tcp is a shape too
    only = parse_cell('[[tool]]\ntcp = [0, 0, 0.1]\n', "c.toml")
    assert only.tool == () and np.allclose(only.tcp, _offset(0, 0, 0.1))
    assert parse_cell("", "c.toml").tcp is None
    assert any("tool centre point (tcp): xyz 0 0 100 mm" in line for line in only.summary())


def test_fk_of_the_cells_robot_is_fk_times_the_offset(cell_mm):
    robot = kin.load_robot("ur5e")
    cell = load_cell(cell_mm)
    np.testing.assert_allclose(cell_tcp(cell_mm), cell.tcp, atol=0)
    moved = cell.with_tcp(robot)
    Q = np.radians([[10, -80, 100, -60, -90, 30], [-40, -120, 60, 10, 45, 200]])
    for q in Q:
        np.testing.assert_allclose(moved.fk(q), robot.fk(q) @ OFFSET, atol=1e-12)
    # a robot that carries a tcp of its own keeps it (as --tcp over the cell's)
    from kin.tcp import with_tcp
    own = with_tcp(robot, _offset(0, 0, 0.3))
    assert cell.with_tcp(own) is own and parse_cell("", "c").with_tcp(robot) is robot


def test_plan_to_a_goal_pose_with_the_cells_tcp_is_the_tcp_result(cell_mm):
    base = ["plan", "ur5e", "--start", *START, "--goal-pose", *map(str, POSE), "--json"]
    rc, out, err = run([*base, "--cell", cell_mm])
    assert rc == 0 and err == "", err
    via_cell = json.loads(out)
    rc, out, err = run([*base, "--tcp", *TCP_M, "--self-collision"])
    assert rc == 0, err
    via_tcp = json.loads(out)
    np.testing.assert_allclose(via_cell["goal"], via_tcp["goal"], atol=1e-9)
    # and the goal puts the offset point on the pose: FK of the file's tool frame (rmt fk) times the offset
    rc, out, _ = run(["fk", "ur5e", *map(str, via_cell["goal"]), "--json"])
    np.testing.assert_allclose(np.array(json.loads(out)["T"]) @ OFFSET, _offset(*POSE), atol=1e-6)


def test_the_python_plan_with_the_cells_robot_uses_the_offset(cell_mm):
    from planning.collision import collision_world
    from planning.ompl import plan
    cell = load_cell(cell_mm)
    robot = cell.with_tcp(kin.load_robot("ur5e"))
    world = collision_world(robot, cell)
    res = plan(robot, np.radians([float(v) for v in START]), goal_pose=_offset(*POSE), world=world,
               goal_frame="cell")
    assert res.success, res.status
    plain = kin.load_robot("ur5e")
    np.testing.assert_allclose(plain.fk(res.path[-1]) @ OFFSET, _offset(*POSE), atol=1e-6)


def test_tcp_overrides_the_cells_with_a_note(cell_mm):
    argv = ["ik", "ur5e", "--xyz", "-0.45", "-0.2", "0.3", "--rpy", "180", "0", "0", "--json", "--frame", "base"]
    rc, out, err = run([*argv, "--cell", cell_mm, "--tcp", "0", "0", "0.3"])
    assert rc == 0
    assert err.strip() == f"note: --tcp overrides the tool centre point of cell {cell_mm} ([[tool]] tcp)"
    q = np.radians(json.loads(out)["q"])
    T = kin.load_robot("ur5e").fk(q)
    np.testing.assert_allclose(T @ _offset(0, 0, 0.3), _offset(*POSE), atol=1e-9)
    # --tcp 0 0 0 overrides it too: the file's own tool frame
    rc, out, err = run([*argv, "--cell", cell_mm, "--tcp", "0", "0", "0"])
    assert rc == 0 and "overrides" in err
    np.testing.assert_allclose(kin.load_robot("ur5e").fk(np.radians(json.loads(out)["q"])), _offset(*POSE),
                               atol=1e-9)
    # without --tcp, the cell's: the same solutions as --tcp with the same offset
    rc, out, err = run([*argv, "--cell", cell_mm])
    rc2, out2, _ = run([*argv, "--tcp", *TCP_M, "--self-collision"])
    assert rc == rc2 == 0 and err == ""
    np.testing.assert_allclose([s["q"] for s in json.loads(out)["solutions"]],
                               [s["q"] for s in json.loads(out2)["solutions"]], atol=1e-9)


@pytest.mark.parametrize("body, msg", [
    ("[[tool]]\ntcp = [0, 0, nan]", "tool 1: tcp: z = nan must be a finite number within ±1e+07 mm"),
    ("[[tool]]\ntcp = [0, 0, inf]", "tool 1: tcp: z = inf must be a finite number within ±1e+07 mm"),
    ("[[tool]]\ntcp = [0, 0, 2e7]", "tool 1: tcp: z = 20000000.0 must be a finite number within ±1e+07 mm"),
    ("[[tool]]\ntcp = [0, 0, 0, 0, 0, 361]", "tool 1: tcp: yaw = 361.0 must be a finite number within ±360 deg"),
    ("[[tool]]\ntcp = [0, 0]", "tool 1: tcp: must be [x, y, z] or [x, y, z, roll, pitch, yaw] (mm, deg)"),
    ("[[tool]]\ntcp = [0, 0, 0, 0]", "tool 1: tcp: must be [x, y, z] or [x, y, z, roll, pitch, yaw]"),
    ('[[tool]]\ntcp = ["1", 0, 0]', "tool 1: tcp: must be [x, y, z] or"),
    ("[[tool]]\ntcp = [true, 0, 0]", "tool 1: tcp: must be [x, y, z] or"),
    ("[[tool]]\ntcp = 150", "tool 1: tcp: must be [x, y, z] or"),
    ("[[tool]]\ntcp = [0, 0, 1]\n[[tool]]\ntcp = [0, 0, 2]",
     "tool 2: tcp: the tool centre point is already set by tool 1; a cell file holds one tcp"),
    ("[[tool]]\ntcp = [0, 0, 1]\nradius = 5", "tool 1: type: required; one of: capsule, sphere"),
    ("[[tool]]\ntcp = [0, 0, 1]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 5\nsize = 3",
     "tool 1: unknown key(s) size"),
])
def test_hostile_cell_tcp(tmp_path, body, msg):
    p = tmp_path / "bad.toml"
    p.write_text('length_unit = "mm"\n' + body + "\n")
    rc, out, err = run(["ik", "ur5e", "--xyz", "-0.45", "-0.2", "0.3", "--cell", str(p)])
    assert rc == 2 and out == "" and err.startswith(f"rmt: error: {p}: {msg}")
    assert len(err.strip().splitlines()) == 1
    with pytest.raises(CellError, match="tcp|type|unknown"):           # the Python reader: the same error
        load_cell(p)


def test_hostile_tcp_in_radians(tmp_path):
    p = tmp_path / "rad.toml"
    p.write_text('angle_unit = "rad"\n[[tool]]\ntcp = [0, 0, 0, 7, 0, 0]\n')
    with pytest.raises(CellError, match=r"tool 1: tcp: roll = 7.0 must be a finite number within ±6.28319 rad"):
        cell_tcp(p)


def test_a_task_files_cell_sets_the_tcp_unless_tcp_or_cell_is_given(cell_mm, capsys):
    # rmt reach, place and coverage: a task file's cell (no --cell) sets the tool point as --cell would
    from argparse import Namespace

    from studies.cli.tcp import with_task_cell_tcp
    robot, cell = kin.load_robot("ur5e"), load_cell(cell_mm)
    q = np.radians([10, -80, 100, -60, -90, 30])
    moved = with_task_cell_tcp(Namespace(tcp=None, cell=None), robot, cell)
    np.testing.assert_allclose(moved.fk(q), robot.fk(q) @ OFFSET, atol=1e-12)
    assert with_task_cell_tcp(Namespace(tcp=["0", "0", "0"], cell=None), robot, cell) is robot
    assert capsys.readouterr().err.startswith("note: --tcp overrides the tool centre point of cell")
    assert with_task_cell_tcp(Namespace(tcp=None, cell="other.toml"), robot, cell) is robot   # the loader's
    assert with_task_cell_tcp(Namespace(tcp=None, cell=None), robot, None) is robot
