"""planning.cell.model: a cell tied to a robot — body names looked up, the tool on body n + 1, the
pairs never checked — and keep-out boxes as a cell."""
from __future__ import annotations

import numpy as np
import pytest

import kin
from kin.geometry import body_frames
from planning.cell import Cell, CellError, cell_from_keep_out, parse_cell
from planning.ompl.validity import KeepOutBox

CELL = """
length_unit = "mm"
[robot]
xyz = [100, 0, 800]
rpy = [0, 0, 90]
[[obstacle]]
name = "table"
type = "box"
size = [1000, 1000, 40]
xyz = [0, 0, 780]
ignore = ["base", "J1"]
[[obstacle]]
name = "part"
type = "sphere"
radius = 30
xyz = [500, 0, 900]
ignore = ["tool", "Link 6"]
[[tool]]
name = "torch"
type = "capsule"
a = [0, 0, 0]
b = [0, 0, 150]
radius = 15
[allow]
pairs = [["link 5", "tool"], ["link 2 (J2)", "part"], ["base", "link 4"]]
"""


@pytest.fixture(scope="module")
def fanuc():
    return kin.load_robot("fanuc_lrmate200id")


def test_names_become_bodies(fanuc):
    r = parse_cell(CELL, "c.toml").resolve(fanuc)
    n = fanuc.n
    table, part = r.obstacles
    assert table.ignore == {0, 1} and part.ignore == {n + 1, 6, 2}
    assert (5, n + 1) in r.geometry.allowed and (0, 4) in r.geometry.allowed
    assert (5, n + 1) not in r.self_pairs and (0, 4) not in r.self_pairs and (0, 3) in r.self_pairs
    assert r.self_pairs == tuple(r.geometry.checked_pairs(n))
    torch = [c for c in r.geometry.capsules if c.name == "torch"]
    assert len(torch) == 1 and torch[0].body == n + 1 and torch[0].b == pytest.approx((0, 0, 0.15))
    assert r.geometry.source == fanuc.geometry.source + " + cell tool"
    assert len(r.geometry.capsules) == len(fanuc.geometry.capsules) + 1
    checked = r.obstacle_pairs()
    assert (0, 0) not in checked and (2, 0) in checked and (n + 1, 1) not in checked and (3, 1) in checked
    assert "  obstacle 'part': sphere, 1 primitive(s); may touch: link 2 (J2), link 6 (J6), tool" in r.describe()


def test_the_base_places_the_robot(fanuc):
    r = parse_cell(CELL, "c.toml").resolve(fanuc)
    q = np.array([0.3, -0.2, 0.4, 1.0, -0.5, 0.7])
    F = body_frames(fanuc.chain, q, base=r.base)[0]
    # the tool frame in the cell: the placement (yaw 90°, at (0.1, 0, 0.8)) times the robot's own FK
    expect = np.array([[0, -1, 0, 0.1], [1, 0, 0, 0], [0, 0, 1, 0.8], [0, 0, 0, 1]]) @ fanuc.fk(q)
    assert F[-1] == pytest.approx(expect, abs=1e-12)
    assert F[0][:3, 3] == pytest.approx([0.1, 0, 0.8])


@pytest.mark.parametrize("where, name", [("ignore", "link 7"), ("ignore", "J9"), ("pair", "wrist"),
                                         ("pair", "link 0")])
def test_an_unknown_body_lists_the_valid_ones(fanuc, where, name):
    text = ('[[obstacle]]\nname = "p"\ntype = "sphere"\nradius = 1\n'
            + (f'ignore = ["{name}"]\n' if where == "ignore" else f'[allow]\npairs = [["tool", "{name}"]]\n'))
    with pytest.raises(CellError) as e:
        parse_cell(text, "c.toml").resolve(fanuc)
    msg = str(e.value)
    assert msg.startswith("c.toml: ") and "\n" not in msg
    assert f"'{name}' is not a body of fanuc_lrmate200id" in msg
    assert "bodies: base, link 1 (J1), link 2 (J2), link 3 (J3), link 4 (J4), link 5 (J5), link 6 (J6), tool" in msg


def test_a_body_paired_with_itself(fanuc):
    with pytest.raises(CellError, match=r"names body 6 twice"):
        parse_cell('[allow]\npairs = [["J6", "link 6"]]\n', "c.toml").resolve(fanuc)


UNNAMED = """
name = "two_links"
convention = "standard"
length_unit = "m"
angle_unit = "deg"
[[joints]]
type = "revolute"
a = 0.5
limits = [-180, 180]
[[joints]]
type = "revolute"
a = 0.4
limits = [-180, 180]
"""


def test_a_chain_without_joint_names_and_its_own_geometry():
    robot = kin.Robot(kin.loads_robot(UNNAMED, "two_links.toml"))
    cell = parse_cell('[[obstacle]]\nname = "post"\ntype = "cylinder"\nradius = 0.1\nlength = 1\n'
                      'ignore = ["link 1"]\n[[tool]]\ntype = "sphere"\ncenter = [0, 0, 0]\nradius = 0.02\n', "c.toml")
    r = cell.resolve(robot.chain)                            # a chain works as well as a robot
    assert r.obstacles[0].ignore == {1}
    assert [c.body for c in r.geometry.capsules if c.name == "tool"][-1] == robot.n + 1
    with pytest.raises(CellError, match=r"bodies: base, link 1, link 2, tool"):
        parse_cell('[allow]\npairs = [["J1", "tool"]]\n', "c.toml").resolve(robot)
    own = robot.geometry.with_allowed([(0, 2)])
    assert (0, 2) in cell.resolve(robot, geometry=own).geometry.allowed


def test_keep_out_boxes_become_box_obstacles(fanuc):
    boxes = [KeepOutBox((0.4, -0.2, 0.0), (0.7, 0.2, 0.3)), KeepOutBox((-1, -1, -1), (1, 1, 1), all_frames=True)]
    cell = cell_from_keep_out(boxes)
    assert isinstance(cell, Cell) and [o.name for o in cell.obstacles] == ["box 1", "box 2"]
    (s,) = cell.obstacles[0].shapes
    assert s.kind == "box" and s.size == pytest.approx((0.15, 0.2, 0.15))
    assert s.pose[:3, 3] == pytest.approx([0.55, 0, 0.15]) and np.array_equal(s.pose[:3, :3], np.eye(3))
    assert np.array_equal(cell.base, np.eye(4))
    r = cell.resolve(fanuc)
    assert all(not o.ignore for o in r.obstacles)
    with pytest.raises(CellError, match="box 1: lower"):
        cell_from_keep_out([KeepOutBox((0, 0, 1), (1, 1, 0))])


def test_a_cell_built_in_code_is_checked():
    from kin.geometry import Obstacle, Shape
    ob = Obstacle("a", (Shape("sphere", (1, 0, 0)),))
    with pytest.raises(CellError, match="the name 'a' is used twice"):
        Cell("c", (ob, ob))
    with pytest.raises(CellError, match="rigid"):
        Cell("c", (ob,), base=np.diag([1, 1, 2, 1.0]))
    with pytest.raises(CellError, match="names obstacle 'b'"):
        Cell("c", (ob,), obstacle_pairs=(("b", "tool"),))
