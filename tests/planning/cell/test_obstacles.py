"""planning.cell.obstacles: cones (enclosed by their cylinder, by a stated amount), meshes written in the
cell file, compound obstacles of several parts — against hand-computed and sampled numpy values — and
their hostile forms, refused in one line."""
from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

from kin.geometry import Obstacle
from planning.cell import CellError, parse_cell
from planning.cell.obstacles import cone_over_estimate
from tests.planning.cell.helpers import uncovered


def one(text: str, **kw) -> tuple[Obstacle, object]:
    cell = parse_cell(text, "c.toml", **kw)
    assert len(cell.obstacles) == 1
    return cell.obstacles[0], cell


def _segment_distance_2d(p, a, b):
    ab = b - a
    t = np.clip(((p - a) @ ab) / (ab @ ab), 0, 1)
    return np.linalg.norm(a + t[:, None] * ab - p, axis=1)


def test_a_cone_is_its_cylinder_and_says_by_how_much_it_stands_out():
    ob, cell = one('length_unit = "mm"\n[[obstacle]]\nname = "k"\ntype = "cone"\nradius = 30\nlength = 40\n'
                   'xyz = [0, 0, 500]\nrpy = [90, 0, 0]\n')
    (s,) = ob.shapes
    assert ob.kind == "cone" and s.kind == "cylinder" and s.size == pytest.approx((0.03, 0.02, 0))
    assert s.pose[:3, 3] == pytest.approx([0, 0, 0.5]) and s.pose[:3, :3] @ [0, 0, 1] == pytest.approx([0, -1, 0])
    # r·h/√(r² + h²) = 30·40/50 mm; sampled: the farthest point of the cylinder from the cone, in the
    # half-plane (ρ, z) where the cone is the triangle (0, −h/2), (r, −h/2), (0, h/2)
    assert ob.over_estimate == pytest.approx(0.024, rel=1e-12) == cone_over_estimate(0.03, 0.04)
    r, h = 0.03, 0.04
    g = np.linspace(0, 1, 201)
    P = np.array([[r * u, h * (v - 0.5)] for u in g for v in g])            # the cylinder's cross-section
    apex, rim, axis_foot = np.array([0, h / 2]), np.array([r, -h / 2]), np.array([0, -h / 2])
    inside = P[:, 0] <= r * (h / 2 - P[:, 1]) / h
    side = _segment_distance_2d(P, rim, apex)
    d = np.where(inside, 0.0, side)
    assert d.max() == pytest.approx(ob.over_estimate, rel=1e-9) and np.all(d <= ob.over_estimate + 1e-15)
    assert _segment_distance_2d(np.array([[0, -h / 2]]), axis_foot, rim)[0] == 0
    assert "cone enclosed by its cylinder" in cell.notes["k"] and "24.0 mm" in cell.notes["k"]


def test_a_mesh_written_in_the_file(tmp_path):
    box = trimesh.creation.box((2.0, 4.0, 6.0))
    V, F = box.vertices.tolist(), box.faces.tolist()
    text = ('length_unit = "mm"\n[[obstacle]]\nname = "m"\ntype = "mesh"\nunit = "in"\nxyz = [100, 0, 0]\n'
            f'rpy = [0, 0, 90]\ntolerance = 0.5\nvertices = {V}\ntriangles = {F}\n')
    ob, cell = one(text)
    # (±1, ±2, ±3) in, yawed 90° (x ↔ y), then +100 mm in x: the same as the mesh file test of test_reader
    expect = np.array([[0.1 - y, x, z] for x in (-0.0254, 0.0254) for y in (-0.0508, 0.0508)
                       for z in (-0.0762, 0.0762)])
    assert ob.kind == "mesh" and len(uncovered(expect, ob.spheres)) == 0
    T = cell.meshes["m"]
    assert T.shape == (12, 3, 3)
    assert np.unique(T.reshape(-1, 3).astype(float).round(6), axis=0) == \
        pytest.approx(np.unique(expect.round(6), axis=0), abs=1e-7)
    assert "vertices and triangles: 12 triangles" in cell.notes["m"]
    # the same triangles from an STL file give spheres holding the same corners
    box.export(tmp_path / "b.stl")
    ob2, _ = one(text.replace(f"vertices = {V}\ntriangles = {F}\n", 'file = "b.stl"\n'), base_dir=tmp_path)
    assert len(uncovered(expect, ob2.spheres)) == 0


