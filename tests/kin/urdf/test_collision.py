"""Collision geometry through URDF (kin/urdf/collision.py, kin/urdf/write.py).

* Import: every vertex of every collision mesh of example-robot-data's Panda and UR5, placed by the
  URDF's own forward kinematics (yourdfpy) at random configurations, lies inside the capsules of its
  body placed by :func:`kin.geometry.body_frames` of the imported chain, in both DH conventions.
* Export: re-read with yourdfpy, each capsule is a cylinder and two spheres equal to it; coal's
  distances to those solids are the capsule's; export → import gives the same capsules exactly.
* Synthetic URDFs: primitives, mesh paths (relative, package://, given package directories), the
  tool body with a finger held at 0, links off the chain left out, and every bad mesh or size a
  one-line UrdfError.
"""
from __future__ import annotations

import dataclasses
import zlib
from pathlib import Path

import numpy as np
import pytest
import trimesh

import kin
from kin.geometry import body_frames
from kin.geometry.enclose import segment_distance
from kin.urdf import UrdfError, import_urdf, read_serial_chain, save_urdf
from kin.urdf import collision as collision_module
from tests.kin.urdf.reference import ERD_ROBOTS, erd_urdf

PREFIX = "package://example-robot-data/robots/"


def place(T: np.ndarray, P) -> np.ndarray:
    P = np.atleast_2d(np.asarray(P, dtype=float))
    return P @ T[:3, :3].T + T[:3, 3]


def outside(points: np.ndarray, caps, F) -> float:
    """The largest distance by which a point stands out of the capsules (negative: all inside)."""
    d = np.full(len(points), np.inf)
    for c in caps:
        a, b = place(F[c.body], [c.a, c.b])
        d = np.minimum(d, segment_distance(points, a, b) - c.radius)
    return float(d.max())


def urdf_solids(urdf_path: Path):
    """(link, origin (4×4), vertices (V, 3) in the collision frame) of every collision element of the URDF
    that is a mesh or a box, read independently of kin.urdf (trimesh; package:// of example-robot-data)."""
    import yourdfpy
    model = yourdfpy.URDF.load(str(urdf_path), build_scene_graph=True, load_meshes=False)
    robots = urdf_path.parents[2]
    assert robots.name == "robots"
    out = []
    for link in model.robot.links:
        for c in link.collisions:
            T = np.eye(4) if c.origin is None else c.origin
            g = c.geometry
            if g.mesh is not None:
                assert g.mesh.filename.startswith(PREFIX)
                mesh = trimesh.load(str(robots / g.mesh.filename[len(PREFIX):]), force="mesh")
                V = np.asarray(mesh.vertices) * (1.0 if g.mesh.scale is None else np.asarray(g.mesh.scale))
            elif g.box is not None:
                corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
                V = corners * np.asarray(g.box.size) / 2
            else:
                continue
            out.append((link.name, T, V))
    return model, out


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("relative, tip, capsules", [
    ("panda_description/urdf/panda.urdf", "panda_link8", 1),
    ("ur_description/urdf/ur5_robot.urdf", "tool0", 3),
])
def test_imported_capsules_hold_every_mesh_vertex(relative, tip, capsules, convention):
    if convention == "modified" and capsules > 1:
        capsules = 1                        # the enclosure is the same; only the frames differ
    path = erd_urdf(relative)
    chain = import_urdf(str(path), tip=tip, convention=convention, max_capsules=capsules)
    sc = read_serial_chain(str(path), tip=tip)
    g = chain.geometry
    assert g is not None and g.source.startswith("urdf: the <collision> elements of")
    assert g.over_estimate > 0 and all(c.radius > 0 for c in g.capsules)
    body_of = {lk.name: lk.body for lk in sc.links}
    model, solids = urdf_solids(path)
    carried = [s for s in solids if s[0] in body_of]
    assert len(carried) >= chain.n
    names = chain.joint_names()
    rng = np.random.default_rng(zlib.crc32(relative.encode()))
    for q in rng.uniform(chain.lower, chain.upper, size=(6, chain.n)):
        model.update_cfg(dict(zip(names, q)))
        F = body_frames(chain, q)[0]
        for link, origin, V in carried:
            world = place(np.asarray(model.get_transform(link, sc.base)) @ origin, V)
            caps = [c for c in g.capsules if c.body == body_of[link]]
            assert caps, link
            assert outside(world, caps, F) <= 1e-9, link
    if "panda" in relative:     # the fingers' joints are held at 0 (yourdfpy's default too): on the tool
        assert "held at panda_finger_joint1 = 0 (0), panda_finger_joint2 = 0 (mimic of panda_finger_joint1)" in g.source
        assert {body_of["panda_leftfinger"], body_of["panda_rightfinger"], body_of["panda_hand"]} == {chain.n + 1}
        assert {"panda_leftfinger", "panda_rightfinger"} <= {s[0] for s in carried}
        assert {c.body for c in g.capsules} == set(range(chain.n + 2))


