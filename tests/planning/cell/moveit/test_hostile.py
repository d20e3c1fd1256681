"""Hostile planning scenes: every malformed or hostile YAML or file is refused in one line naming the file,
the object (index and id) and the field, with what is allowed — alias and merge-key bombs, huge files,
non-numbers, non-finite and non-positive sizes, rotations that are not rotations, duplicate ids."""
from __future__ import annotations

import pytest

from planning.cell import CellError
from planning.cell.moveit import load_scene, parse_scene_yaml

BOX = "{id: b, primitives: [{type: box, dimensions: [1, 1, 1]}]}"


def _world(*objects: str) -> str:
    return "world:\n  collision_objects:\n" + "".join(f"    - {o}\n" for o in objects)


BILLION_LAUGHS = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{chr(98 + k)}: &{chr(98 + k)} [{', '.join(['*' + chr(97 + k)] * 9)}]\n" for k in range(9)) + \
    "world: {collision_objects: *j}\n"
MERGE_BOMB = "a: &a {x: 1, y: 2}\n" + "".join(
    f"{chr(98 + k)}: &{chr(98 + k)} {{<<: [*{chr(97 + k)}, *{chr(97 + k)}]}}\n" for k in range(20))


@pytest.mark.parametrize("text, words", [
    # the document
    (BILLION_LAUGHS, ["s.yaml: line 2: a YAML alias (*a)", "not read"]),
    (MERGE_BOMB, ["s.yaml: line 2: a YAML alias (*a)"]),
    ("world: [unclosed\n", ["s.yaml: not valid YAML (line 2:"]),
    ("a: 1\n---\nb: 2\n", ["not valid YAML", "single document"]),
    ("[" * 100_000, ["not valid YAML", "nesting depth"]),
    ("", ["not a moveit_msgs/PlanningScene", "an empty file"]),
    ("- 1\n- 2\n", ["not a moveit_msgs/PlanningScene", "a list"]),
    ("start_state: {}\ngoal_constraints: []\n", ["a motion plan request, not a planning scene", "sceneNNNN.yaml"]),
    ("wurld: {}\n", ["s.yaml: unknown field(s) wurld", "allowed: allowed_collision_matrix"]),
    ("world: [1]\n", ["world: must be a map"]),
    ("world: {collision_objects: {a: 1}}\n", ["world.collision_objects: must be a list"]),
    ("world: {collision_objects: [], planes: []}\n", ["s.yaml: world: unknown field(s) planes"]),
    # ids
    (_world("3"), ["s.yaml: object 1: must be a map"]),
    (_world("{primitives: []}"), ["object 1: id: required"]),
    (_world("{id: true, primitives: []}"), ["object 1: id: must be a string, not bool"]),
    (_world("{id: '" + "x" * 101 + "', primitives: []}"), ["object 1: id", "1 to 100 printable characters"]),
    (_world('{id: "bell\\a", primitives: []}'), ["object 1: id", "printable"]),
    (_world(BOX, BOX), ["object 2 ('b'): id 'b' is already object 1's; ids must be unique"]),
    (_world("{id: b, colour: red}"), ["object 1 ('b'): unknown field(s) colour", "allowed: header, id"]),
    (_world("{id: b}"), ["object 1 ('b'): no shapes (primitives or meshes)"]),
    # operations
    (_world("{id: b, operation: 1}"), ["object 1 ('b'): operation remove edits an object", "operation add"]),
    (_world("{id: b, operation: move}"), ["operation move edits an object"]),
    (_world("{id: b, operation: explode}"), ["operation 'explode' unknown; allowed: add (0), append (2)"]),
    (_world(BOX, BOX.replace("{id: b,", "{id: b, operation: append,")), ["object 2 ('b'): operation append edits"]),
    # primitives
    (_world("{id: b, primitives: [{type: torus, dimensions: [1]}]}"),
     ["object 1 ('b'): primitives[0]: type 'torus' unknown; allowed: box, sphere, cylinder, cone (or 1 to 4)"]),
    (_world("{id: b, primitives: [{type: 7, dimensions: [1]}]}"), ["type '7' unknown"]),
    (_world("{id: b, primitives: [{type: true, dimensions: [1]}]}"), ["type 'True' unknown"]),
    (_world("{id: b, primitives: [{type: 5, dimensions: [1, 1]}]}"), ["a prism is not read"]),
    (_world("{id: b, primitives: [{type: box, dimensions: [1, 1]}]}"),
     ["primitives[0]: dimensions: a box has 3 [x, y, z] (full edge lengths, m), not [1, 1]"]),
    (_world("{id: b, primitives: [{type: cylinder, dimensions: 0.5}]}"), ["a cylinder has 2 [height, radius]"]),
    (_world("{id: b, primitives: [{type: box, dimensions: [1, 0, 1]}]}"), ["dimensions: y must be > 0 (m), not 0"]),
    (_world("{id: b, primitives: [{type: cylinder, dimensions: [1, -0.1]}]}"), ["radius must be > 0 (m), not -0.1"]),
    (_world("{id: b, primitives: [{type: sphere, dimensions: [.nan]}]}"), ["dimensions: must be a finite number"]),
    (_world("{id: b, primitives: [{type: sphere, dimensions: [.inf]}]}"), ["finite number", "inf"]),
    (_world("{id: b, primitives: [{type: sphere, dimensions: ['1e999']}]}"), ["finite number", "1e999"]),
    (_world("{id: b, primitives: [{type: sphere, dimensions: [big]}]}"),
     ["must be a number ([radius] (m)), not 'big'"]),
    (_world("{id: b, primitives: [{type: sphere, dimensions: [yes]}]}"), ["must be a number", "not bool True"]),
    (_world("{id: b, primitives: [{type: sphere, dimensions: [2e4]}]}"), ["radius 20000 m is more than the 10 km"]),
    (_world("{id: b, primitives: [{type: box, dimensions: [1, 1, 1], size: 3}]}"), ["unknown field(s) size"]),
    # poses
    (_world("{id: b, primitives: [{type: box, dimensions: [1, 1, 1]}], primitive_poses: [{}, {}]}"),
     ["object 1 ('b'): 2 primitive_poses for 1 primitives"]),
    (_world("{id: b, primitives: [{type: box, dimensions: [1, 1, 1]}], primitive_poses: [{position: [a, 1, 2]}]}"),
     ["primitives[0]: pose.position: must be a number (m), not 'a'"]),
    (_world("{id: b, primitives: [{type: box, dimensions: [1, 1, 1]}], primitive_poses: [{position: {x: 1}}]}"),
     ["pose.position: must have the fields x, y, z (m), not ['x']"]),
    (_world("{id: b, primitives: [{type: box, dimensions: [1, 1, 1]}], primitive_poses: [{position: [1, 2]}]}"),
     ["pose.position: must be 3 numbers [x, y, z] (m), not [1, 2]"]),
    (_world("{id: b, primitives: [{type: box, dimensions: [1, 1, 1]}], "
            "primitive_poses: [{orientation: [0, 0, 0.5, 0.5]}]}"),
     ["primitives[0]: pose: the quaternion [0, 0, 0.5, 0.5] (x, y, z, w) has norm 0.707107", "within 0.001"]),
    (_world("{id: b, pose: {position: [1e5, 0, 0]}, primitives: [{type: box, dimensions: [1, 1, 1]}]}"),
     ["object 1 ('b'): pose: position [100000.0, 0.0, 0.0] is more than the 10 km"]),
    (_world("{id: b, pose: [1, 2], primitives: [{type: box, dimensions: [1, 1, 1]}]}"),
     ["object 1 ('b'): pose: must be a pose {position, orientation}, not list"]),
    (_world("{id: b, header: {frame_id: tool0}, primitives: [{type: box, dimensions: [1, 1, 1]}]}"),
     ["header.frame_id 'tool0' is neither the planning frame nor a fixed frame of the scene (the scene names none)"]),
    (_world("{id: b, header: {frame_id: 3}, primitives: [{type: box, dimensions: [1, 1, 1]}]}"),
     ["header.frame_id: must be a string, not int"]),
    ("fixed_frame_transforms: 3\n", ["fixed_frame_transforms: must be a list"]),
    ("fixed_frame_transforms: [{child_frame_id: w, transform: {rotation: [0, 0, 0, 3]}}]\n",
     ["fixed_frame_transforms[0]", "has norm 3"]),
    # planes, meshes
    (_world("{id: b, planes: [{coef: [0, 0, 1, 0]}]}"), ["planes: an infinite plane is not an obstacle", "as a box"]),
    (_world("{id: b, meshes: [{resource: 'package://x/m.stl'}]}"),
     ["meshes[0]: a mesh resource ('package://x/m.stl') is not read", "export it to STL"]),
    (_world("{id: b, meshes: [{vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]], triangles: [[0, 1, 3]]}]}"),
     ["meshes[0]: triangle 0 refers to vertex [0, 1, 3]; the mesh has 3 vertices (0 to 2)"]),
    (_world("{id: b, meshes: [{vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]], triangles: [[0, 1, -2]]}]}"),
     ["triangle 0 refers to vertex [0, 1, -2]"]),
    (_world("{id: b, meshes: [{vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]], triangles: [[0, 1]]}]}"),
     ["meshes[0]: triangles[0]: must be 3 vertex indices"]),
    (_world("{id: b, meshes: [{vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]], triangles: [[0, 1, true]]}]}"),
     ["triangles[0]: vertex indices must be whole numbers, not 'True'"]),
    (_world("{id: b, meshes: [{vertices: [[0, 0, 0], [1, 0, x], [0, 1, 0]], triangles: [[0, 1, 2]]}]}"),
     ["meshes[0]: vertices[1]: must be a number (m), not 'x'"]),
    (_world("{id: b, meshes: [{vertices: [[0, 0, 0]], triangles: []}]}"), ["meshes[0]: no triangles"]),
    (_world("{id: b, meshes: [{vertices: [[0, 0, 0]]}]}"), ["meshes[0]: vertices and triangles must be lists"]),
])
def test_hostile_yaml_is_one_line(text, words):
    with pytest.raises(CellError) as e:
        parse_scene_yaml(text, "s.yaml")
    msg = str(e.value)
    assert msg.startswith("s.yaml") and "\n" not in msg, msg
    for w in words:
        assert w in msg, (w, msg)


