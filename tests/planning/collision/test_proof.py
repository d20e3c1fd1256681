"""Collision proofs (planning.certify.collision): a graze between samples that a sampled check
misses and the proof catches; proven segments are clear at a dense grid; found collisions collide;
the proven lower bound holds."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.geometry import Obstacle, RobotGeometry, Shape, body_frames
from planning.certify.collision import certify_collision
from planning.collision import CollisionWorld
from planning.validate import check_path


def _sphere(center, r, name="ball") -> Obstacle:
    T = np.eye(4)
    T[:3, 3] = center
    return Obstacle(name, (Shape("sphere", (r, 0, 0), T),))


def _box(center, size, name="box") -> Obstacle:
    T = np.eye(4)
    T[:3, 3] = center
    return Obstacle(name, (Shape("box", tuple(0.5 * np.asarray(size)), T),))


@pytest.fixture(scope="module")
def fanuc():
    return kin.load_robot("fanuc_lrmate200id")


def _graze(robot, t_star: float, depth: float):
    """A joint 1 motion and a small ball placed beside the end of the capsule farthest from joint 1's
    axis at t_star, beyond that end and off its path, so that the capsule dips ``depth`` into the
    ball around t_star only: (path (2, n), world)."""
    chain = robot.chain
    a = np.array([0.0, 0.3, -0.2, 0.0, -0.6, 0.0])
    b = a.copy()
    b[0] = 0.2
    geo = robot.geometry
    q = a + t_star * (b - a)
    F = body_frames(chain, np.array([q, q + 1e-6 * (b - a)]))
    best = None
    for c in geo.capsules:
        if c.length < 1e-3:
            continue
        for end, other in ((c.b, c.a), (c.a, c.b)):
            p = (F[0, c.body] @ [*end, 1])[:3]
            if best is None or np.hypot(*p[:2]) > best[0]:
                best = (np.hypot(*p[:2]), c, np.array(end), np.array(other))
    _, cap, end, other = best
    p0 = (F[0, cap.body] @ [*end, 1])[:3]
    p1 = (F[1, cap.body] @ [*end, 1])[:3]
    v = (p1 - p0) / np.linalg.norm(p1 - p0)
    axis = F[0, cap.body][:3, :3] @ (end - other)
    u = axis - (axis @ v) * v                          # beyond the capsule's end, off its path
    u /= np.linalg.norm(u)
    r_ball = 0.002
    centre = p0 + u * (cap.radius + r_ball - depth)
    # the robot reduced to that one capsule, so that no other capsule reaches the ball
    world = CollisionWorld(robot, RobotGeometry((cap,)), [_sphere(centre, r_ball)], margin=0.0)
    return np.array([a, b]), world


def test_a_graze_between_samples_is_missed_by_samples_and_caught_by_the_proof(fanuc):
    """A 0.2 rad joint 1 motion checked every 0.1° has 115 states; the ball is touched only for a
    sliver of the motion between two of them."""
    step = math.radians(0.1)
    k = 0.2 / step
    t_star = (57 + 0.5) / math.ceil(k)                    # half-way between two sampled states
    path, world = _graze(fanuc, t_star, depth=1e-6)
    ts = np.linspace(t_star - 1e-3, t_star + 1e-3, 20001)
    dense = world.clearance(path[0] + ts[:, None] * (path[1] - path[0]))
    assert dense.min() < 0, "the construction must graze the ball"
    sampled = check_path(fanuc, path, step_angle=step, world=world, prove=False)
    assert sampled.valid, "a check at 0.1° steps sees nothing (the point of the test)"
    assert sampled.min_clearance > 0
    proof = certify_collision(world, path)
    assert not proof.proven and proof.violation is not None
    v = proof.violation
    assert v.segment == 0 and abs(v.t - t_star) < 1e-2
    assert world.clearance(v.q) <= 0
    assert "against obstacle 'ball'" in v.text
    full = check_path(fanuc, path, step_angle=step, world=world)
    assert not full.valid and full.first_violation.kind == "collision" and "(proven)" in full.first_violation.detail


def test_proven_segments_are_clear_and_the_bound_holds(fanuc):
    """Random segments in a cell of boxes and balls: a proven segment is clear at 4001 states with
    clearance ≥ the proven bound; a found collision collides; unproven never happens in practice."""
    rng = np.random.default_rng(11)
    obstacles = [_box((0.5, 0.0, 0.15), (0.2, 0.6, 0.3), "block"), _sphere((0.2, 0.45, 0.5), 0.08),
                 _box((-0.5, 0.0, 0.5), (0.05, 2.0, 1.0), "wall")]
    world = CollisionWorld(fanuc, obstacles=obstacles)
    Q = fanuc.random_configurations(4000, seed=5)
    Q = Q[world.clearance(Q) > 0]
    proven = found = 0
    for _ in range(40):
        a, b = Q[rng.integers(len(Q), size=2)]
        b = a + 0.3 * (b - a)
        P = np.array([a, b])
        proof = certify_collision(world, P)
        ts = np.linspace(0, 1, 4001)
        c = world.clearance(a + ts[:, None] * (b - a))
        if proof.proven:
            proven += 1
            assert c.min() > 0
            assert c.min() >= proof.bound - 1e-12
        else:
            assert proof.violation is not None, proof.unproven
            found += 1
            assert world.clearance(proof.violation.q) <= 0
            assert c.min() <= 0
    assert proven >= 5 and found >= 5, (proven, found)


def test_a_segment_that_ends_in_collision_is_reported_where_it_enters(fanuc):
    """The first colliding state, not the colliding row: clearance ≤ 0 there and > 0 a little before."""
    world = CollisionWorld(fanuc, obstacles=[_box((0.6, 0.0, 0.3), (0.3, 0.6, 0.6), "block")])
    a = np.zeros(6)
    b = np.array([0.0, 1.2, 0.9, 0.0, -1.0, 0.0])
    assert world.clearance(a) > 0 and world.clearance(b) <= 0
    v = certify_collision(world, np.array([a, b])).violation
    assert v is not None and v.segment == 0 and 0 < v.t < 1
    assert world.clearance(v.q) <= 0
    ts = np.linspace(0, v.t, 2001)[:-1]
    assert world.clearance(a + ts[:, None] * (b - a)).min() > -1e-9        # nothing deeper before it
    assert v.deepest <= v.clearance and "obstacle 'block'" in v.text


def test_the_c_motion_proof_agrees_with_the_batch_proof(fanuc):
    """A motion validator's yes/no (the kernel's C proof) equals the batch proof's on random motions,
    and a state it reports is in collision."""
    obstacles = [_box((0.5, 0.0, 0.15), (0.2, 0.6, 0.3), "block"), _sphere((0.2, 0.45, 0.5), 0.08)]
    world = CollisionWorld(fanuc, obstacles=obstacles)
    Q = fanuc.random_configurations(3000, seed=9)
    Q = Q[world.clearance(Q) > 0]
    rng = np.random.default_rng(4)
    seen = set()
    for _ in range(150):
        a, b = Q[rng.integers(len(Q), size=2)]
        b = a + 0.4 * (b - a)
        fast = certify_collision(world, [a, b], stop_at_first=True)
        full = certify_collision(world, np.array([a, b]))
        assert fast.proven == full.proven
        if fast.violation is not None:
            assert world.clearance(fast.violation.q) <= 0
        seen.add(fast.proven)
    assert seen == {True, False}
    assert world.model.backend == "compiled"


@pytest.mark.parametrize("name", ["fanuc_lrmate200id", "franka_panda", "ur5e"])
def test_self_clearance_changes_no_faster_than_the_relative_bound(name):
    """Each body's self clearance (min over its pairs) changes along a short motion by no more than
    the bound of the joints between the bodies of its pairs (finite differences, 400 motions)."""
    from planning.certify.collision import _motion
    robot = kin.load_robot(name)
    world = CollisionWorld(robot)
    rng = np.random.default_rng(2)
    Q = robot.random_configurations(400, seed=8)
    dQ = rng.normal(size=Q.shape) * 1e-4
    _, s0 = world.per_body(Q)
    _, s1 = world.per_body(Q + dQ)
    _, Ds = _motion(world, dQ)
    live = (s0 < world.cap) & (s1 < world.cap)
    assert live.any()
    assert np.all(np.abs(s1 - s0)[live] <= Ds[live] * (1 + 1e-6) + 1e-12)


def test_keep_out_boxes_move_with_the_robots_place_in_the_cell(fanuc):
    """A keep-out box is given in the robot's base frame: in a cell that puts the robot 0.8 m up and
    turned 90° about z, the box stands where that placement takes it."""
    from planning.cell import parse_cell
    from planning.collision import collision_world
    from planning.ompl import KeepOutBox

    cell = parse_cell("[robot]\nxyz = [0, 0, 0.8]\nrpy = [0, 0, 90]\n", "c.toml")
    world = collision_world(fanuc, cell, keep_out=[KeepOutBox((0.4, -0.1, 0.0), (0.6, 0.1, 0.2))])
    (box,) = world.obstacles[-1].shapes
    assert box.kind == "box" and box.size == pytest.approx((0.1, 0.1, 0.1))
    assert box.pose[:3, 3] == pytest.approx([0.0, 0.5, 0.9])                 # (0.5, 0, 0.1) turned and lifted
    assert box.pose[:3, :3] == pytest.approx(cell.base[:3, :3])
    alone = collision_world(fanuc, keep_out=[KeepOutBox((0.4, -0.1, 0.0), (0.6, 0.1, 0.2))])
    q = fanuc.random_configurations(200, seed=1)
    np.testing.assert_allclose(world.clearance(q), alone.clearance(q), atol=1e-9)   # same box for the robot