def capsule_solids(urdf_path: Path, q, names):
    """World cylinders (centre, axis, length, radius) and spheres (centre, radius) of every link of an
    exported URDF, as yourdfpy places them."""
    import yourdfpy
    model = yourdfpy.URDF.load(str(urdf_path), build_scene_graph=True, load_meshes=False)
    model.update_cfg(dict(zip(names, q)))
    cylinders, spheres = [], []
    for link in model.robot.links:
        T = np.asarray(model.get_transform(link.name, "base_link"))
        for c in link.collisions:
            W = T @ (np.eye(4) if c.origin is None else c.origin)
            if c.geometry.cylinder is not None:
                cylinders.append((W, c.geometry.cylinder.length, c.geometry.cylinder.radius))
            elif c.geometry.sphere is not None:
                spheres.append((W[:3, 3], c.geometry.sphere.radius))
            else:
                raise AssertionError(f"unexpected collision geometry in {link.name}")
    return cylinders, spheres


GEOMETRY = '''
[geometry]
[[geometry.capsule]]
body = "base"
a = [0.0, 0.0, 0.0]
b = [0.0, 0.0, 0.2]
radius = 0.1
[[geometry.capsule]]
body = "link 2"
a = [-0.3, 0.01, 0.02]
b = [0.05, 0.0, 0.0]
radius = 0.06
[[geometry.sphere]]
body = "link 3"
center = [0.01, 0.02, 0.03]
radius = 0.05
[[geometry.box]]
body = "tool"
center = [0.0, 0.0, -0.03]
size = [0.05, 0.08, 0.06]
rpy = [0.1, 0.2, 0.3]
'''


def chains():
    bare = dataclasses.replace(kin.load_chain("puma560"), geometry=None)        # the default capsules
    text = kin.robotfile.dumps_robot(bare)
    shaped = kin.robotfile.with_units(kin.loads_robot(kin.robotfile.dumps_robot(
        kin.robotfile.with_units(bare, "m", "rad")) + GEOMETRY), "mm", "deg")
    assert "[geometry]" not in text
    return {"puma560 default": bare, "puma560 shapes": shaped,
            "stanford modified": kin.load_chain("stanford_arm").to_modified(), "ur5e": kin.load_chain("ur5e")}


@pytest.mark.parametrize("which", ["puma560 default", "puma560 shapes", "stanford modified", "ur5e"])
def test_export_writes_each_capsule_as_a_cylinder_and_two_spheres(tmp_path, which):
    chain = chains()[which]
    geometry = kin.Robot(chain).geometry
    path = save_urdf(chain, tmp_path / "robot.urdf")
    rng = np.random.default_rng(4)
    for q in rng.uniform(chain.lower, chain.upper, size=(4, chain.n)):
        cylinders, spheres = capsule_solids(path, q, chain.joint_names())
        F = body_frames(chain, q)[0]
        used = set()
        for c in geometry.capsules:
            a, b = place(F[c.body], [c.a, c.b])
            for p in (a, b):
                hit = [i for i, (s, r) in enumerate(spheres)
                       if np.linalg.norm(s - p) < 1e-12 and abs(r - c.radius) < 1e-15]
                assert hit, (c, p)
                used.update(hit)
            if np.linalg.norm(b - a) > 1e-12:
                ok = [W for W, L, r in cylinders if abs(r - c.radius) < 1e-15 and abs(L - np.linalg.norm(b - a)) < 1e-12
                      and np.linalg.norm(W[:3, 3] - (a + b) / 2) < 1e-12
                      and np.linalg.norm(np.cross(W[:3, 2], b - a)) < 1e-12]
                assert len(ok) >= 1, c
        assert len(used) == len(spheres)
        n_cyl = sum(1 for c in geometry.capsules if c.length > 1e-12)
        assert len(cylinders) == n_cyl