def test_limits_on_objects_shapes_vertices_and_triangles(monkeypatch):
    import planning.cell.moveit.scene as scene
    import planning.cell.moveit.yaml_scene as yaml_scene
    monkeypatch.setattr(scene, "MAX_OBJECTS", 2)
    with pytest.raises(CellError, match="s.yaml: 3 collision objects; at most 2"):
        parse_scene_yaml(_world(*(BOX.replace("id: b", f"id: b{k}") for k in range(3))), "s.yaml")
    monkeypatch.setattr(scene, "MAX_SHAPES", 3)
    two = "{id: X, primitives: [{type: box, dimensions: [1, 1, 1]}, {type: box, dimensions: [1, 1, 1]}]}"
    with pytest.raises(CellError, match=r"object 2 \('c'\): the scene's objects have more than 3 shapes together"):
        parse_scene_yaml(_world(two.replace("X", "a"), two.replace("X", "c")), "s.yaml")
    monkeypatch.setattr(yaml_scene, "MAX_VERTICES", 2)
    with pytest.raises(CellError, match=r"meshes\[0\]: 3 vertices; at most 2"):
        parse_scene_yaml(_world("{id: b, meshes: [{vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "
                                "triangles: [[0, 1, 2]]}]}"), "s.yaml")
    monkeypatch.setattr(scene, "MAX_CELL_ELEMENTS", 1)
    with pytest.raises(CellError, match="the scene's meshes have more than 1 triangles together"):
        parse_scene_yaml(_world("{id: b, meshes: [{vertices: [[0, 0, 0], [1, 0, 0]], "
                                "triangles: [[0, 1, 0], [1, 0, 1]]}]}"), "s.yaml")


