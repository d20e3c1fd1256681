"""planning.cell: every malformed or hostile cell file, mesh or point cloud raises CellError in one
line naming the file, the obstacle (index and name) and the field — quickly, without reading more
than it must."""
from __future__ import annotations

import time

import numpy as np
import pytest
import trimesh

from planning.cell import CellError, load_cell, parse_cell
from planning.cell.mesh import MAX_FILE_BYTES, MAX_TRIANGLES
from planning.cell.points import MAX_POINTS
from planning.cell.reader import MAX_OBSTACLES

BOX = '[[obstacle]]\nname = "b"\ntype = "box"\nsize = [1, 1, 1]\n'


def refused(text: str, *words: str, base_dir=None, seconds: float = 2.0) -> str:
    t0 = time.perf_counter()
    with pytest.raises(CellError) as e:
        parse_cell(text, "cell.toml", base_dir)
    msg = str(e.value)
    assert time.perf_counter() - t0 < seconds, f"took {time.perf_counter() - t0:.1f} s to refuse: {msg}"
    assert msg.startswith("cell.toml") and "\n" not in msg, msg
    for w in words:
        assert w in msg, (w, msg)
    return msg


@pytest.mark.parametrize("text, words", [
    # the file and its top level
    ("[[obstacle]\n", ["not valid TOML"]),
    ("colour = 'red'\n", ["unknown key(s) colour", "allowed: allow, angle_unit"]),
    ("length_unit = 'furlong'\n", ["length_unit", "'furlong' unknown", "allowed: m, mm, in"]),
    ("angle_unit = 'grad'\n", ["angle_unit", "'grad' unknown"]),
    ("name = 3\n", ["name", "must be a string"]),
    ("obstacle = 3\n", ["obstacle must be an array of tables"]),
    ("[robot]\nxyz = [0, 0]\n", ["[robot]: xyz", "3 numbers"]),
    ("[robot]\nrpy = [0, 0, inf]\n", ["[robot]: rpy", "finite"]),
    ("[robot]\nmodel = 'x'\n", ["[robot]: unknown key(s) model"]),
    # obstacles
    ('[[obstacle]]\nname = "t"\ntype = "box"\nsize = [nan, 1, 1]\n', ["obstacle 1 ('t')", "size", "finite"]),
    ('[[obstacle]]\nname = "t"\ntype = "box"\nsize = [1, 0, 1]\n', ["obstacle 1 ('t')", "size", "> 0"]),
    ('[[obstacle]]\nname = "t"\ntype = "box"\nsize = "big"\n', ["size", "must be 3 numbers"]),
    ('[[obstacle]]\nname = "t"\ntype = "box"\n', ["size", "required"]),
    (BOX + '[[obstacle]]\nname = "s"\ntype = "sphere"\nradius = -5\n', ["obstacle 2 ('s')", "radius", "> 0"]),
    ('[[obstacle]]\nname = "s"\ntype = "sphere"\nradius = true\n', ["radius", "must be a number"]),
    ('[[obstacle]]\nname = "s"\ntype = "sphere"\nradius = 1e7\n', ["radius", "10 km"]),
    ('[[obstacle]]\nname = "c"\ntype = "cylinder"\nradius = 1\n', ["obstacle 1 ('c')", "length", "required"]),
    ('[[obstacle]]\nname = "k"\ntype = "torus"\n',
     ["obstacle 1 ('k')", "type", "'torus' unknown",
      "allowed: box, sphere, cylinder, capsule, cone, mesh, point_cloud, compound"]),
    ('[[obstacle]]\nname = "k"\n', ["type", "required"]),
    ('[[obstacle]]\nname = "s"\ntype = "sphere"\nradius = 1\nsize = [1, 1, 1]\n',
     ["obstacle 1 ('s')", "unknown key(s) size", "allowed:"]),
    ('[[obstacle]]\ntype = "sphere"\nradius = 1\n', ["obstacle 1", "name: required"]),
    ('[[obstacle]]\nname = ""\ntype = "sphere"\nradius = 1\n', ["name", "printable"]),
    # an obstacle may have a body's name, but a pair that could mean either must say which
    ('[[obstacle]]\nname = "tool"\ntype = "sphere"\nradius = 1\n[allow]\npairs = [["link 3", "tool"]]\n',
     ["[allow]: pair 1", "'tool' is both obstacle 'tool' and a robot body", "'obstacle:tool' or 'body:tool'"]),
    ('[[obstacle]]\nname = "Link 3"\ntype = "sphere"\nradius = 1\n[allow]\npairs = [["Link 3", "tool"]]\n',
     ["'Link 3' is both obstacle 'Link 3' and a robot body"]),
    ('[[obstacle]]\nname = "base"\ntype = "sphere"\nradius = 1\n[allow]\npairs = [["BASE", "tool"]]\n',
     ["pair 1: 'BASE' is both obstacle 'base' and a robot body; write 'obstacle:base' or 'body:BASE'"]),
    (BOX + '[allow]\npairs = [["tool", "obstacle:c"]]\n', ["pair 1", "'obstacle:c'", "the cell has no obstacle 'c'"]),
    (BOX + '[[obstacle]]\nname = "c"\ntype = "sphere"\nradius = 1\nignore = ["obstacle:b"]\n',
     ["obstacle 2 ('c')", "ignore", "'obstacle:b' is an obstacle"]),
    (BOX + BOX, ["obstacle 2 ('b')", "name 'b' is already obstacle 1's"]),
    ('[[obstacle]]\nname = "b"\ntype = "box"\nsize = [1, 1, 1]\nxyz = [0, 0, "up"]\n', ["xyz", "3 numbers"]),
    ('[[obstacle]]\nname = "b"\ntype = "box"\nsize = [1, 1, 1]\nrpy = [0, 0, 1e9]\n', ["rpy", "not angles"]),
    ('[[obstacle]]\nname = "b"\ntype = "box"\nsize = [1, 1, 1]\nignore = "tool"\n', ["ignore", "list of body names"]),
    (BOX + '[[obstacle]]\nname = "c"\ntype = "sphere"\nradius = 1\nignore = ["b"]\n',
     ["obstacle 2 ('c')", "ignore", "'b' is an obstacle"]),
    ('[[obstacle]]\nname = "m"\ntype = "mesh"\n', ["obstacle 1 ('m')", "file", "required"]),
    ('[[obstacle]]\nname = "m"\ntype = "mesh"\nfile = "a.step"\n', ["obstacle 1 ('m')", "STL, OBJ, PLY"]),
    ('[[obstacle]]\nname = "m"\ntype = "mesh"\nfile = "a.stl"\nunit = "ft"\n', ["unit", "'ft' unknown"]),
    ('[[obstacle]]\nname = "m"\ntype = "mesh"\nfile = "a.stl"\nscale = -1\n', ["scale", "positive"]),
    ('[[obstacle]]\nname = "m"\ntype = "mesh"\nfile = "a.stl"\nmax_spheres = 0\n', ["max_spheres", "whole number"]),
    ('[[obstacle]]\nname = "m"\ntype = "mesh"\nfile = "a.stl"\ntolerance = 0\n', ["tolerance", "> 0"]),
    ('[[obstacle]]\nname = "p"\ntype = "point_cloud"\nfile = "a.csv"\n', ["point_radius", "required"]),
    ('[[obstacle]]\nname = "p"\ntype = "point_cloud"\nfile = "a.csv"\npoint_radius = 1\nmerge = 1\n',
     ["merge", "true or false"]),
    # tool and pairs
    ('[[tool]]\ntype = "box"\n', ["tool 1", "type", "'box' unknown", "capsule, sphere"]),
    ('[[tool]]\ntype = "capsule"\na = [0, 0, 0]\nb = [0, 0, 1]\n', ["tool 1", "radius", "required"]),
    ('[[tool]]\ntype = "sphere"\ncenter = [0, 0, 0]\nradius = 0\n', ["tool 1", "radius", "> 0"]),
    ('[[tool]]\ntype = "sphere"\ncenter = [0, 0, 0]\nradius = 1\na = [0, 0, 0]\n', ["unknown key(s) a"]),
    ('[allow]\npairs = [["tool"]]\n', ["[allow]: pair 1", "two names"]),
    ('[allow]\nlinks = []\n', ["[allow]: unknown key(s) links"]),
    (BOX + '[[obstacle]]\nname = "c"\ntype = "sphere"\nradius = 1\n[allow]\npairs = [["b", "c"]]\n',
     ["pair 1", "two obstacles"]),
])
def test_bad_fields(text, words):
    refused(text, *words)