def test_coal_sees_the_same_solids(tmp_path):
    """coal's distance from a ball to the exported cylinder-and-spheres equals the distance to our capsule."""
    coal = pytest.importorskip("coal")
    chain = chains()["puma560 shapes"]
    geometry = chain.geometry
    path = save_urdf(chain, tmp_path / "robot.urdf")
    rng = np.random.default_rng(8)
    q = rng.uniform(chain.lower, chain.upper, size=chain.n)
    cylinders, spheres = capsule_solids(path, q, chain.joint_names())
    F = body_frames(chain, q)[0]
    ball = coal.Sphere(0.02)

    def dist(shape, W, p):
        req, res = coal.DistanceRequest(), coal.DistanceResult()
        return coal.distance(shape, coal.Transform3s(W[:3, :3], W[:3, 3]), ball,
                             coal.Transform3s(np.eye(3), p), req, res)

    ours_all, theirs_all = [], []
    for p in rng.uniform(-1, 1, size=(200, 3)):
        theirs = min([dist(coal.Cylinder(r, L), W, p) for W, L, r in cylinders]
                     + [dist(coal.Sphere(r), np.block([[np.eye(3), s[:, None]], [np.zeros((1, 3)), 1]]), p)
                        for s, r in spheres])
        ours = min(float(segment_distance(p[None], *place(F[c.body], [c.a, c.b]))[0]) - c.radius - 0.02
                   for c in geometry.capsules)
        ours_all.append(ours)
        theirs_all.append(theirs)
    ours_all, theirs_all = np.array(ours_all), np.array(theirs_all)
    out = ours_all > 0
    assert out.sum() > 100
    np.testing.assert_allclose(theirs_all[out], ours_all[out], atol=1e-9)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_export_import_gives_the_same_capsules(tmp_path, convention):
    chain = chains()["puma560 shapes"]
    path = save_urdf(chain, tmp_path / "robot.urdf")
    again = import_urdf(str(path), tip="tool", convention=convention)
    g0, g1 = chain.geometry, again.geometry
    assert g1.over_estimate == 0.0 and len(g1.capsules) == len(g0.capsules)
    assert "(1 sphere, 3 capsules)" in g1.source          # the ball comes back as a sphere
    q = np.random.default_rng(1).uniform(chain.lower, chain.upper, size=chain.n)
    F0, F1 = body_frames(chain, q)[0], body_frames(again, q)[0]
    world0 = sorted((c.body, *np.round(place(F0[c.body], [c.a, c.b]).ravel(), 9), round(c.radius, 12))
                    for c in g0.capsules)
    world1 = sorted((c.body, *np.round(place(F1[c.body], [c.a, c.b]).ravel(), 9), round(c.radius, 12))
                    for c in g1.capsules)
    assert world0 == world1


# ---- synthetic URDFs ----------------------------------------------------------------------------
def write(tmp_path: Path, links: dict[str, str], joints: str, where: str = "robot.urdf") -> Path:
    path = tmp_path / where
    path.parent.mkdir(parents=True, exist_ok=True)
    body = "".join(f'<link name="{n}">{c}</link>' for n, c in links.items())
    path.write_text(f'<?xml version="1.0"?><robot name="t">{body}{joints}</robot>')
    return path


def col(geometry: str, xyz="0 0 0", rpy="0 0 0") -> str:
    return f'<collision><origin xyz="{xyz}" rpy="{rpy}"/><geometry>{geometry}</geometry></collision>'


def j(name, type_, parent, child, xyz="0 0 0", axis="0 0 1") -> str:
    lim = '<limit lower="-2" upper="2" effort="1" velocity="1"/>' if type_ != "fixed" else ""
    ax = f'<axis xyz="{axis}"/>' if type_ != "fixed" else ""
    return (f'<joint name="{name}" type="{type_}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="0 0 0"/>{ax}{lim}</joint>')


JOINTS = (j("j1", "revolute", "base", "arm", "0 0 0.3") + j("j2", "revolute", "arm", "fore", "0.4 0 0", "0 1 0")
          + j("tip", "fixed", "fore", "flange", "0.3 0 0") + j("grip", "fixed", "flange", "gripper", "0.05 0 0")
          + j("finger", "prismatic", "gripper", "finger", "0.02 0 0", "1 0 0") + j("ped", "fixed", "world", "base"))


def stl(path: Path, mesh: trimesh.Trimesh) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    mesh.export(str(path))


