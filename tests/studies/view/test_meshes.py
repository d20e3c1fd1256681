"""The robot's real shape (studies.shape.meshes, kin.visual, kin.urdf.visual).

Meshes placed by the robot file's body frames (kin.geometry.body_frames) at random configurations are
compared with the same mesh files placed by the URDF's own kinematics (yourdfpy), vertex by vertex.
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import kin
from kin.errors import RobotFileError
from kin.geometry import body_frames
from kin.robotfile import dumps_robot, loads_robot, save_robot
from kin.urdf import import_urdf
from studies.shape.meshes import MeshWarning, decimate, visual_meshes
from tests.kin.urdf.reference import erd_urdf

URDF = """<?xml version="1.0"?>
<robot name="toy">
  <material name="red"><color rgba="0.8 0.1 0.1 1"/></material>
  <link name="base"><visual><geometry><mesh filename="meshes/base.stl"/></geometry></visual></link>
  <link name="l1"><visual><origin xyz="0.01 0.02 0.1" rpy="0.3 -0.2 0.5"/>
    <geometry><mesh filename="meshes/arm.stl" scale="1 2 0.5"/></geometry><material name="red"/></visual>
    <visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
  <link name="l2"><visual><origin xyz="0.2 0 0" rpy="1.5707963 0 0"/>
    <geometry><mesh filename="meshes/arm.stl"/></geometry></visual></link>
  <link name="l3"><visual><origin xyz="0 0 0.05"/>
    <geometry><mesh filename="meshes/base.stl"/></geometry></visual></link>
  <link name="tip"><visual><geometry><mesh filename="meshes/arm.stl" scale="0.3 0.3 0.3"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.3" rpy="0 0 0.4"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.05 0.1 0.2" rpy="1.2 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0.4 0 0.02" rpy="0 0.3 0"/>
    <axis xyz="0.6 0 0.8"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="tj" type="fixed"><parent link="l3"/><child link="tip"/><origin xyz="0.1 0 0.1"/></joint>