def test_too_many_obstacles_is_refused_before_reading_them():
    text = "[[obstacle]]\n" * (MAX_OBSTACLES + 1)
    refused(text, f"{MAX_OBSTACLES + 1} obstacles; at most {MAX_OBSTACLES}")


MESH = '[[obstacle]]\nname = "fixture"\ntype = "mesh"\nfile = "{}"\n'
CLOUD = '[[obstacle]]\nname = "scan"\ntype = "point_cloud"\nfile = "{}"\npoint_radius = 0.005\n'


def test_missing_mesh(tmp_path):
    refused(MESH.format("gone.stl"), "obstacle 1 ('fixture')", "file", "no such mesh file", "gone.stl",
            base_dir=tmp_path)
    (tmp_path / "dir.stl").mkdir()
    refused(MESH.format("dir.stl"), "not a regular file", base_dir=tmp_path)


@pytest.mark.parametrize("name, content, words", [
    ("text.stl", b"hello, I am a letter and not a mesh\n" * 20, ["text.stl is not a triangle mesh", "no triangles"]),
    ("empty.stl", b"", ["empty.stl is not a triangle mesh"]),
    ("empty.obj", b"# nothing\n", ["empty.obj is not a triangle mesh"]),
    ("garbage.ply", bytes(range(256)) * 40, ["garbage.ply is not a PLY file"]),
    ("lying.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                  b"property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                  + bytes(range(200)), ["lying.ply is not a readable PLY triangle mesh"]),
    ("nan.stl", b"solid x\nfacet normal 0 0 1\nouter loop\nvertex nan 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
                b"endfacet\nendsolid x\n", ["nan.stl is not a triangle mesh", "finite"]),
    ("outside.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", ["outside.obj"]),
    ("points.ply", None, ["points.ply is not a triangle mesh", "point_cloud"]),
])
def test_a_mesh_that_is_not_a_mesh(tmp_path, name, content, words):
    if content is None:
        trimesh.PointCloud(np.random.default_rng(0).random((20, 3))).export(tmp_path / name)
    else:
        (tmp_path / name).write_bytes(content)
    refused(MESH.format(name), "obstacle 1 ('fixture')", "file", *words, base_dir=tmp_path)


