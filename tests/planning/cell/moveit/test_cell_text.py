"""planning.cell.moveit.cell_text: a scene → a cell file's text → the cell reader's Cell holds the same
primitives (box corners, cylinder axes, cone, mesh) as scipy's rotations of the scene say; strings and
rotations survive the text exactly."""
from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kin.transforms import rpy_to_matrix
from planning.cell.moveit import cell_name, parse_scene_text, parse_scene_yaml, scene_cell
from planning.cell.moveit.cell_text import rpy_degrees, toml_string
from tests.planning.cell.helpers import uncovered
from tests.planning.cell.moveit.scenes import EXPECTED, TEXT_NOETIC, WEDGE_TRIANGLES, WEDGE_VERTICES, YAML_ECHO

CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)


def _place(T, P):
    return P @ T[:3, :3].T + T[:3, 3]


def test_the_round_trip_gives_the_scenes_primitives():
    text, cell = scene_cell(parse_scene_yaml(YAML_ECHO, "lab.yaml"), "lab.toml")
    assert tomllib.loads(text)["name"] == "lab" == cell.name
    assert [(o.name, o.kind) for o in cell.obstacles] == [("table", "compound"), ("base", "sphere"),
                                                         ("wedge", "mesh"), ("funnel", "cone")]
    table, base, wedge, funnel = cell.obstacles
    (_, _, box_size, box_T), (_, _, cyl_size, cyl_T) = EXPECTED[:2]
    box, cyl = table.shapes
    # the box's corners: scipy's rotation of the scene against the cell's shape
    expect = _place(box_T, CORNERS * np.array(box_size) / 2)
    np.testing.assert_allclose(_place(box.pose, CORNERS * box.size), expect, atol=1e-12)
    # the cylinder: radius, half length, and its axis ends
    assert cyl.kind == "cylinder" and cyl.size == pytest.approx((0.02, 0.2, 0))
    ends = np.array([[0, 0, -0.2], [0, 0, 0.2]])
    np.testing.assert_allclose(_place(cyl.pose, ends), _place(cyl_T, ends), atol=1e-12)
    (ball,) = base.shapes
    assert ball.size == pytest.approx((0.05, 0, 0)) and ball.pose[:3, 3] == pytest.approx([0.3, 0.2, 0.1], abs=1e-15)
    # the mesh: written in the cell, placed as the scene places it, every vertex inside a sphere
    T = cell.meshes["wedge"]
    np.testing.assert_allclose(T, _place(EXPECTED[3][3], WEDGE_VERTICES)[WEDGE_TRIANGLES], atol=1e-7)
    assert len(uncovered(_place(EXPECTED[3][3], WEDGE_VERTICES), wedge.spheres)) == 0
    # the cone: its cylinder, and how much that stands out of it
    (c,) = funnel.shapes
    assert c.kind == "cylinder" and c.size == pytest.approx((0.1, 0.15, 0))
    np.testing.assert_allclose(_place(c.pose, ends), _place(EXPECTED[4][3], ends), atol=1e-12)
    assert funnel.over_estimate == pytest.approx(0.1 * 0.3 / math.hypot(0.1, 0.3), rel=1e-12)
    # "base" is kept, and said to be a robot body's name too
    assert "# Obstacles named like robot bodies (base)" in text


def test_the_text_version_imports_to_the_same_cell():
    _, a = scene_cell(parse_scene_yaml(YAML_ECHO, "lab.yaml"), "a.toml")
    _, b = scene_cell(parse_scene_text(TEXT_NOETIC, "lab.scene"), "b.toml")
    for oa, ob in zip(a.obstacles, b.obstacles):
        assert (oa.name, oa.kind, len(oa.shapes)) == (ob.name, ob.kind, len(ob.shapes))
        for sa, sb in zip(oa.shapes, ob.shapes):
            np.testing.assert_allclose(sa.pose, sb.pose, atol=2e-6)
            np.testing.assert_allclose(sa.size, sb.size, atol=1e-15)


def test_the_robot_placement_and_the_name():
    scene = parse_scene_yaml(YAML_ECHO, "dir/lab.yaml")
    text, cell = scene_cell(scene, "c.toml", name="my cell", robot_xyz=(0.1, 0, 0.8), robot_rpy=(0, 0, 90))
    assert cell.name == "my cell"
    np.testing.assert_allclose(cell.base, [[0, -1, 0, 0.1], [1, 0, 0, 0], [0, 0, 1, 0.8], [0, 0, 0, 1]], atol=1e-15)
    assert cell_name(parse_scene_text(TEXT_NOETIC.replace("lab", "(noname)", 1), "x/the scene.scene")) == "the scene"
    assert cell_name(parse_scene_text(TEXT_NOETIC.replace("lab", "\x07" * 3, 1), "s.scene")) == "s"


@pytest.mark.parametrize("s", ['a "quoted" \\ name', "tab\there", "line\nbreak", "del\x7f", "bell\x07",
                               "ünïcødé ✓ 🤖", "sep\u2028x", "bom\ufeffx", "'single'", "trailing\\"])
def test_toml_strings_round_trip(s):
    assert tomllib.loads(f"a = {toml_string(s)}\n")["a"] == s


def test_rpy_degrees_gives_the_rotation_back_gimbal_lock_included():
    rng = np.random.default_rng(4)
    mats = list(Rotation.random(500, random_state=5).as_matrix())
    for _ in range(200):                         # at and near pitch ±90°, where rpy is ill-conditioned
        r, y = rng.uniform(-np.pi, np.pi, 2)
        p = np.sign(rng.uniform(-1, 1)) * (np.pi / 2 - 10.0 ** rng.uniform(-17, -3))
        mats.append(Rotation.from_euler("xyz", [r, p, y]).as_matrix())
    mats.append(Rotation.from_euler("xyz", [0.3, np.pi / 2, 0.2]).as_matrix())
    worst = max(np.abs(rpy_to_matrix(np.radians(rpy_degrees(R))) - R).max() for R in mats)
    assert worst < 1e-14


def test_several_shapes_make_a_compound_with_parts_in_the_objects_frame():
    text, _ = scene_cell(parse_scene_yaml(YAML_ECHO, "lab.yaml"), "lab.toml")
    doc = tomllib.loads(text)
    table = doc["obstacle"][0]
    assert table["type"] == "compound" and [p["type"] for p in table["part"]] == ["box", "cylinder"]
    assert table["xyz"] == pytest.approx([0.6, 0, -0.1]) and table["rpy"] == pytest.approx([0, 0, 90])
    assert table["part"][1]["xyz"] == pytest.approx([0.5, 0.3, -0.2]) and "rpy" not in table["part"][1]
    assert table["part"][1]["radius"] == 0.02 and table["part"][1]["length"] == 0.4
    assert doc["obstacle"][2]["triangles"] == WEDGE_TRIANGLES.tolist()
    assert doc["robot"] == {"xyz": [0, 0, 0], "rpy": [0, 0, 0]}