def test_synthetic_urdf_bodies_and_shapes(tmp_path):
    pkg = tmp_path / "mypkg"
    stl(pkg / "meshes" / "arm.stl", trimesh.creation.box((0.4, 0.06, 0.06)))
    path = write(pkg / "urdf", {
        "world": col('<box size="1 1 0.1"/>', "0 0 -0.1"),
        "base": col('<cylinder radius="0.1" length="0.3"/>', "0 0 0.15"),
        "arm": col('<mesh filename="package://mypkg/meshes/arm.stl" scale="1 1 1"/>', "0.2 0 0"),
        "fore": col('<sphere radius="0.05"/>', "0.3 0 0") + col('<mesh filename="../meshes/arm.stl" scale="0.5 1 1"/>'),
        "flange": "", "gripper": col('<box size="0.05 0.1 0.05"/>'), "finger": col('<box size="0.01 0.01 0.05"/>'),
    }, JOINTS)
    chain = import_urdf(str(path), base="world", tip="flange")
    g = chain.geometry
    names = {(c.name, c.body) for c in g.capsules}     # capsules are named after their link
    assert names == {("world", 0), ("base", 0), ("arm", 1), ("fore", 2), ("gripper", 3), ("finger", 3)}   # tool
    assert "held at finger = 0 (0)" in g.source and "left out" not in g.source
    assert "2 meshes, 3 boxes, 1 cylinder, 1 sphere" in g.source
    # every solid inside at random configurations, by the URDF's own kinematics
    import yourdfpy
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    solids = {"world": trimesh.creation.box((1, 1, 0.1)).apply_translation((0, 0, -0.1)),
              "base": trimesh.creation.cylinder(0.1, 0.3).apply_translation((0, 0, 0.15)),
              "arm": trimesh.creation.box((0.4, 0.06, 0.06)).apply_translation((0.2, 0, 0)),
              "fore": trimesh.creation.box((0.2, 0.06, 0.06)),
              "gripper": trimesh.creation.box((0.05, 0.1, 0.05)),
              "finger": trimesh.creation.box((0.01, 0.01, 0.05))}
    body = {"world": 0, "base": 0, "arm": 1, "fore": 2, "gripper": 3, "finger": 3}
    for q in np.random.default_rng(0).uniform(-2, 2, size=(5, 2)):
        model.update_cfg({"j1": q[0], "j2": q[1]})
        F = body_frames(chain, q)[0]
        for link, mesh in solids.items():
            P = place(np.asarray(model.get_transform(link, "world")), mesh.vertices)
            assert outside(P, [c for c in g.capsules if c.body == body[link]], F) <= 1e-9, link
    # the same with the package directory given, and without collision geometry
    again = import_urdf(str(path), base="world", tip="flange", package_dirs={"mypkg": str(pkg)})
    assert again.geometry == g
    assert import_urdf(str(path), base="world", tip="flange", collision=False).geometry is None


def test_no_collision_elements_means_default_geometry(tmp_path):
    path = write(tmp_path, {"a": "", "b": ""}, j("j1", "revolute", "a", "b"))
    assert import_urdf(str(path)).geometry is None


@pytest.mark.parametrize("mesh, setup, message", [
    ("meshes/none.stl", None, r"link 'b' collision 0 mesh 'meshes/none.stl': no such mesh file '.*none.stl'"),
    ("meshes/bad.stl", "garbage", r"link 'b' collision 0 mesh 'meshes/bad.stl': (cannot read|.* holds no triangles)"),
    ("meshes/empty.stl", "empty", r"holds no triangles|cannot read the mesh"),
    ("http://example.com/x.stl", None, r"the scheme http:// is not read .*nothing is fetched from a network"),
    ("package://nowhere/x.stl", None, r"package 'nowhere' is neither a directory above the URDF file nor given "
                                      r"\(rmt import-urdf --package nowhere=DIR\)"),
    ("meshes/big.stl", "big", r"the mesh file is 0 MB; at most 0 MB are read"),
    ("meshes/many.stl", "many", r"the mesh has 12 triangles; at most 11 are read"),
])
def test_bad_meshes_are_one_line_errors(tmp_path, monkeypatch, mesh, setup, message):
    if setup == "garbage":
        (tmp_path / "meshes").mkdir()
        (tmp_path / "meshes" / "bad.stl").write_bytes(b"solid x\nfacet normal nonsense\n" + bytes(range(256)))
    elif setup == "empty":
        (tmp_path / "meshes").mkdir()
        (tmp_path / "meshes" / "empty.stl").write_text("solid x\nendsolid x\n")
    elif setup == "big":
        stl(tmp_path / "meshes" / "big.stl", trimesh.creation.box())
        monkeypatch.setattr(collision_module, "MAX_MESH_BYTES", 10)
    elif setup == "many":
        stl(tmp_path / "meshes" / "many.stl", trimesh.creation.box())
        monkeypatch.setattr(collision_module, "MAX_MESH_TRIANGLES", 11)
    path = write(tmp_path, {"a": "", "b": col(f'<mesh filename="{mesh}"/>')}, j("j1", "revolute", "a", "b"))
    with pytest.raises(UrdfError) as e:
        import_urdf(str(path))
    assert str(e.value).startswith(f"{path}: ") and "\n" not in str(e.value)
    import re
    assert re.search(message, str(e.value)), str(e.value)