def test_a_compound_obstacle_places_its_parts_in_its_frame(tmp_path):
    text = """
length_unit = "mm"
[[obstacle]]
name = "shelf"
type = "compound"
xyz = [1000, 0, 0]
rpy = [0, 0, 90]
ignore = ["tool"]
[[obstacle.part]]
type = "box"
size = [200, 100, 20]
xyz = [100, 0, 0]
[[obstacle.part]]
type = "cylinder"
radius = 10
length = 300
xyz = [0, 50, 150]
rpy = [90, 0, 0]
[[obstacle.part]]
type = "cone"
radius = 30
length = 40
[[obstacle.part]]
type = "mesh"
vertices = [[0, 0, 0], [100, 0, 0], [0, 100, 0]]
triangles = [[0, 1, 2]]
xyz = [0, 0, 500]
"""
    ob, cell = one(text)
    box, cyl, cone = ob.shapes
    Rz = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]])
    # the part's centre: the obstacle's pose times the part's own
    assert box.pose[:3, 3] == pytest.approx([1.0, 0.1, 0]) and box.pose[:3, :3] == pytest.approx(Rz, abs=1e-15)
    assert cyl.pose[:3, 3] == pytest.approx(np.array([1.0, 0, 0]) + Rz @ [0, 0.05, 0.15])
    assert cyl.pose[:3, :3] @ [0, 0, 1] == pytest.approx(Rz @ [0, -1, 0], abs=1e-15)
    assert cone.kind == "cylinder" and ob.over_estimate == pytest.approx(0.024)
    corners = np.array([[0, 0, 0.5], [0.1, 0, 0.5], [0, 0.1, 0.5]]) @ Rz.T + [1.0, 0, 0]
    assert len(uncovered(corners, ob.spheres)) == 0
    assert cell.meshes["shelf"] == pytest.approx(corners[None], abs=1e-6)
    assert ob.kind == "compound" and cell.notes["shelf"].startswith("4 parts; part 3: a cone")
    assert set(cell.obstacle_pairs) == {("shelf", "tool")}


COMPOUND = '[[obstacle]]\nname = "c"\ntype = "compound"\n'
MESH = '[[obstacle]]\nname = "m"\ntype = "mesh"\n'


