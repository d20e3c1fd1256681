"""MotionBenchMaker's scenes (both robots, every scene kind) imported as cells: the cell's primitives are
where the raw YAML says (read here by PyYAML alone, rotated by scipy), and the Panda's clearance in the
imported cage and bookshelf equals coal's distances between its capsules and the scene's shapes (inside
an obstacle: rmtkit's depth is the deepest point's, never more than coal's least move out)."""
from __future__ import annotations

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

import kin
from kin.geometry import body_frames
from planning.cell.moveit import load_scene, scene_cell
from planning.collision import collision_world
from studies.benchmarks.mbm import ROBOTS, SCENES, MbmDataError, problem_dir

CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)


@pytest.fixture(scope="module")
def problems():
    try:
        return {r: problem_dir(r) for r in ROBOTS}
    except MbmDataError as e:
        pytest.skip(f"MotionBenchMaker data: {e}")


def _T(pose) -> np.ndarray:
    T = np.eye(4)
    if pose:
        T[:3, :3] = Rotation.from_quat(pose["orientation"]).as_matrix()
        T[:3, 3] = pose["position"]
    return T


def _raw_shapes(path):
    """(id, type, dimensions, 4×4) of every primitive, from PyYAML and scipy alone."""
    doc = yaml.safe_load(path.read_text())
    out = []
    for o in doc["world"]["collision_objects"]:
        for prim, pose in zip(o["primitives"], o["primitive_poses"]):
            out.append((o["id"], prim["type"], prim["dimensions"], _T(o.get("pose")) @ _T(pose)))
    return out


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("scene", SCENES)
def test_every_scene_kind_imports_where_the_yaml_says(problems, robot, scene):
    for number in (1, 50, 100):
        path = problems[robot] / f"{scene}_{robot}" / f"scene{number:04d}.yaml"
        text, cell = scene_cell(load_scene(path), "c.toml")
        raw = _raw_shapes(path)
        assert [o.name for o in cell.obstacles] == [r[0] for r in raw]            # ids kept, "base" too
        for ob, (_, kind, dims, T) in zip(cell.obstacles, raw):
            (s,) = ob.shapes
            if kind == "box":
                np.testing.assert_allclose(CORNERS * s.size @ s.pose[:3, :3].T + s.pose[:3, 3],
                                           CORNERS * np.array(dims) / 2 @ T[:3, :3].T + T[:3, 3], atol=1e-12)
            else:
                assert kind == "cylinder" and s.size[:2] == pytest.approx((dims[1], dims[0] / 2), abs=1e-15)
                ends = np.array([[0, 0, -dims[0] / 2], [0, 0, dims[0] / 2]])
                np.testing.assert_allclose(ends @ s.pose[:3, :3].T + s.pose[:3, 3], ends @ T[:3, :3].T + T[:3, 3],
                                           atol=1e-12)
        assert np.array_equal(cell.base, np.eye(4))                               # the robot at the planning frame


def _coal_obstacle(coal, kind, dims, T):
    shape = coal.Box(*dims) if kind == "box" else coal.Cylinder(dims[1], dims[0])
    return coal.CollisionObject(shape, coal.Transform3s(T[:3, :3], T[:3, 3]))


def _coal_capsules(coal, geometry, F, body):
    out = []
    for c in geometry.capsules:
        if c.body != body:
            continue
        a, b = (F[body] @ [*c.a, 1])[:3], (F[body] @ [*c.b, 1])[:3]
        L = float(np.linalg.norm(b - a))
        z = (b - a) / L if L > 0 else np.array([0.0, 0.0, 1.0])
        x = np.cross(z, [1.0, 0, 0]) if abs(z[0]) < 0.9 else np.cross(z, [0, 1.0, 0])
        x /= np.linalg.norm(x)
        R = np.column_stack([x, np.cross(z, x), z])
        out.append(coal.CollisionObject(coal.Capsule(c.radius, L), coal.Transform3s(R, 0.5 * (a + b))))
    return out


def _distance(coal, a, b) -> float:
    req = coal.DistanceRequest()
    req.enable_signed_distance = True
    res = coal.DistanceResult()
    coal.distance(a, b, req, res)
    return res.min_distance


@pytest.mark.parametrize("scene", ["cage", "bookshelf_small"])
def test_the_pandas_clearance_in_an_imported_scene_is_coals(problems, scene):
    coal = pytest.importorskip("coal")
    d = problems["panda"] / f"{scene}_panda"
    robot = kin.load_robot("franka_panda")
    _, cell = scene_cell(load_scene(d / "scene0001.yaml"), "c.toml")
    world = collision_world(robot, cell)
    req = yaml.safe_load((d / "request0001.yaml").read_text())
    start = req["start_state"]["joint_state"]["position"][:7]
    goal = [j["position"] for j in req["goal_constraints"][0]["joint_constraints"]]
    rng = np.random.default_rng(7)
    start, goal = np.array(start), np.array(goal)
    bent = goal + [0, 0.3, 0, 0.3, 0, 0, 0]
    Q = np.vstack([start, goal, start + 1.2 * (goal - start), bent,     # past the goal: into the obstacles
                   rng.uniform(robot.chain.lower, robot.chain.upper, size=(4, 7))])
    obstacles = [_coal_obstacle(coal, kind, dims, T) for _, kind, dims, T in _raw_shapes(d / "scene0001.yaml")]
    ours = world.per_body(Q)[0]
    F = body_frames(robot.chain, Q, base=world.base)
    for i in range(len(Q)):
        for body in world.geometry.bodies():
            theirs = min(_distance(coal, c, o) for c in _coal_capsules(coal, world.geometry, F[i], body)
                         for o in obstacles)
            if theirs >= 0:
                assert ours[i, body] == pytest.approx(min(theirs, world.cap), abs=1e-6), (i, body)
            else:       # inside: ours is the deepest point's depth, coal's (EPA) the least move out — no less
                assert theirs - 1e-6 <= ours[i, body] < 0, (i, body)
    assert (ours[2:4] < 0).any() == (scene == "cage")   # past the goal, the Panda is in the cage's boards
    assert ours[1].min() < 0.1                   # the goal reaches in among the obstacles: they are where it goes