def test_bad_primitives(tmp_path):
    path = write(tmp_path, {"a": "", "b": col('<box size="0.1 -0.2 0.1"/>')}, j("j1", "revolute", "a", "b"))
    with pytest.raises(UrdfError, match=r"link 'b' collision 0: the box size .* must be a positive finite number"):
        import_urdf(str(path))


def test_erd_urdf_path_helper_matches_prefix():
    assert ERD_ROBOTS.endswith("example-robot-data/robots")


@pytest.mark.parametrize("geometry, xyz, message", [
    ('<sphere radius="1e-12"/>', "0 0 0", r"the sphere radius 1e-12 m; allowed: 1e-09 to 10000 m \(1 nm to 10 km\)"),
    ('<box size="0.1 2e4 0.1"/>', "0 0 0", r"the box size 20000 m; allowed: 1e-09 to 10000 m"),
    ('<sphere radius="0.1"/>', "0 3e5 0", r"its <origin> xyz \[0.0, 300000.0, 0.0\]; allowed: at most 10000 m"),
    ('<mesh filename="meshes/huge.stl"/>', "0 0 0",
     r"mesh 'meshes/huge.stl': the mesh's vertices \(scale \[1.0, 1.0, 1.0\]\) reach 3e\+38 m from its origin; "
     r"allowed: at most 10000 m"),
])
def test_sizes_a_robot_file_cannot_hold_are_refused(tmp_path, geometry, xyz, message):
    """Sizes beyond a robot file's range (1 nm to 10 km) — a URDF's own or a mesh's ±3e38 vertices — are
    one line naming the link and the element, never a robot file the reader refuses."""
    stl(tmp_path / "meshes" / "huge.stl", trimesh.Trimesh(np.array([[0, 0, 0], [3e38, 0, 0], [0, -3e38, 0]]),
                                                         np.array([[0, 1, 2]]), process=False))
    path = write(tmp_path, {"a": "", "b": col(geometry, xyz)}, j("j1", "revolute", "a", "b"))
    with pytest.raises(UrdfError) as e:
        import_urdf(str(path))
    import re
    assert str(e.value).startswith(f"{path}: link 'b' collision 0") and "\n" not in str(e.value)
    assert re.search(message, str(e.value)), str(e.value)


def test_imported_hulls_hold_every_mesh_vertex():
    """``hulls``: each collision element also as a hull on its body; every vertex of the URDF's meshes, placed
    by yourdfpy, lies within the hull's radius of the hull placed by body_frames (by coal's distance), and the
    hulls survive a save and load."""
    coal = pytest.importorskip("coal")
    relative, tip = "ur_description/urdf/ur5_robot.urdf", "tool0"
    path = erd_urdf(relative)
    chain = import_urdf(str(path), tip=tip, hulls=1e-3)
    g = chain.geometry
    assert g.hulls and "hulls of every element" in g.source
    assert kin.loads_robot(kin.dumps_robot(chain)).geometry.hulls == g.hulls
    sc = read_serial_chain(str(path), tip=tip)
    body_of = {lk.name: lk.body for lk in sc.links}
    model, solids = urdf_solids(path)
    names = chain.joint_names()
    from tests.coal_ref import frame_along, hull, placed_distance
    point = coal.Sphere(1e-12)
    rng = np.random.default_rng(3)
    checked = set()
    for q in rng.uniform(chain.lower, chain.upper, size=(3, chain.n)):
        model.update_cfg(dict(zip(names, q)))
        F = body_frames(chain, q)[0]
        for link, origin, V in solids:
            if link not in body_of:
                continue
            world = place(np.asarray(model.get_transform(link, sc.base)) @ origin, V)
            hs = [h for h in g.hulls if h.body == body_of[link] and len(h.points) >= 4]
            if not hs:              # a box's hulls are its capsules (their containment is tested above)
                assert any(h.body == body_of[link] for h in g.hulls), link
                continue
            checked.add(link)
            placed = [(hull(h.array @ F[h.body, :3, :3].T + F[h.body, :3, 3]), h.radius) for h in hs]
            for p in world[:: max(1, len(world) // 200)]:
                d = min(placed_distance(H, np.eye(4), point, frame_along(p, p)) - r for H, r in placed)
                assert d <= 1e-9, link
    assert len(checked) >= 6
