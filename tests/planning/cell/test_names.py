"""Obstacle names that are robot bodies' names (MoveIt scenes have an object called ``base``): they are
kept, every reference says unambiguously which one it means (``body:`` / ``obstacle:``), and the
collision world names the obstacle as ``obstacle 'base'``; clearances checked against numpy."""
from __future__ import annotations

import numpy as np
import pytest

import kin
from kin.geometry import body_frames
from planning.cell import CellError, parse_cell
from planning.cell.model import split_reference
from planning.collision import collision_world

# obstacles named like bodies: "base" (every robot's), "link 3" (every 3-joint robot's), "J3" (the FANUC's
# joint 3): a sphere in front of the robot, a box on the floor, a post
CELL = """
[[obstacle]]
name = "base"
type = "sphere"
radius = 0.05
xyz = [0.45, 0.1, 0.6]
ignore = ["base", "link 1"]          # in ignore, every name is a body: the robot's base and link 1

[[obstacle]]
name = "link 3"
type = "box"
size = [0.2, 0.2, 0.2]
xyz = [-0.6, 0, 0.1]

[[obstacle]]
name = "J3"
type = "cylinder"
radius = 0.05
length = 1.0
xyz = [0, -0.7, 0.5]

[allow]
pairs = [["obstacle:base", "link 6"],    # the obstacle named base may touch link 6
         ["body:base", "link 4"],         # the robot's base and link 4: a body pair
         ["link 2", "obstacle: link 3"],  # spaces after the colon are allowed
         ["obstacle:J3", "body:J3"]]      # the post and the robot's joint 3 body
"""


@pytest.fixture(scope="module")
def fanuc():
    return kin.load_robot("fanuc_lrmate200id")


def test_split_reference():
    assert split_reference("obstacle:base") == ("obstacle", "base")
    assert split_reference("Body :  link   3") == ("body", "link 3")
    assert split_reference("  table  top ") == (None, "table top")
    assert split_reference("obstacle:body:x") == ("obstacle", "body:x")      # one qualifier comes off
    assert split_reference("bodywork") == (None, "bodywork")


def test_body_names_are_obstacle_names_and_every_reference_is_unambiguous(fanuc):
    cell = parse_cell(CELL, "c.toml")
    assert [o.name for o in cell.obstacles] == ["base", "link 3", "J3"]
    assert cell.body_pairs == (("base", "link 4"),)
    assert set(cell.obstacle_pairs) == {("base", "base"), ("base", "link 1"), ("base", "link 6"),
                                        ("link 3", "link 2"), ("J3", "J3")}
    assert cell.unqualified == frozenset()
    r = cell.resolve(fanuc)
    sphere, box, post = r.obstacles
    assert sphere.ignore == {0, 1, 6} and box.ignore == {2} and post.ignore == {3}
    assert (0, 4) in r.geometry.allowed
    lines = r.describe()
    assert "  obstacle 'base': sphere, 1 primitive(s); may touch: base, link 1 (J1), link 6 (J6)" in lines
    assert "  obstacle 'link 3': box, 1 primitive(s); may touch: link 2 (J2)" in lines


def test_an_unqualified_pair_that_could_mean_a_joint_is_refused_when_tied_to_that_robot(fanuc):
    text = CELL.replace('["obstacle:J3", "body:J3"]', '["J3", "tool"]')
    cell = parse_cell(text, "c.toml")                   # at parse time J3 is the obstacle (no body is called J3 …)
    assert ("J3", "tool") in cell.obstacle_pairs and cell.unqualified == {"J3"}
    with pytest.raises(CellError) as e:                 # … but the FANUC's joint 3 is
        cell.resolve(fanuc)
    assert str(e.value) == ("c.toml: [allow]: 'J3' is both obstacle 'J3' and the body link 3 (J3) of "
                            "fanuc_lrmate200id; write 'obstacle:J3' or 'body:J3'")
    post = '[[obstacle]]\nname = "J3"\ntype = "sphere"\nradius = 0.1\n[allow]\npairs = [["J3", "tool"]]\n'
    chain = kin.loads_robot(UNNAMED, "three_links.toml")    # a robot without joint names: no doubt
    assert parse_cell(post, "c.toml").resolve(chain).obstacles[0].ignore == {4}
    with pytest.raises(CellError, match="'J3' is both obstacle 'J3' and the body link 3 \\(J3\\)"):
        parse_cell(post, "c.toml").resolve(fanuc)


UNNAMED = """
name = "three_links"
convention = "standard"
length_unit = "m"
angle_unit = "deg"
[[joints]]
type = "revolute"
a = 0.3
limits = [-180, 180]
[[joints]]
type = "revolute"
a = 0.3
limits = [-180, 180]
[[joints]]
type = "revolute"
a = 0.2
limits = [-180, 180]
"""


def _segment_distance(a, b, p):
    ab = b - a
    t = np.clip(np.dot(p - a, ab) / max(np.dot(ab, ab), 1e-300), 0.0, 1.0)
    return float(np.linalg.norm(a + t * ab - p))


def test_the_world_names_the_obstacle_and_its_clearance_is_numpys(fanuc):
    cell = parse_cell(CELL.split("[allow]")[0], "c.toml")        # no pairs: only the sphere's own ignore
    world = collision_world(fanuc, cell)
    q = np.radians([20, 30, -10, 0, -60, 0])
    obs, _ = world.per_body(q[None])
    F = body_frames(fanuc.chain, q[None], base=world.base)[0]
    centre, radius = np.array([0.45, 0.1, 0.6]), 0.05
    for body in world.geometry.bodies():
        caps = [c for c in world.geometry.capsules if c.body == body]
        expect = min(_segment_distance((F[body] @ [*c.a, 1])[:3], (F[body] @ [*c.b, 1])[:3], centre) - c.radius
                     - radius for c in caps)
        if body in (0, 1):                     # the sphere ignores them: they are checked against the others
            assert obs[0, body] <= min(world.cap, 10.0)
            continue
        assert obs[0, body] <= expect + 1e-9, body               # the box and post can only be nearer
    near = world.nearest(q[None])
    b, o = int(near.body[0]), int(near.other[0])
    assert o == 0 and world.other_name(o) == "obstacle 'base'"
    text = world.describe(b, o, float(near.clearance[0]))
    assert text.startswith(f"{world.body_names[b]} against obstacle 'base': ")
    caps = [c for c in world.geometry.capsules if c.body == b]
    d = min(_segment_distance((F[b] @ [*c.a, 1])[:3], (F[b] @ [*c.b, 1])[:3], centre) - c.radius - radius
            for c in caps)
    assert float(near.clearance[0]) == pytest.approx(d, abs=1e-9)
