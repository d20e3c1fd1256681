"""The work-cell 3-D view draws what the collision checks use: capsule meshes on the capsules' surfaces,
placed by a plain numpy DH product; obstacle meshes where the shapes are (the original triangles of a
mesh when given, else its spheres); the closest approach between the points the clearance kernel
reports; an animation whose frames move the capsules along the path and keep the triangles."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

import kin
from kin.geometry import Shape
from planning.cell import parse_cell
from planning.collision import collision_world
from studies.report.cell_view import (
    MAX_ANIMATION_FRAMES,
    capsule_mesh,
    cell_view,
    closest_segments,
    contact_world,
    obstacle_mesh,
    robot_mesh,
    shape_mesh,
    spheres_mesh,
    triangles_mesh,
)
from tests.dh_numpy import frames_numpy

CELL = """
length_unit = "mm"
[robot]
xyz = [0, 0, 800]
[[obstacle]]
name = "table"
type = "box"
size = [1400, 900, 40]
xyz = [400, 0, 780]
ignore = ["base", "link 1"]
[[obstacle]]
name = "post"
type = "cylinder"
radius = 80
length = 1000
xyz = [-250, -550, 1300]
[[obstacle]]
name = "ball"
type = "mesh"
file = "ball.stl"
xyz = [450, 0, 1100]
tolerance = 10
max_spheres = 300
[[tool]]
name = "torch"
type = "capsule"
a = [0, 0, 0]
b = [0, 0, 200]
radius = 22
"""


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    d = tmp_path_factory.mktemp("cell")
    trimesh.creation.icosphere(1, 60.0).export(d / "ball.stl")
    cell = parse_cell(CELL, "c.toml", base_dir=d)
    w = collision_world(kin.load_robot("fanuc_lrmate200id"), cell)
    w.test_cell = cell
    return w


def _segment_distance(P, a, b):
    ab = b - a
    t = np.clip((P - a) @ ab / max(ab @ ab, 1e-300), 0.0, 1.0)
    return np.linalg.norm(P - (a + t[:, None] * ab), axis=1)


def _outward(V, F, inside):
    """Whether every triangle's normal (by its winding) points away from ``inside(centroid)``."""
    T = V[F]
    n = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    c = T.mean(axis=1)
    return np.all(np.einsum("ij,ij->i", n, c - inside(c)) > 0)


def test_capsule_mesh_lies_on_the_capsule_and_faces_out():
    rng = np.random.default_rng(1)
    for _ in range(5):
        a, b, r = rng.normal(size=3), rng.normal(size=3), rng.uniform(0.01, 0.3)
        V, F = capsule_mesh(a, b, r)
        np.testing.assert_allclose(_segment_distance(V, a, b), r, atol=1e-12)
        ab = b - a
        near = lambda C: a + np.clip((C - a) @ ab / (ab @ ab), 0, 1)[:, None] * ab     # noqa: E731
        assert _outward(V, F, near)
        assert F.min() == 0 and F.max() == len(V) - 1
    V, F = capsule_mesh([1, 2, 3], [1, 2, 3], 0.5)                   # a sphere
    np.testing.assert_allclose(np.linalg.norm(V - [1, 2, 3], axis=1), 0.5, atol=1e-12)


def test_obstacle_shapes_as_meshes():
    R = trimesh.transformations.rotation_matrix(0.7, [1, 2, 3])
    R[:3, 3] = [0.3, -0.2, 1.0]
    V, F = shape_mesh(Shape("box", (0.1, 0.2, 0.3), R))
    L = (V - R[:3, 3]) @ R[:3, :3]
    np.testing.assert_allclose(np.abs(L), np.tile([0.1, 0.2, 0.3], (8, 1)), atol=1e-12)
    assert len(F) == 12 and _outward(V, F, lambda C: np.tile(R[:3, 3], (len(C), 1)))
    V, F = shape_mesh(Shape("cylinder", (0.08, 0.9, 0), R))
    L = (V - R[:3, 3]) @ R[:3, :3]
    rim = np.abs(np.abs(L[:, 2]) - 0.9) < 1e-12
    assert rim.all()
    ring = np.hypot(L[:, 0], L[:, 1])
    assert np.allclose(ring[ring > 1e-9], 0.08) and (ring < 1e-9).sum() == 2     # the two cap centres
    assert _outward(V, F, lambda C: np.tile(R[:3, 3], (len(C), 1)))
    V, _ = shape_mesh(Shape("capsule", (0.05, 0.2, 0), R))
    ends = R[:3, 3] + np.outer([-0.2, 0.2], R[:3, 2])
    np.testing.assert_allclose(_segment_distance(V, ends[0], ends[1]), 0.05, atol=1e-12)
    V, _ = shape_mesh(Shape("sphere", (0.3, 0, 0), R))
    np.testing.assert_allclose(np.linalg.norm(V - R[:3, 3], axis=1), 0.3, atol=1e-12)


def test_spheres_keep_the_largest_and_triangles_round_trip():
    S = np.array([[0, 0, 0, 0.1], [1, 0, 0, 0.3], [2, 0, 0, 0.2]])
    V, F, k = spheres_mesh(S, limit=2)
    assert k == 2 and len(V) == 24 and len(F) == 40
    centres = V.reshape(2, 12, 3).mean(axis=1)
    np.testing.assert_allclose(centres, [[1, 0, 0], [2, 0, 0]], atol=1e-12)        # 0.3 and 0.2, in order
    radii = np.linalg.norm(V.reshape(2, 12, 3) - centres[:, None], axis=2)
    np.testing.assert_allclose(radii, np.repeat([[0.3], [0.2]], 12, axis=1))
    T = trimesh.creation.box((1, 2, 3)).triangles
    V, F = triangles_mesh(T)
    assert len(V) == 8 and np.array_equal(V[F], T)


