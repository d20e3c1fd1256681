"""The native motion checker (planning.motion) against independent values: its states against the
clearance kernel's distances, its proven motions against dense sampling (no proven motion touches
anything at 2000 states), its collisions at states that collide, a graze between samples caught,
limits and interval windows decided exactly, its lower bound below every sampled clearance."""
from __future__ import annotations

import math
from importlib.resources import files

import numpy as np
import pytest

import kin
import kin.geometry
from kin.geometry import LinkCapsule, Obstacle, RobotGeometry, Shape
from planning.collision import CollisionWorld, collision_world
from planning.errors import PlanningError
from planning.motion import MotionChecker, available

pytestmark = pytest.mark.skipif(not available(), reason="the native motion checker needs a C compiler")

SCENES = files("studies") / "benchmarks" / "scenes"
CELLS = files("studies") / "cells"


def _spheres(robot):
    """The robot with each capsule replaced by three balls along it (a spherized robot, as MotionBenchMaker's)."""
    caps = []
    for c in robot.geometry.capsules:
        for s in (0.0, 0.5, 1.0):
            p = tuple(np.add(c.a, s * np.subtract(c.b, c.a)))
            caps.append(LinkCapsule(c.body, p, p, c.radius + 0.25 * c.length, c.name))
    return RobotGeometry(tuple(caps), robot.geometry.allowed, "balls")


