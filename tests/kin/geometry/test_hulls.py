"""Hulls besides capsules: the [[geometry.hull]] tables (read, written back, hostile input refused), and
the refined clearances of a world with hulls — never below the capsules', never above coal's distance
between the same hulls (a lower bound of the real shapes'), and the proofs built on them re-checked
densely with coal."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.errors import RobotFileError
from kin.geometry import body_frames
from kin.robotfile import dumps_robot, loads_robot
from planning.certify.collision import certify_collision
from planning.collision import collision_world
from studies.cli.common import cell_file
from tests.coal_ref import frame_along, hull, placed_distance

coal = pytest.importorskip("coal")


def test_bundled_ur5e_has_hulls_that_round_trip():
    chain = kin.load_chain("ur5e")
    hulls = chain.geometry.hulls
    assert [h.body for h in hulls] == list(range(7)) and all(h.radius > 0.001 for h in hulls)
    again = loads_robot(dumps_robot(chain))
    assert again.geometry.hulls == hulls
    # the modified-DH twin carries its hulls into its own frames: the same points in the world
    mod = chain.to_modified()
    q = np.radians([10, -70, 80, -30, 40, 20])
    F, G = body_frames(chain, q[None])[0], body_frames(mod, q[None])[0]
    for h, g in zip(hulls, mod.geometry.hulls):
        W1 = h.array @ F[h.body, :3, :3].T + F[h.body, :3, 3]
        W2 = g.array @ G[g.body, :3, :3].T + G[g.body, :3, 3]
        assert np.abs(W1 - W2).max() < 1e-9


BASE = """name = "two"
convention = "standard"
length_unit = "mm"
angle_unit = "deg"
[[joints]]
type = "revolute"
a = 300
limits = [-180, 180]
[[joints]]
type = "revolute"
a = 200
limits = [-180, 180]
[geometry]
[[geometry.capsule]]
body = "link 1"
a = [-300, 0, 0]
b = [0, 0, 0]
radius = 30
"""


@pytest.mark.parametrize("hull, field", [
    ('body = "link 1"\npoints = [[0, 0, 0], [1, 2]]', "geometry.hull[0].points[1]"),
    ('body = "link 1"\npoints = [[0, 0, nan]]', "geometry.hull[0].points[0]"),
    ('body = "link 9"\npoints = [[0, 0, 0]]', "geometry.hull[0].body"),
    ('body = "link 1"\npoints = []', "geometry.hull[0].points"),
    ('body = "link 1"\npoints = [[0, 0, 0]]\nradius = -1', "geometry.hull[0].radius"),
    ('body = "link 1"\npoints = [[0, 0, true]]', "geometry.hull[0].points[0]"),
    ('body = "link 1"\npoints = [[0, 0, 1e30]]', "geometry.hull[0].points[0]"),
    ('body = "link 1"\npoints = [[0, 0, 0]]\ncolour = "red"', "geometry.hull[0].colour"),
    ('points = [[0, 0, 0]]', "geometry.hull[0].body"),
])
def test_hostile_hull_tables_are_refused_naming_the_field(hull, field):
    with pytest.raises(RobotFileError) as e:
        loads_robot(BASE + "[[geometry.hull]]\n" + hull + "\n")
    assert field in str(e.value) and "\n" not in str(e.value)


def test_too_many_points_and_hulls_without_capsules_are_refused():
    pts = ", ".join(["[0, 0, 0]"] * 5000)
    with pytest.raises(RobotFileError, match="1 to 4096 points"):
        loads_robot(BASE + f'[[geometry.hull]]\nbody = "link 1"\npoints = [{pts}]\n')
    bare = BASE[:BASE.index("[geometry]")] + '[geometry]\n[[geometry.hull]]\nbody = "link 1"\npoints = [[0, 0, 0]]\n'
    with pytest.raises(RobotFileError, match="capsules listed too"):
        loads_robot(bare)
    c = loads_robot(BASE + '[[geometry.hull]]\nbody = "link 1"\npoints = [[-300, 0, 0], [0, 10, 0]]\nradius = 2\n')
    h = c.geometry.hulls[0]
    assert h.radius == pytest.approx(0.002) and np.allclose(h.array, [[-0.3, 0, 0], [0, 0.01, 0]])


@pytest.fixture(scope="module")
def shelf():
    robot = kin.load_robot("ur5e")
    return robot, collision_world(robot, cell_file("ur5e_shelf_cell"))


def _coal_per_body(world, q):
    """Per body, the least coal distance of its hulls (radius subtracted) to the obstacles it may touch
    and to its checked pair bodies' hulls (capsules where a body has none): what the refined values must
    not exceed."""
    F = body_frames(world.chain, q[None], base=world.base)[0]
    B = world.chain.n + 2
    geo = {}
    for b in range(B):
        hs = [h for h in world.geometry.hulls if h.body == b]
        if hs:
            geo[b] = [(hull(h.array), F[b], h.radius) for h in hs]
        else:
            geo[b] = []
            for c in world.geometry.capsules:
                if c.body == b:
                    a, e = F[b, :3, :3] @ np.array(c.a) + F[b, :3, 3], F[b, :3, :3] @ np.array(c.b) + F[b, :3, 3]
                    geo[b].append((coal.Capsule(c.radius, float(np.linalg.norm(e - a))), frame_along(a, e), 0.0))
    obs, slf = np.full(B, np.inf), np.full(B, np.inf)
    for b in range(B):
        for ob in world.obstacles:
            if b in ob.ignore:
                continue
            for sh in ob.shapes:
                assert sh.kind == "box"
                box = coal.Box(*(2 * np.asarray(sh.size)))
                for g, T, r in geo[b]:
                    obs[b] = min(obs[b], placed_distance(g, T, box, sh.pose) - r)
    for i, j in world.pairs:
        d = min(placed_distance(g1, T1, g2, T2) - r1 - r2 for g1, T1, r1 in geo[i] for g2, T2, r2 in geo[j])
        slf[i], slf[j] = min(slf[i], d), min(slf[j], d)
    return obs, slf


def test_refined_clearances_lie_between_the_capsules_and_coal(shelf):
    robot, world = shelf
    rng = np.random.default_rng(7)
    Q = rng.uniform(-math.pi, math.pi, (60, 6))
    cap_o, cap_s = world.model.per_body(Q)
    ref_o, ref_s = world.per_body(Q)
    assert (ref_o >= cap_o - 1e-12).all() and (ref_s >= cap_s - 1e-12).all()
    raised = 0
    for k, q in enumerate(Q):
        co, cs = _coal_per_body(world, q)
        for ref, cap, c in ((ref_o[k], cap_o[k], co), (ref_s[k], cap_s[k], cs)):
            up = ref > cap + 1e-12
            raised += int(up.sum())
            # where raised, the value is the hulls' (a lower bound: never above coal's distance, apart from
            # the prism-free boxes here, tight to 1e-7)
            assert (ref[up] <= c[up] + 1e-7).all()
            assert (np.abs(ref[up] - np.minimum(c[up], world.cap)) < 1e-6).all()
    assert raised > 20


def test_place_low_is_clear_of_the_hulls_not_of_the_capsules(shelf):
    robot, world = shelf
    q = np.radians([46.7, -76.3, 137.9, -241.6, -46.7, 0.0])
    from kin.ik.analytic import analytic_branches
    from kin.transforms import make_transform, rpy_to_matrix
    target = np.linalg.inv(world.base) @ make_transform(rpy_to_matrix(np.radians([-90, 0, 0])),
                                                        np.array([0.10, 0.40, 1.08]))
    q = min(analytic_branches(robot, target), key=lambda b: np.abs(np.angle(np.exp(1j * (b - q)))).max())
    assert world.model.clear_one(q) < 0 < world.clearance(q)
    co, cs = _coal_per_body(world, q)
    assert min(co.min(), cs.min()) > 0.005


def test_proofs_with_hulls_hold_densely(shelf):
    """A motion into the place-low configuration, proven by the hulls: coal's distances at 400 states along
    it stay above zero."""
    robot, world = shelf
    a = np.radians([-39.7, -76.9, 121.8, -134.9, -90.0, -129.7])
    b = np.radians([-313.3, -76.3, 137.9, -241.6, -46.7, 0.0])
    proof = certify_collision(world, [a, b])
    assert proof.proven
    for t in np.linspace(0, 1, 400):
        co, cs = _coal_per_body(world, a + t * (b - a))
        assert min(co.min(), cs.min()) > 0