def test_files_are_bounded_before_they_are_read(tmp_path):
    big = tmp_path / "big.yaml"
    with open(big, "wb") as f:
        f.truncate(50 * 2**20 + 1)                     # sparse: no time spent writing it
    with pytest.raises(CellError, match="big.yaml: 50.0 MB; a scene file may have at most 50 MB"):
        load_scene(big)
    (tmp_path / "bin.scene").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(CellError, match=r"bin.scene: not UTF-8 text \(byte 0xff at offset 0, line 1\)"):
        load_scene(tmp_path / "bin.scene")
    with pytest.raises(CellError, match="nope.yaml: no such scene file"):
        load_scene(tmp_path / "nope.yaml")
    (tmp_path / "dir.yaml").mkdir()
    with pytest.raises(CellError, match="dir.yaml: a directory, not a regular file"):
        load_scene(tmp_path / "dir.yaml")
    with pytest.raises(CellError, match=r"s.json: a MoveIt planning scene is a .scene text file .* \(.yaml, .yml\)"):
        load_scene(tmp_path / "s.json")
    (tmp_path / "s.scene").write_text("s\n.\n")
    with pytest.raises(CellError, match="a .scene file names no frames"):
        load_scene(tmp_path / "s.scene", frame="world")
    assert load_scene(tmp_path / "s.scene").objects == ()