def _world(case: str, margin: float = 0.0) -> CollisionWorld:
    name, cell = case.split("/")
    robot = kin.load_robot(name.removesuffix("+balls"))
    if cell == "balls":               # balls where the robot's tool and elbow have been (a machine tool's cell)
        F = kin.geometry.body_frames(robot.chain, robot.random_configurations(6, seed=4))
        obs = []
        for i, f in enumerate(F):
            T = np.eye(4)
            T[:3, 3] = f[-1][:3, 3] if i % 2 else f[robot.n // 2][:3, 3]
            obs.append(Obstacle(f"ball {i}", (Shape("sphere", (0.08, 0, 0), T),)))
        return collision_world(robot, margin=margin, obstacles=obs)
    path = CELLS / cell if (CELLS / cell).is_file() else SCENES / cell
    w = collision_world(robot, str(path), margin=margin)
    if name.endswith("+balls"):
        w = CollisionWorld(robot, _spheres(robot), w.obstacles, w.base, margin, w.name)
    return w


CASES = ["fanuc_lrmate200id/fanuc_weld_cell.toml", "franka_panda/clutter.toml", "ur5e/cage.toml",
         "franka_panda+balls/bookshelf.toml", "cnc_rrrppp/balls", "scara_rrp/balls"]


def _valid(world, count, seed, near: bool = False):
    """Valid configurations; with ``near``, the closest to touching of many (motions near obstacles)."""
    chain = world.chain
    rng = np.random.default_rng(seed)
    Q = rng.uniform(chain.lower, chain.upper, size=(20 * count, chain.n))
    c = world.model.clearance(Q)
    ok = c > world.margin
    Q, c = Q[ok], c[ok]
    if near:
        Q = Q[np.argsort(c)]
    return Q[:count]


@pytest.mark.parametrize("case", CASES)
def test_states_agree_with_the_clearance_kernel(case):
    world = _world(case)
    mc = MotionChecker(world.robot, world)
    chain = world.chain
    Q = np.random.default_rng(1).uniform(chain.lower, chain.upper, size=(3000, chain.n))
    truth = world.model.clearance(Q) > world.margin
    got = np.array([mc.state_valid(q) for q in Q])
    assert truth.any() and (~truth).any(), "the sample must hold both valid and colliding states"
    assert np.array_equal(got, truth)
    f = mc.ompl_state()                         # OMPL's callback: the same answers from a sequence
    assert [f(list(q)) for q in Q[:200]] == list(truth[:200])


def _dense_min(world, a, b, count=2001):
    t = np.linspace(0.0, 1.0, count)
    return world.model.clearance(a + t[:, None] * (b - a))


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("margin", [0.0, 0.02])
def test_proven_motions_are_clear_at_every_dense_state(case, margin):
    world = _world(case, margin)
    mc = MotionChecker(world.robot, world)
    rng = np.random.default_rng(2)
    V = np.vstack([_valid(world, 40, 3, near=True), _valid(world, 40, 4)])
    seen = {"clear": 0, "collision": 0, "unproven": 0}
    for k in range(120):
        a, b = V[rng.integers(len(V))], V[rng.integers(len(V))]
        b = a + rng.choice([0.05, 0.3, 1.0]) * (b - a)
        r = mc.check(a, b)
        seen[r.status] += 1
        dense = _dense_min(world, a, b)
        if r.status == "clear":
            assert dense.min() > margin, f"proven motion {k} comes {dense.min():.3g} m close"
            assert mc.check(a, b, ordered=True).status == "clear", "ordered and unordered checks disagree"
        elif r.status == "collision":
            q = a + r.t * (b - a)
            assert world.model.clearance(q) <= margin + 1e-7, "a reported collision must be a state that collides"
        else:       # left open: only where the motion comes within a hair of the margin (or touches)
            assert _dense_min(world, a, b, 20001).min() <= margin + 1e-5, f"motion {k} clear by a lot, not proven"
    assert seen["clear"] > 10 and seen["collision"] > 10


def test_a_graze_between_samples_is_caught():
    """A ball placed just inside the path of a capsule's end, half-way between any states a sampled
    check would look at: the dense truth says collision, and the checker never proves the motion."""
    robot = kin.load_robot("fanuc_lrmate200id")
    chain = robot.chain
    a = np.array([0.0, 0.3, -0.2, 0.0, -0.6, 0.0])
    b = a.copy()
    b[0] = 0.4
    base = CollisionWorld(robot, margin=0.0)
    mc0 = MotionChecker(robot, base)
    assert mc0.check(a, b).status == "clear"
    from kin.geometry import body_frames
    t_star = 0.537
    F = body_frames(chain, (a + t_star * (b - a))[None])[0]
    far = max(robot.geometry.capsules, key=lambda c: np.hypot(*(F[c.body] @ [*c.b, 1])[:2]))
    p = (F[far.body] @ [*far.b, 1])[:3]
    out = p[:2] / np.hypot(*p[:2])
    for depth in (1e-4, 1e-6):
        centre = p + np.array([*out, 0.0]) * (far.radius + 0.002 - depth)
        T = np.eye(4)
        T[:3, 3] = centre
        world = CollisionWorld(robot, RobotGeometry((far,)), [Obstacle("ball", (Shape("sphere", (0.002, 0, 0), T),))])
        assert _dense_min(world, a, b, 200001).min() < 0, "the construction must graze the ball"
        assert MotionChecker(robot, world).check(a, b).status != "clear"


def test_limits_windows_and_bad_values_are_decided_exactly():
    robot = kin.load_robot("ur5e")
    chain = robot.chain
    mc = MotionChecker(robot, None, [(4, -0.1, 0.1)])            # a wrist window on joint 5 (0-based 4)
    a = np.array([0.1, -1.0, 1.0, 0.0, 0.5, 0.0])
    b = a.copy()
    b[4] = -0.5
    r = mc.check(a, b)
    assert r.status == "window" and math.isclose(r.t, 0.4 / 1.0, rel_tol=1e-12)
    assert mc.state_status(np.array([0.1, -1.0, 1.0, 0.0, 0.05, 0.0])) == "window"
    out = a.copy()
    out[1] = chain.upper[1] + 1e-6
    assert mc.check(a, out).status == "limits" and mc.state_status(out) == "limits"
    bad = a.copy()
    bad[2] = math.nan
    assert mc.check(a, bad).status == "bad" and not mc.state_valid(bad)
    with pytest.raises(PlanningError):
        mc.check(a, b[:4])
    no_limits = MotionChecker(robot, None, limits=False)
    assert no_limits.check(a, out).status == "clear"


@pytest.mark.parametrize("case", ["fanuc_lrmate200id/fanuc_weld_cell.toml", "franka_panda+balls/bookshelf.toml"])
def test_the_bound_lies_below_every_sampled_clearance(case):
    world = _world(case)
    mc = MotionChecker(world.robot, world)
    V = _valid(world, 30, 6, near=True)
    rng = np.random.default_rng(7)
    bounded = 0
    for _ in range(40):
        a, b = V[rng.integers(len(V))], V[rng.integers(len(V))]
        b = a + 0.3 * (b - a)
        r = mc.check(a, b, bound=True)
        if r.status != "clear":
            continue
        dense = _dense_min(world, a, b)
        assert world.margin < r.bound <= dense.min() + 1e-9
        bounded += 1
    assert bounded > 5


@pytest.mark.parametrize("case", CASES[:4])
def test_shortcut_keeps_the_ends_and_the_proofs_and_never_lengthens(case):
    world = _world(case)
    mc = MotionChecker(world.robot, world)
    V = _valid(world, 60, 8)
    rng = np.random.default_rng(9)
    done = 0
    for _ in range(300):                       # zigzag paths of proven short motions
        path = [V[rng.integers(len(V))]]
        for _ in range(6):
            nxt = path[-1] + 0.1 * (V[rng.integers(len(V))] - path[-1])
            if mc.check(path[-1], nxt).status != "clear":
                break
            path.append(nxt)
        if len(path) < 4:
            continue
        P = np.array(path)
        S, _ = mc.shortcut(P, seed=3)
        S2, _ = mc.shortcut(P, seed=3)
        assert np.array_equal(S, S2), "the same seed gives the same path"
        assert np.array_equal(S[0], P[0]) and np.array_equal(S[-1], P[-1])
        length = lambda X: float(np.linalg.norm(np.diff(X, axis=0), axis=1).sum())  # noqa: E731
        assert length(S) <= length(P) + 1e-12
        for k in range(len(S) - 1):
            assert mc.check(S[k], S[k + 1]).status == "clear"
            assert _dense_min(world, S[k], S[k + 1], 501).min() > 0
        done += 1
        if done == 8:
            break
    assert done >= 5
