"""planning.cell.reader: every obstacle type read, units and rpy converted as hand-computed numbers say."""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import trimesh

from kin.geometry import Obstacle
from planning.cell import Cell, CellError, load_cell, parse_cell
from planning.cell.reader import DEFAULT_MAX_SPHERES, OBSTACLE_TYPES
from tests.planning.cell.helpers import uncovered


def one(text: str, **kw) -> Obstacle:
    cell = parse_cell(text, "c.toml", **kw)
    assert len(cell.obstacles) == 1
    return cell.obstacles[0]


def test_an_empty_cell_is_a_cell():
    cell = parse_cell("", "c.toml")
    assert isinstance(cell, Cell) and cell.obstacles == () and cell.tool == () and cell.name == "c"
    assert np.array_equal(cell.base, np.eye(4)) and cell.length_unit == "m"


def test_box_in_mm_with_a_yaw():
    ob = one('length_unit = "mm"\n[[obstacle]]\nname = "b"\ntype = "box"\nsize = [2, 4, 6]\n'
             'xyz = [10, 20, 30]\nrpy = [0, 0, 90]\n')
    (s,) = ob.shapes
    assert s.kind == "box" and s.size == pytest.approx((0.001, 0.002, 0.003))      # half edges, m
    assert s.pose[:3, 3] == pytest.approx([0.010, 0.020, 0.030])
    assert s.pose[:3, :3] == pytest.approx(np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]]), abs=1e-15)
    # the corners of the yawed box: 4 mm along x, 2 mm along y, about (10, 20, 30) mm
    corners = np.array([[x, y, z, 1] for x in (-1, 1) for y in (-2, 2) for z in (-3, 3)]) * [1e-3, 1e-3, 1e-3, 1]
    world = (s.pose @ corners.T).T[:, :3]
    assert world.min(axis=0) == pytest.approx([0.008, 0.019, 0.027]) and \
        world.max(axis=0) == pytest.approx([0.012, 0.021, 0.033])
    assert ob.kind == "box" and ob.over_estimate == 0 and ob.spheres is None


def test_roll_then_yaw_is_the_robot_files_convention():
    # R = Rz(yaw)·Ry(pitch)·Rx(roll): roll 90°, yaw 90° sends local x → y, y → z, z → x
    ob = one('[[obstacle]]\nname = "c"\ntype = "cylinder"\nradius = 0.1\nlength = 0.5\nrpy = [90, 0, 90]\n')
    R = ob.shapes[0].pose[:3, :3]
    assert R == pytest.approx(np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0]]), abs=1e-15)
    assert ob.shapes[0].size == pytest.approx((0.1, 0.25, 0))
    ob = one('angle_unit = "rad"\n[[obstacle]]\nname = "c"\ntype = "capsule"\nradius = 1\nlength = 2\n'
             f'rpy = [0, {math.pi / 2}, 0]\n')
    # pitch 90° about y: local z → world x
    assert ob.shapes[0].pose[:3, :3] @ [0, 0, 1] == pytest.approx([1, 0, 0], abs=1e-15)
    assert ob.shapes[0].kind == "capsule" and ob.shapes[0].size == pytest.approx((1, 1, 0))


def test_inches_and_the_robot_placement():
    cell = parse_cell('length_unit = "in"\n[robot]\nxyz = [10, 0, 20]\nrpy = [0, 0, 180]\n'
                      '[[obstacle]]\nname = "s"\ntype = "sphere"\nradius = 2\nxyz = [1, 2, 3]\n', "c.toml")
    assert cell.base[:3, 3] == pytest.approx([0.254, 0, 0.508])
    assert cell.base[:3, :3] == pytest.approx(np.diag([-1, -1, 1]), abs=1e-15)
    (s,) = cell.obstacles[0].shapes
    assert s.size == pytest.approx((0.0508, 0, 0)) and s.pose[:3, 3] == pytest.approx([0.0254, 0.0508, 0.0762])


def test_mesh_units_scale_and_pose(tmp_path):
    trimesh.creation.box((2.0, 4.0, 6.0)).export(tmp_path / "b.stl")         # numbers of the file: ±1, ±2, ±3
    text = ('length_unit = "mm"\n[[obstacle]]\nname = "m"\ntype = "mesh"\nfile = "b.stl"\nunit = "{unit}"\n'
            'scale = {scale}\nxyz = [100, 0, 0]\nrpy = [0, 0, 90]\ntolerance = 0.5\nmax_spheres = 400\n')
    ob = one(text.format(unit="in", scale="[1, 0.5, 2]"), base_dir=tmp_path)
    # file (±1, ±2, ±3) × (1, 0.5, 2) in → (±1, ±1, ±6) in; yaw 90°: x ↔ y; then +100 mm in x
    expect = np.array([[0.1 + y, x, z] for x in (-0.0254, 0.0254) for y in (-0.0254, 0.0254)
                       for z in (-0.1524, 0.1524)])
    assert len(uncovered(expect, ob.spheres)) == 0
    assert ob.kind == "mesh" and 0 < ob.over_estimate and len(ob.spheres) <= 400
    lo, hi = (ob.spheres[:, :3] - ob.spheres[:, 3:]).min(0), (ob.spheres[:, :3] + ob.spheres[:, 3:]).max(0)
    assert lo == pytest.approx([0.1 - 0.0254, -0.0254, -0.1524], abs=ob.over_estimate + 1e-9)
    assert hi == pytest.approx([0.1 + 0.0254, 0.0254, 0.1524], abs=ob.over_estimate + 1e-9)
    # the triangles are kept, placed as the spheres are (for drawing), and every vertex is covered
    cell = parse_cell(text.format(unit="in", scale="[1, 0.5, 2]"), "c.toml", base_dir=tmp_path)
    T = cell.meshes["m"]
    assert T.shape == (12, 3, 3) and T.dtype == np.float32 and not T.flags.writeable
    V = np.unique(T.reshape(-1, 3).astype(float).round(6), axis=0)
    assert V == pytest.approx(np.unique(expect.round(6), axis=0), abs=1e-7)
    assert parse_cell('[[obstacle]]\nname = "b"\ntype = "box"\nsize = [1, 1, 1]\n', "c.toml").meshes == {}
    with pytest.raises(CellError, match="a mesh is given for obstacle 'x', which the cell does not have"):
        Cell("c", (), meshes={"x": T})
    # no unit: the file's numbers are in the cell's unit (mm)
    ob = one(text.replace('unit = "{unit}"\n', "").format(scale=1), base_dir=tmp_path)
    assert (ob.spheres[:, :3] + ob.spheres[:, 3:]).max(0)[2] == pytest.approx(0.003, abs=ob.over_estimate + 1e-9)