def test_robot_capsules_follow_a_numpy_dh_product(world):
    chain = world.chain
    for q in np.random.default_rng(4).uniform(chain.lower, chain.upper, (3, chain.n)):
        frames = [world.base @ T for T in frames_numpy(chain, q)]
        frames.append(frames[-1] @ np.array(chain.tool.matrix))            # the tool, body n + 1
        from kin.geometry import body_frames
        Fb = body_frames(chain, q[None], world.base)[0]
        for c in world.geometry.capsules:
            V, _ = robot_mesh(world.geometry, Fb, {c.body})
            M = frames[c.body]
            a, b = M[:3, :3] @ c.a + M[:3, 3], M[:3, :3] @ c.b + M[:3, 3]
            # every vertex of the body's mesh is on one of its capsules; this one's are among them
            d = _segment_distance(V, a, b) - c.radius
            assert (np.abs(d) < 1e-9).sum() >= len(capsule_mesh(a, b, c.radius)[0])


def test_obstacles_use_the_original_triangles_when_given(world):
    cell = world.test_cell
    ball = world.obstacles[2]
    V, F, how = obstacle_mesh(ball, cell.meshes["ball"])
    assert how == f"{len(cell.meshes['ball'])} triangles"
    np.testing.assert_allclose(V[F], cell.meshes["ball"], atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(V - [0.45, 0, 1.1], axis=1), 0.06, atol=1e-6)
    V, F, how = obstacle_mesh(ball)
    assert how == f"{len(ball.spheres)} spheres" and len(V) == 12 * len(ball.spheres)
    fig = cell_view(world, np.zeros(6), meshes=cell.meshes)
    names = [t.name for t in fig.data]
    assert names[:4] == ["robot links (capsules)", "tool", "DH frames", "closest approach"]
    assert "ball (mesh: 80 triangles)" in names and "post (cylinder)" in names
    assert fig.layout.scene.xaxis.title.text == "x (mm)"
    table = next(t for t in fig.data if t.name.startswith("table"))
    corners = np.c_[table.x, table.y, table.z]
    assert corners[:, 2].min() == pytest.approx(760) and corners[:, 2].max() == pytest.approx(800)
    assert "may touch: base, link 1 (J1)" in table.hovertemplate


def test_the_closest_approach_joins_the_kernels_points(world):
    q_hit = np.radians([0, 100, 0, 0, 90, 0])          # the arm reaching down into the table
    q_clear = np.zeros(6)
    assert world.clearance(q_hit) < 0 < world.clearance(q_clear)
    for q, colour in ((q_hit, "#d62728"), (q_clear, "#2ca02c")):
        fig = cell_view(world, q, closest="all")
        line = fig.data[3]
        c = world.nearest(q[None])
        np.testing.assert_allclose(np.c_[line.x, line.y, line.z][:2],
                                   1000 * np.vstack([c.point_robot[0], c.point_other[0]]), atol=0.051)
        assert line.line.color == colour
        assert line.text[2] == f"{1000 * c.clearance[0]:.4g} mm".replace("-", "−")
        assert world.describe(int(c.body[0]), int(c.other[0]), float(c.clearance[0])) == line.hovertext[0]
    # among the cell's obstacles only, or the robot's own pairs only
    cell_only, own = contact_world(world, "cell"), contact_world(world, "self")
    assert cell_only.pairs == [] and own.obstacles == ()
    Q = world.chain.lower + np.random.default_rng(0).random((200, 6)) * (world.chain.upper - world.chain.lower)
    obs, slf = world.per_body(Q)
    np.testing.assert_allclose(cell_only.clearance(Q), np.minimum(obs.min(axis=1), world.cap), atol=1e-9)
    np.testing.assert_allclose(own.clearance(Q), np.minimum(slf.min(axis=1), world.cap), atol=1e-9)
    seg = closest_segments(world, Q[:5], "cell")
    assert all(s["other"] >= 0 for s in seg if s is not None)
    with pytest.raises(ValueError, match="closest"):
        cell_view(world, q_clear, closest="nearby")


def test_the_animation_moves_the_capsules_and_keeps_the_triangles(world):
    start, goal = np.radians([-90, 0, 0, 0, 90, 0]), np.radians([60, 20, -10, 30, 60, 0])
    path = np.array([start, 0.5 * (start + goal) + 0.1, goal])
    q = 0.3 * start + 0.7 * goal
    fig = cell_view(world, q, path=path, closest="cell", tip=[0, 0, 0.2])
    assert len(fig.frames) == MAX_ANIMATION_FRAMES
    [slider] = fig.layout.sliders
    active = slider.active
    assert 0 < active < MAX_ANIMATION_FRAMES - 1
    links = fig.frames[active].data[0]
    assert links.i is None and links.x is not None                      # frames move vertices only
    np.testing.assert_allclose(np.c_[links.x, links.y, links.z], np.c_[fig.data[0].x, fig.data[0].y, fig.data[0].z])
    from kin.geometry import body_frames
    V, F = robot_mesh(world.geometry, body_frames(world.chain, goal[None], world.base)[0], set(range(7)))
    last = fig.frames[-1].data[0]
    np.testing.assert_allclose(np.c_[last.x, last.y, last.z], 1000 * V, atol=0.051)
    assert np.array_equal(np.c_[fig.data[0].i, fig.data[0].j, fig.data[0].k], F)
    trace = next(t for t in fig.data if t.name == "tool path")
    T = body_frames(world.chain, goal[None], world.base)[0, -1]
    np.testing.assert_allclose([trace.x[-1], trace.y[-1], trace.z[-1]], 1000 * (T[:3, :3] @ [0, 0, 0.2] + T[:3, 3]),
                               atol=0.051)