def test_huge_meshes_are_refused_from_their_headers(tmp_path):
    n = MAX_TRIANGLES + 1                               # a binary STL announcing one triangle too many
    with open(tmp_path / "big.stl", "wb") as f:
        f.write(b"\0" * 80 + n.to_bytes(4, "little"))
        f.truncate(84 + 50 * n)                         # sparse: no time spent writing
    refused(MESH.format("big.stl"), f"big.stl has {n} triangles; at most {MAX_TRIANGLES}", base_dir=tmp_path)
    with open(tmp_path / "huge.obj", "wb") as f:
        f.truncate(MAX_FILE_BYTES + 1)
    refused(MESH.format("huge.obj"), "huge.obj: 50.0 MB; a mesh file may have at most 50 MB", base_dir=tmp_path)
    header = (b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              b"property float z\nelement face 900000\nproperty list uchar int vertex_indices\nend_header\n")
    (tmp_path / "big.ply").write_bytes(header + b"\0" * 100)
    refused(MESH.format("big.ply"), "big.ply has 900000 triangles", base_dir=tmp_path)


def test_a_million_point_cloud_is_refused_quickly(tmp_path):
    (tmp_path / "scan.csv").write_bytes(b"x,y,z\n" + b"0.125,0.25,0.5\n" * 1_000_000)
    refused(CLOUD.format("scan.csv"), "obstacle 1 ('scan')", f"scan.csv has 1000000 points; at most {MAX_POINTS}",
            base_dir=tmp_path, seconds=1.0)
    header = (b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000\nproperty float x\nproperty float y\n"
              b"property float z\nend_header\n")
    (tmp_path / "scan.ply").write_bytes(header + np.zeros(3_000_000, np.float32).tobytes())
    refused(CLOUD.format("scan.ply"), "scan.ply has 1000000 points", base_dir=tmp_path, seconds=1.0)
    with open(tmp_path / "huge.csv", "wb") as f:
        f.truncate(MAX_FILE_BYTES + 1)
    refused(CLOUD.format("huge.csv"), "huge.csv: 50.0 MB", base_dir=tmp_path, seconds=1.0)