@pytest.mark.parametrize("suffix", ["stl", "obj", "ply"])
def test_every_mesh_format(tmp_path, suffix):
    trimesh.creation.icosphere(2, 0.05).export(tmp_path / f"s.{suffix}")
    ob = one(f'[[obstacle]]\nname = "ball"\ntype = "mesh"\nfile = "s.{suffix}"\n', base_dir=tmp_path)
    assert 0 < len(ob.spheres) <= DEFAULT_MAX_SPHERES and ob.over_estimate < 0.01
    assert len(uncovered(trimesh.creation.icosphere(2, 0.05).vertices, ob.spheres)) == 0


@pytest.mark.parametrize("suffix", ["csv", "ply"])
def test_point_clouds(tmp_path, suffix):
    P = np.array([[0, 0, 0], [10, 0, 0], [0, 20, 0], [0, 0, 30.5]])
    if suffix == "csv":
        (tmp_path / "p.csv").write_text("x,y,z\n# a comment\n" + "\n".join(",".join(map(str, p)) for p in P) + "\n")
    else:
        trimesh.PointCloud(P).export(tmp_path / "p.ply")
    text = (f'length_unit = "mm"\n[[obstacle]]\nname = "scan"\ntype = "point_cloud"\nfile = "p.{suffix}"\n'
            'point_radius = 2\nxyz = [0, 0, 1000]\nmerge = false\n')
    ob = one(text, base_dir=tmp_path)
    assert ob.kind == "point_cloud" and len(ob.spheres) == 4
    assert sorted(map(tuple, ob.spheres[:, :3].round(6))) == sorted(map(tuple, (P * 1e-3 + [0, 0, 1]).round(6)))
    assert ob.spheres[:, 3] == pytest.approx(0.002) and ob.over_estimate < 1e-8
    merged = one(text.replace("merge = false", "merge = true"), base_dir=tmp_path)
    assert len(merged.spheres) == 4               # 10 mm apart with 2 mm balls: nothing to merge


def test_tool_and_allowed_pairs():
    cell = parse_cell('length_unit = "mm"\n[[obstacle]]\nname = "part"\ntype = "sphere"\nradius = 5\n'
                      'ignore = ["tool"]\n'
                      '[[tool]]\nname = "torch"\ntype = "capsule"\na = [0, 0, 0]\nb = [0, 0, 100]\nradius = 10\n'
                      '[[tool]]\ntype = "sphere"\ncenter = [0, 0, 120]\nradius = 4\n'
                      '[allow]\npairs = [["link 6", "part"], ["link 3", "tool"], ["part", "J4"]]\n', "c.toml")
    torch, tip = cell.tool
    assert torch.name == "torch" and torch.b == pytest.approx((0, 0, 0.1)) and torch.radius == pytest.approx(0.01)
    assert tip.name == "tool" and tip.a == tip.b == pytest.approx((0, 0, 0.12)) and tip.radius == pytest.approx(0.004)
    assert cell.body_pairs == (("link 3", "tool"),)
    assert set(cell.obstacle_pairs) == {("part", "tool"), ("part", "link 6"), ("part", "J4")}


def test_obstacle_types_are_documented():
    page = (Path(__file__).resolve().parents[3] / "docs" / "cells.md").read_text()
    for kind, keys in OBSTACLE_TYPES.items():
        assert f"`{kind}`" in page, kind
        for key in keys:
            assert re.search(rf"`{key}( = [^`]*)?`", page), (kind, key)


def test_load_cell_finds_files_next_to_it(tmp_path):
    (tmp_path / "sub").mkdir()
    trimesh.creation.box((1, 1, 1)).export(tmp_path / "sub" / "b.stl")
    (tmp_path / "sub" / "cell.toml").write_text('[[obstacle]]\nname = "b"\ntype = "mesh"\nfile = "b.stl"\n')
    cell = load_cell(tmp_path / "sub" / "cell.toml")
    assert cell.path == tmp_path / "sub" / "cell.toml" and cell.name == "cell" and len(cell.obstacles[0].spheres)
    with pytest.raises(CellError, match="no such cell file"):
        load_cell(tmp_path / "nope.toml")