</robot>
"""


def write_toy(tmp_path):
    import trimesh
    (tmp_path / "meshes").mkdir()
    trimesh.creation.box(extents=(0.1, 0.2, 0.05)).export(tmp_path / "meshes" / "base.stl")
    arm = trimesh.creation.cylinder(radius=0.04, height=0.3, sections=24)
    arm.apply_translation((0.1, 0.0, 0.0))
    arm.export(tmp_path / "meshes" / "arm.stl")
    (tmp_path / "toy.urdf").write_text(URDF)
    return tmp_path / "toy.urdf"


def urdf_placed(path, names, q, base: str):
    """Each <visual> mesh's vertices at q by yourdfpy's FK: {link: [world vertices (k, 3)]}."""
    import trimesh
    import yourdfpy
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    model.update_cfg(dict(zip(names, q)))
    out = {}
    for link in model.robot.links:
        for v in link.visuals:
            if v.geometry.mesh is None:
                continue
            file = path.parent / v.geometry.mesh.filename if "://" not in v.geometry.mesh.filename else \
                path.parents[2] / v.geometry.mesh.filename.split("robots/", 1)[1]
            V = np.asarray(trimesh.load(str(file), force="mesh", process=False).vertices)
            V = V * (np.ones(3) if v.geometry.mesh.scale is None else np.asarray(v.geometry.mesh.scale))
            T = np.asarray(model.get_transform(link.name, base)) @ (np.eye(4) if v.origin is None else v.origin)
            out.setdefault(link.name, []).append(V @ T[:3, :3].T + T[:3, 3])
    return out


def view_placed(chain, meshes, q):
    F = body_frames(chain, q)[0]
    out = {}
    for m in meshes:
        out.setdefault(m.name, []).append(m.vertices @ F[m.body, :3, :3].T + F[m.body, :3, 3])
    return out


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_imported_visual_meshes_sit_where_the_urdf_puts_them(tmp_path, convention):
    path = write_toy(tmp_path)
    chain = import_urdf(str(path), tip="tip", convention=convention)
    out = tmp_path / "robot" / "toy.toml"
    save_robot(chain, out)
    assert 'file = "../meshes/arm.stl"' in out.read_text()        # named relative to the robot file
    loaded = kin.load_chain(out)
    assert loaded == chain and len(loaded.visual) == 5 and "box" in loaded.visual_source
    meshes = visual_meshes(kin.Robot(loaded), budget=None)
    assert [m.body for m in meshes] == [0, 1, 2, 3, 4]
    assert meshes[1].rgba == (0.8, 0.1, 0.1, 1.0)
    names = [j.name for j in chain.joints]
    for q in np.random.default_rng(1).uniform(-3, 3, size=(5, 3)):
        ref, got = urdf_placed(path, names, q, "base"), view_placed(loaded, meshes, q)
        assert ref.keys() == got.keys()
        for link in ref:
            for a, b in zip(ref[link], got[link], strict=True):
                np.testing.assert_allclose(b, a, atol=1e-9)


def test_a_missing_or_unreadable_mesh_is_one_line_and_capsules(tmp_path):
    path = write_toy(tmp_path)
    chain = import_urdf(str(path), tip="tip")
    save_robot(chain, tmp_path / "toy.toml")
    (tmp_path / "meshes" / "arm.stl").unlink()
    (tmp_path / "meshes" / "base.stl").write_text("not a mesh at all")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got = visual_meshes(kin.load_chain(tmp_path / "toy.toml"), budget=None)
    assert got is None
    said = [str(w.message) for w in caught if issubclass(w.category, MeshWarning)]
    assert len(said) == 5 and all("\n" not in s and "drawn as capsules" in s for s in said)
    assert any("no such file" in s for s in said) and any("base.stl" in s for s in said)


def test_the_visual_table_is_checked_on_load(tmp_path):
    text = dumps_robot(kin.load_chain("planar_2r"))
    for table, field in [('[[visual.mesh]]\nbody = "link 1"\nfile = "arm.step"\n', "visual.mesh[0].file"),
                         ('[[visual.mesh]]\nbody = "link 7"\nfile = "arm.stl"\n', "visual.mesh[0].body"),
                         ('[[visual.mesh]]\nbody = "link 1"\nfile = "arm.stl"\ncolor = [1, 2, 0, 1]\n',
                          "visual.mesh[0].color"),
                         ('[[visual.mesh]]\nbody = "link 1"\nfile = "http://x/arm.stl"\n', "visual.mesh[0].file"),
                         ('[[visual.mesh]]\nbody = "link 1"\n', "visual.mesh[0].file"),
                         ('[visual]\nsize = 3\n', "visual.size")]:
        with pytest.raises(RobotFileError) as e:
            loads_robot(text + "\n" + table, str(tmp_path / "r.toml"))
        assert e.value.field == field and "\n" not in str(e.value)


def test_bundled_panda_wears_the_makers_meshes():
    path = erd_urdf("panda_description/urdf/panda.urdf")
    chain = kin.load_chain("franka_panda")
    meshes = visual_meshes(chain, budget=None)
    assert meshes is not None and sorted({m.body for m in meshes}) == list(range(8))
    names = [f"panda_joint{i}" for i in range(1, 8)]
    for q in np.random.default_rng(2).uniform(chain.lower, chain.upper, size=(3, chain.n)):
        ref, got = urdf_placed(path, names, q, "panda_link0"), view_placed(chain, meshes, q)
        for link in got:
            for a, b in zip(ref[link], got[link], strict=True):
                np.testing.assert_allclose(b, a, atol=1e-9)


def test_arms_without_a_known_shape_have_none():
    # example-robot-data ships the CB-series UR5, whose lengths are not the e-series UR5e's
    assert visual_meshes(kin.load_chain("ur5e")) is None
    assert visual_meshes(kin.load_chain("planar_2r")) is None


def test_decimate_keeps_the_budget_and_the_shape():
    import trimesh
    m = trimesh.creation.icosphere(subdivisions=5, radius=0.2)         # 20 480 triangles
    V, F = decimate(np.asarray(m.vertices), np.asarray(m.faces), 2000)
    assert 500 < len(F) <= 2000 and F.max() < len(V)
    r = np.linalg.norm(V, axis=1)
    assert np.all(np.abs(r - 0.2) < 0.02)
    assert np.all(np.abs(V.max(axis=0) - 0.2) < 0.02)