@pytest.mark.parametrize("name, content, words", [
    ("nan.csv", b"0,0,0\n1,nan,0\n", ["nan.csv: point 2 is not finite"]),
    ("nanfirst.csv", b"nan,0,0\n1,1,0\n", ["point 1 is not finite"]),
    ("four.csv", b"0,0,0,1\n1,1,1,1\n", ["4 columns; expected three"]),
    ("ragged.csv", b"0,0,0\n1,1\n", ["not rows of three numbers"]),
    ("words.csv", b"x,y,z\na,b,c\n", ["not rows of three numbers"]),
    ("empty.csv", b"# nothing here\n", ["empty.csv has no points"]),
    ("binary.csv", bytes(range(256)) * 4, ["binary.csv"]),
    ("garbage.ply", bytes(range(256)) * 4, ["garbage.ply is not a PLY file"]),
    ("inf.ply", None, ["inf.ply: point 2 is not finite"]),
])
def test_bad_point_clouds(tmp_path, name, content, words):
    if content is None:
        trimesh.PointCloud(np.array([[0, 0, 0], [np.inf, 0, 0.0]])).export(tmp_path / name)
    else:
        (tmp_path / name).write_bytes(content)
    refused(CLOUD.format(name), "obstacle 1 ('scan')", *words, base_dir=tmp_path)


def test_far_away_geometry_is_a_unit_mistake(tmp_path):
    trimesh.creation.box((1000.0, 1000.0, 1000.0)).export(tmp_path / "b.stl")   # mm numbers …
    refused(MESH.format("b.stl") + "scale = 100\n", "10 km", "check unit and scale", base_dir=tmp_path)


def test_the_budget_of_the_whole_cell(tmp_path, monkeypatch):
    import planning.cell.reader as reader
    monkeypatch.setattr(reader, "MAX_CELL_ELEMENTS", 15)
    trimesh.creation.box((1.0, 1.0, 1.0)).export(tmp_path / "b.stl")              # 12 triangles
    text = MESH.format("b.stl") + MESH.format("b.stl").replace("fixture", "again")
    refused(text, "obstacle 2 ('again')", "more than 15 triangles and points", base_dir=tmp_path)


def test_a_missing_cell_file_and_a_binary_one(tmp_path):
    with pytest.raises(CellError, match="no such cell file"):
        load_cell(tmp_path / "nope.toml")
    (tmp_path / "bin.toml").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(CellError, match="bin.toml: not UTF-8 text"):
        load_cell(tmp_path / "bin.toml")
