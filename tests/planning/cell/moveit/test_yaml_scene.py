"""planning.cell.moveit.yaml_scene: PlanningScene YAML as rostopic echo and robowflex write it — shapes,
sizes and poses against scipy's rotations and hand-computed frames."""
from __future__ import annotations

import numpy as np
import pytest

from planning.cell import CellError
from planning.cell.moveit import parse_scene_yaml
from tests.planning.cell.moveit.scenes import (
    EXPECTED,
    WEDGE_TRIANGLES,
    WEDGE_VERTICES,
    YAML_ECHO,
    shapes_in_planning_frame,
)


def test_echo_style_yaml_every_shape_where_moveit_puts_it():
    scene = parse_scene_yaml(YAML_ECHO, "lab.yaml")
    assert scene.name == "lab" and scene.robot_model_name == "fanuc_lrmate200id"
    assert scene.format == "PlanningScene YAML"
    assert [ob.name for ob in scene.objects] == ["table", "base", "wedge", "funnel"]
    got = shapes_in_planning_frame(scene)
    assert len(got) == len(EXPECTED)
    for (name, kind, size, T), (e_name, e_kind, e_size, e_T) in zip(got, EXPECTED):
        assert (name, kind) == (e_name, e_kind)
        assert size == pytest.approx(e_size, abs=1e-15)
        np.testing.assert_allclose(T, e_T, atol=1e-12)
    wedge = scene.objects[2].shapes[0]
    np.testing.assert_array_equal(wedge.vertices, WEDGE_VERTICES)
    np.testing.assert_array_equal(wedge.triangles, WEDGE_TRIANGLES)
    # the table's object pose is kept as the object's frame, its shapes relative to it
    np.testing.assert_allclose(scene.objects[0].shapes[1].pose[:3, 3], [0.5, 0.3, -0.2])
    assert scene.notes == () and scene.kinds == {"box": 1, "cylinder": 1, "sphere": 1, "mesh": 1, "cone": 1}


ROBOWFLEX = """
world:
  collision_objects:
    - id: Cube1
      primitives:
        - type: box
          dimensions: [0.07, 0.07, 0.07]
      primitive_poses:
        - position: [0.74, -0.14, 0.26]
          orientation: [0, 0, -0.03996434360673529, 0.999201106504633]
    - id: Can1
      pose:
        position: [-0.06, -0.11, 0.087]
        orientation: [0, 0, 0.9972514405491772, 0.07409159414259425]
      primitives:
        - type: cylinder
          dimensions: [0.12, 0.03]
      primitive_poses:
        - position: [0.85, 0, 0.8]
          orientation: [0, 0, 0, 1]
    - id: 42
      primitives:
        - type: SPHERE
          dimensions: ["1e-01"]
"""


def test_robowflex_style_lists_object_poses_and_numbers_without_a_dot():
    from scipy.spatial.transform import Rotation
    scene = parse_scene_yaml(ROBOWFLEX, "scene0001.yaml")
    cube, can, ball = scene.objects
    assert cube.name == "Cube1" and cube.shapes[0].size == (0.07, 0.07, 0.07)
    R = Rotation.from_quat([0, 0, -0.03996434360673529, 0.999201106504633]).as_matrix()
    np.testing.assert_allclose((cube.pose @ cube.shapes[0].pose)[:3, :3], R, atol=1e-15)
    # MoveIt ≥ 1.1: a primitive pose is in the object's frame — world = object pose · primitive pose
    T_obj = np.eye(4)
    T_obj[:3, :3] = Rotation.from_quat([0, 0, 0.9972514405491772, 0.07409159414259425]).as_matrix()
    T_obj[:3, 3] = [-0.06, -0.11, 0.087]
    world = T_obj @ np.array([0.85, 0, 0.8, 1])
    np.testing.assert_allclose((can.pose @ can.shapes[0].pose)[:3, 3], world[:3], atol=1e-12)
    assert can.shapes[0].kind == "cylinder" and can.shapes[0].size == (0.03, 0.12)     # radius, length
    assert ball.name == "42" and ball.shapes[0].size == (0.1,)
    np.testing.assert_array_equal(ball.pose @ ball.shapes[0].pose, np.eye(4))       # no pose: the identity