@pytest.mark.parametrize("text, words", [
    ('[[obstacle]]\nname = "k"\ntype = "cone"\nradius = 1\nlength = 0\n', ["obstacle 1 ('k')", "length", "> 0"]),
    ('[[obstacle]]\nname = "k"\ntype = "cone"\nradius = 1\n', ["length", "required"]),
    (MESH, ["obstacle 1 ('m')", "vertices", "required with the other"]),
    (MESH + "vertices = [[0, 0, 0]]\n", ["triangles", "required with the other"]),
    (MESH + 'file = "a.stl"\nvertices = [[0, 0, 0]]\ntriangles = [[0, 0, 0]]\n', ["file", "not both"]),
    (MESH + "vertices = []\ntriangles = [[0, 1, 2]]\n", ["vertices", "non-empty list"]),
    (MESH + "vertices = [[0, 0, 0], [1, 0]]\ntriangles = [[0, 1, 0]]\n", ["vertices", "vertex 1", "3 numbers"]),
    (MESH + "vertices = [[0, 0, 0], [1, 0, true]]\ntriangles = [[0, 1, 0]]\n", ["vertex 1", "3 numbers"]),
    (MESH + "vertices = [[0, 0, 0], [1, 0, nan]]\ntriangles = [[0, 1, 0]]\n", ["vertex 1", "finite"]),
    (MESH + "vertices = [[0, 0, 0], [1, 0, 0]]\ntriangles = [[0, 1, 2]]\n",
     ["triangles", "triangle 0", "vertex indices from 0 to 1"]),
    (MESH + "vertices = [[0, 0, 0], [1, 0, 0]]\ntriangles = [[0, 1, -1]]\n", ["triangle 0"]),
    (MESH + "vertices = [[0, 0, 0], [1, 0, 0]]\ntriangles = [[0, 1, 1.0]]\n", ["triangle 0"]),
    (MESH + "vertices = [[0, 0, 0], [1, 0, 0]]\ntriangles = [[0, 1, false]]\n", ["triangle 0"]),
    (MESH + "vertices = [[0, 0, 0], [1e5, 0, 0]]\ntriangles = [[0, 1, 0]]\n", ["reaches", "10 km"]),
    (COMPOUND, ["obstacle 1 ('c')", "part", "required"]),
    (COMPOUND + "part = 3\n", ["part", "required"]),
    (COMPOUND + '[[obstacle.part]]\ntype = "compound"\n', ["part 1", "type", "'compound' unknown"]),
    (COMPOUND + '[[obstacle.part]]\ntype = "box"\nsize = [1, 1, 1]\nname = "x"\n',
     ["obstacle 1 ('c'): part 1", "unknown key(s) name"]),
    (COMPOUND + '[[obstacle.part]]\ntype = "box"\nsize = [1, 1, 1]\nignore = ["tool"]\n', ["unknown key(s) ignore"]),
    (COMPOUND + '[[obstacle.part]]\ntype = "sphere"\nradius = -1\n', ["obstacle 1 ('c'): part 1: radius", "> 0"]),
    (COMPOUND + '[[obstacle.part]]\ntype = "box"\nsize = [1, 1, 1]\nxyz = [0, 0, 1e5]\n',
     ["part 1: xyz", "10 km"]),
])
def test_bad_parts_and_meshes(text, words):
    with pytest.raises(CellError) as e:
        parse_cell(text, "cell.toml")
    msg = str(e.value)
    assert msg.startswith("cell.toml: ") and "\n" not in msg
    for w in words:
        assert w in msg, (w, msg)


def test_the_bounds_of_parts_and_written_meshes(monkeypatch):
    import planning.cell.obstacles as obstacles
    import planning.cell.reader as reader
    monkeypatch.setattr(obstacles, "MAX_VERTICES", 3)
    with pytest.raises(CellError, match="vertices: 4 vertices; at most 3"):
        parse_cell(MESH + "vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]\ntriangles = [[0, 1, 2]]\n", "c")
    monkeypatch.setattr(obstacles, "MAX_PARTS", 2)
    part = '[[obstacle.part]]\ntype = "sphere"\nradius = 1\n'
    with pytest.raises(CellError, match=r"obstacle 1 \('c'\): part: 3 parts; at most 2"):
        parse_cell(COMPOUND + part * 3, "c")
    monkeypatch.setattr(reader, "MAX_CELL_PARTS", 3)
    with pytest.raises(CellError, match=r"obstacle 2 \('d'\): the cell's compound obstacles have more than 3 parts"):
        parse_cell(COMPOUND + part * 2 + COMPOUND.replace('"c"', '"d"') + part * 2, "c")
    monkeypatch.setattr(reader, "MAX_CELL_ELEMENTS", 1)
    with pytest.raises(CellError, match="more than 1 triangles and points"):
        parse_cell(MESH + "vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\ntriangles = [[0, 1, 2], [0, 2, 1]]\n", "c")


def test_a_long_cell_file_is_refused_before_it_is_parsed(tmp_path, monkeypatch):
    import planning.cell.reader as reader
    monkeypatch.setattr(reader, "MAX_CELL_BYTES", 100)
    with pytest.raises(CellError, match="a cell file may have at most 100"):
        parse_cell("#" * 101, "c.toml")
    monkeypatch.setattr(reader, "MAX_CELL_BYTES", 2**19)
    (tmp_path / "big.toml").write_text("#" * 2**20)
    with pytest.raises(CellError, match="big.toml: 1.0 MB; a cell file may have at most 0.5 MB"):
        reader.load_cell(tmp_path / "big.toml")
    assert math.isclose(cone_over_estimate(3.0, 4.0), 2.4)
