"""planning.cell.moveit.text_scene: MoveIt's .scene text in both versions (with object poses, MoveIt ≥
1.1.10; without, Melodic) gives the same world as the YAML of it — poses against scipy's rotations."""
from __future__ import annotations

import numpy as np
import pytest

from planning.cell import CellError
from planning.cell.moveit import parse_scene_text
from planning.cell.moveit.text_scene import FORMAT_NO_POSES, FORMAT_POSES
from tests.planning.cell.moveit.scenes import (
    EXPECTED,
    TEXT_MELODIC,
    TEXT_NOETIC,
    WEDGE_TRIANGLES,
    WEDGE_VERTICES,
    shapes_in_planning_frame,
)


@pytest.mark.parametrize("text, fmt, name", [(TEXT_NOETIC, FORMAT_POSES, "lab"), (TEXT_MELODIC, FORMAT_NO_POSES, "")])
def test_both_versions_give_the_world(text, fmt, name):
    scene = parse_scene_text(text, "lab.scene")
    assert scene.format == fmt and scene.name == name            # MoveIt's "(noname)" is no name
    got = shapes_in_planning_frame(scene)
    assert [(n, k) for n, k, _, _ in got] == [(n, k) for n, k, _, _ in EXPECTED]
    for (_, _, size, T), (_, _, e_size, e_T) in zip(got, EXPECTED):
        assert size == pytest.approx(e_size, abs=1e-15)
        np.testing.assert_allclose(T, e_T, atol=2e-6)            # the file's 6 significant digits
    wedge = scene.objects[2].shapes[0]
    np.testing.assert_array_equal(wedge.vertices, WEDGE_VERTICES)
    np.testing.assert_array_equal(wedge.triangles, WEDGE_TRIANGLES)


def test_ids_with_spaces_windows_line_ends_and_text_after_the_end():
    text = "s\r\n*   table  top \r\n1\r\nbox\r\n1 2 3\r\n0 0 0\r\n0 0 0 1\r\n.\r\nanything\n"
    (ob,) = parse_scene_text(text, "s.scene").objects
    assert ob.name == "table top" and ob.shapes[0].size == (1.0, 2.0, 3.0)


@pytest.mark.parametrize("text, words", [
    ("s\n* a\n1\nbox\n1 2 3\n0 0 0\n0 0 0 1\n", ["s.scene: the file ends where '*' (an object) or '.'",
                                                 "is it cut short? a scene ends with a '.' line"]),
    ("s\n* a\n1\nbox\n1 2 3\n0 0 0\n", ["object 1 ('a')", "the file ends where a quaternion x y z w should be"]),
    ("s\n* a\n1\nbox\n1 -2 3\n0 0 0\n0 0 0 1\n.\n", ["object 1 ('a'), line 5: box", "y must be > 0 (m), not -2"]),
    ("s\n* a\n1\nbox\n1 nan 3\n0 0 0\n0 0 0 1\n.\n", ["object 1 ('a'), line 5: the box's x y z", "not 'nan'"]),
    ("s\n* a\n1\nbox\n1 1e999 3\n0 0 0\n0 0 0 1\n.\n", ["line 5", "finite number", "1e999"]),
    ("s\n* a\n1\nbox\n1 2 3\n0 0 0\n0 0 0 2\n.\n", ["object 1 ('a'), line 7", "has norm 2"]),
    ("s\n* a\n1\nplane\n0 0 1 0\n0 0 0\n0 0 0 1\n.\n", ["line 4", "a plane is infinite"]),
    ("s\n* a\n1\ntorus\n1 2\n.\n", ["line 4", "shape type 'torus' unknown", "box, sphere, cylinder, cone, mesh"]),
    ("s\n* a\n-1\n.\n", ["line 3", "the number of shapes: expected a whole number, not '-1'"]),
    ("s\n* a\n1001\n.\n", ["line 3", "the number of shapes: 1001; at most 1000"]),
    ("s\n* a\n0\n.\n", ["object 1 ('a')", "no shapes"]),
    ("s\n*\n1\nsphere\n1\n0 0 0\n0 0 0 1\n.\n", ["object 1, line 2: id", "1 to 100 printable characters"]),
    ("s\n* a\n1\nsphere\n1\n0 0 0\n0 0 0 1\n* a\n1\nsphere\n1\n0 0 0\n0 0 0 1\n.\n",
     ["object 2 ('a')", "id 'a' is already object 1's"]),
    ("s\n+ a\n.\n", ["s.scene, line 2", "expected '*' (an object) or '.' (the end), not '+'"]),
    ("s\n* a\n1\nmesh\n3 1\n0 0 0\n1 0 0\n0 1 0\n0 1 3\n0 0 0\n0 0 0 1\n.\n",
     ["object 1 ('a'), line 4: mesh", "triangle 0 refers to vertex [0, 1, 3]; the mesh has 3 vertices"]),
    ("s\n* a\n1\nmesh\n999999999 1\n.\n", ["the mesh's vertex count: 999999999; at most 600000"]),
    ("s\n* a\n1\nmesh\n3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 0\n0 0 0 1\n.\n", ["no triangles"]),
    ("", ["s.scene: the file ends where '*' (an object) or '.' (the end) should be"]),
    ("s\0\n.\n", ["not a text file"]),
])
def test_bad_scene_text_is_one_line(text, words):
    with pytest.raises(CellError) as e:
        parse_scene_text(text, "s.scene")
    msg = str(e.value)
    assert msg.startswith("s.scene") and "\n" not in msg
    for w in words:
        assert w in msg, (w, msg)


def test_the_object_limit(monkeypatch):
    import planning.cell.moveit.scene as scene
    monkeypatch.setattr(scene, "MAX_OBJECTS", 2)
    one = "* {}\n1\nsphere\n1\n0 0 0\n0 0 0 1\n"
    with pytest.raises(CellError, match="s.scene: 3 collision objects; at most 2"):
        parse_scene_text("s\n" + "".join(one.format(k) for k in "abc") + ".\n", "s.scene")