def test_a_quaternion_a_little_off_is_normalised_and_zeros_are_the_identity():
    text = ROBOWFLEX.replace("[0, 0, 0, 1]", "[0, 0, 0, 1.0009]").replace(
        "[0, 0, -0.03996434360673529, 0.999201106504633]", "[0, 0, 0, 0]")
    cube, can, _ = parse_scene_yaml(text, "s.yaml").objects
    np.testing.assert_array_equal(cube.shapes[0].pose[:3, :3], np.eye(3))
    np.testing.assert_allclose(can.shapes[0].pose[:3, :3], np.eye(3), atol=1e-15)
    with pytest.raises(CellError, match=r"object 2 \('Can1'\): primitives\[0\]: pose: the quaternion "
                                        r"\[0, 0, 0, 1.0011\] \(x, y, z, w\) has norm 1.0011; a rotation's is 1 "
                                        r"\(within 0.001\)"):
        parse_scene_yaml(ROBOWFLEX.replace("[0, 0, 0, 1]", "[0, 0, 0, 1.0011]"), "s.yaml")


def test_frames_fixed_frames_and_the_planning_frame():
    text = """
fixed_frame_transforms:
  - child_frame_id: table_frame
    transform: {translation: [1, 2, 3], rotation: [0, 0, 0, 1]}
world:
  collision_objects:
    - id: a
      header: {frame_id: table_frame}
      primitives: [{type: box, dimensions: [1, 1, 1]}]
    - id: b
      header: {frame_id: panda_link0}
      primitives: [{type: box, dimensions: [1, 1, 1]}]
"""
    with pytest.raises(CellError) as e:
        parse_scene_yaml(text, "s.yaml")
    assert str(e.value) == ("s.yaml: object 2 ('b'): header.frame_id 'panda_link0' is neither the planning frame nor a "
                            "fixed frame of the scene (table_frame); an object placed in a robot link's frame moves "
                            "with the robot and is not read — if 'panda_link0' is the planning frame, say so "
                            "(rmt import-scene --frame)")
    a, b = parse_scene_yaml(text, "s.yaml", frame="panda_link0").objects
    np.testing.assert_array_equal(a.pose[:3, 3], [1, 2, 3])
    np.testing.assert_array_equal(b.pose, np.eye(4))


def test_append_is_add_for_a_new_id_and_what_is_left_out_is_noted():
    text = """
robot_state:
  attached_collision_objects: [{link_name: hand, object: {id: cup}}]
  multi_dof_joint_state:
    joint_names: [virtual_joint]
    transforms: [{translation: [0.5, 0, 0], rotation: [0, 0, 0, 1]}]
allowed_collision_matrix: {entry_names: [panda_link0, Box], entry_values: [[false, true], [true, false]]}
link_padding: [{link_name: panda_link1, padding: 0.01}]
world:
  collision_objects:
    - {id: Box, operation: append, primitives: [{type: box, dimensions: [1, 1, 1]}]}
  octomap: {octomap: {id: OcTree, data: [1, 2, 3]}}
"""
    scene = parse_scene_yaml(text, "s.yaml")
    assert [ob.name for ob in scene.objects] == ["Box"]
    assert len(scene.notes) == 5
    assert scene.notes[0].startswith("robot_state: 1 attached object(s) not imported")
    assert "moves the robot from the planning frame's origin" in scene.notes[1]
    assert "allowed_collision_matrix: entries of objects (Box)" in scene.notes[2]
    assert scene.notes[3].startswith("world.octomap") and scene.notes[4].startswith("link_padding")


def test_an_empty_world_is_an_empty_scene():
    scene = parse_scene_yaml("name: empty\nworld: {collision_objects: []}\n", "s.yaml")
    assert scene.objects == () and scene.name == "empty"
